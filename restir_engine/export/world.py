"""World background -> a constant radiance or an equirectangular environment image (W·sr⁻¹·m⁻², scene-linear).

Supported: Background (Color x Strength). A plain equirectangular Environment Texture (its Vector unlinked or
through a Mapping node's rotation) is used as its image; any other graph of the Color and Strength (constants
folded, or textures, gradients, mixes and maths of the direction: core/materials/nodes) is evaluated over the
directions of an equirectangular image (BAKE_WIDTH x BAKE_WIDTH/2, or an environment texture's own resolution
up to MAX_BAKE_WIDTH), which the world light samples, while the graph itself gives the radiance of each direction
(core/lights/world.WorldGraph); the sun discs of Sky Textures read along the direction are left out of the image
and sampled over their cones instead. Nodes the evaluator does not know are named.
"""
from __future__ import annotations

import numpy as np

from ..compat import uses_nodes
from ..core.lights.world import WorldGraph
from ..core.materials.nodes.ops_texture import euler_matrix
from ..core.materials.textures import linear_texels
from .materials import MaterialRegistry
from .node_graph import GraphCompiler

BAKE_WIDTH = 512
MAX_BAKE_WIDTH = 2048
_BAKE_CHUNK = 1 << 18


def export_world(scene, warnings: list, view_layer=None):
    """(constant radiance (3,), image (h, w, 3) radiance or None, rotation world -> texture (3, 3) or None, what
    camera rays see instead: (radiance, image, graph) or None, the WorldGraph the image was baked from or None).
    ``view_layer``: where View Layer attributes are looked up (object_properties.view_layer_places; None: not
    read)."""
    got = _export_world(scene, warnings, view_layer)
    return got + (None,) * (5 - len(got))


def _export_world(scene, warnings: list, view_layer=None):
    world = scene.world
    none = (np.zeros(3, np.float32), None, None)
    if world is None:
        return none
    if not uses_nodes(world):
        return np.array(world.color[:3], np.float32), None, None
    tree = world.node_tree
    from .flat_nodes import cycles_output, flat_output
    out = cycles_output(tree, "OUTPUT_WORLD")
    outputs = [flat_output(out)] if out is not None else []
    if not outputs or not outputs[0].inputs["Surface"].is_linked:
        return none
    node = outputs[0].inputs["Surface"].links[0].from_node
    if node.type != "BACKGROUND":
        warnings.append(f"World '{world.name}': '{node.name}' is not a Background node; using the world colour")
        return np.array(world.color[:3], np.float32), None, None
    color_in, strength_in = node.inputs["Color"], node.inputs["Strength"]
    registry = MaterialRegistry(warnings)
    if color_in.is_linked and not strength_in.is_linked:
        src = color_in.links[0].from_node
        if src.type == "TEX_ENVIRONMENT" and src.image is not None and src.projection == "EQUIRECTANGULAR":
            plain, rotation = _plain_rotation(world, src, warnings)
            if plain:
                strength = float(strength_in.default_value)
                image = linear_texels(registry.textures[registry._texture(world, src.image)]) * np.float32(strength)
                return np.zeros(3, np.float32), np.asarray(image, np.float32), rotation
    return _baked(world, registry, color_in, strength_in, warnings, view_layer)


def _baked(world, registry, color_in, strength_in, warnings: list, view_layer=None):
    """The Background's Color x Strength through their node graph: a constant, or an image over directions."""
    notes = []
    g = GraphCompiler(lambda image, alpha: registry._texture(world, image, alpha=alpha), notes.append)
    g.view_layer = view_layer
    g.world = True  # Light Path reads as a camera ray's here (node_space_handlers.light_path)
    color, strength = g.value(color_in, "color"), g.value(strength_in, "float")
    warnings.extend(f"World '{world.name}': {n}" for n in dict.fromkeys(notes))
    if color.const is not None and strength.const is not None:
        c = np.asarray(color.constant_value(), np.float32) * np.float32(strength.constant_value())
        return c.astype(np.float32), None, None, None
    program = g.program({"color": color, "strength": strength})
    camera_view = None
    if "is_camera_ray" in program.reads:  # Light Path > Is Camera Ray: what the camera sees, baked apart
        seen = _graph(program, color, strength, registry, True)
        camera_view = (np.zeros(3, np.float32), _bake(seen, registry), seen)
    graph = _graph(program, color, strength, registry, False)
    return np.zeros(3, np.float32), _bake(graph, registry), None, camera_view, graph


def _graph(program, color, strength, registry, camera_ray: bool) -> WorldGraph:
    return WorldGraph(program, registry.textures, camera_ray, None if color.const is None else color.const,
                      None if strength.const is None else strength.const, tuple(_sun_cones(program)))


def _sun_cones(program) -> list:
    """(unit direction (3,), half-angle) of each sun disc of a Sky Texture the program reads along the direction."""
    cones = []
    for name, _outs, _ins, params in program.ops:
        if name == "sky_texture" and params.get("plain"):
            cone = params["sky"].sun_cone()
            if cone is not None:
                cones.append(cone)
    return cones


def _bake(graph: WorldGraph, registry) -> np.ndarray:
    """The world graph's Color x Strength over the directions of an equirectangular image (h, w, 3), its sky's sun
    discs left out (the world samples them apart)."""
    sizes = [t.shape[1] for t in registry.textures]
    w = int(min(MAX_BAKE_WIDTH, max([BAKE_WIDTH] + sizes)))
    h = max(1, w // 2)
    rows, cols = np.meshgrid(np.arange(h), np.arange(w), indexing="ij")
    u, v = (cols.ravel() + 0.5) / w, (rows.ravel() + 0.5) / h
    phi, theta = (0.5 - u) * 2 * np.pi, (1.0 - v) * np.pi  # the world image's convention (core/lights/world.py)
    dirs = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)]).astype(np.float32)
    image = np.empty((h * w, 3), np.float32)
    for lo in range(0, h * w, _BAKE_CHUNK):
        hi = min(lo + _BAKE_CHUNK, h * w)
        image[lo:hi] = graph.evaluate(dirs[:, lo:hi], without_sun=True).T
    return image.reshape(h, w, 3)


def _plain_rotation(world, env, warnings: list):
    """(whether an Environment Texture's Vector is unlinked, a Texture Coordinate, or a Mapping of one with its
    other inputs unlinked, the world -> texture rotation of that Mapping or None for the identity)."""
    vec = env.inputs["Vector"]
    node = vec.links[0].from_node if vec.is_linked else None
    if node is None or node.type == "TEX_COORD":
        return True, None
    if node.type != "MAPPING" or any(s.is_linked for s in node.inputs if s.name != "Vector"):
        return False, None
    inner = node.inputs["Vector"]
    if inner.is_linked and inner.links[0].from_node.type != "TEX_COORD":
        return False, None
    inp = node.inputs
    rot = np.array(euler_matrix(np.array(inp["Rotation"].default_value[:], np.float32)), np.float64).reshape(3, 3)
    if "Scale" in inp and not np.allclose(inp["Scale"].default_value[:], 1.0):
        warnings.append(f"World '{world.name}': the Mapping node's Scale is ignored (rotation only)")
    if node.vector_type == "TEXTURE":
        rot = rot.T
    elif node.vector_type not in ("POINT", "VECTOR"):
        warnings.append(f"World '{world.name}': Mapping type {node.vector_type} approximated as Point")
    return True, rot.astype(np.float32)
