"""World background -> a constant radiance or an equirectangular environment image (W·sr⁻¹·m⁻², scene-linear).

Supported: Background (Color x Strength) with a constant colour, or with an Environment Texture (equirectangular,
its image read like material textures) whose Vector is unlinked or comes through a Mapping node (its rotation;
Point/Vector/Texture types) from a Texture Coordinate node. Anything else is approximated by the world's colour and
reported.
"""
from __future__ import annotations

import math

import numpy as np

from ..compat import uses_nodes
from .materials import MaterialRegistry


def export_world(scene, warnings: list):
    """(constant radiance (3,), image (h, w, 3) radiance or None, rotation world -> texture (3, 3) or None)."""
    world = scene.world
    none = (np.zeros(3, np.float32), None, None)
    if world is None:
        return none
    if not uses_nodes(world):
        return np.array(world.color[:3], np.float32), None, None
    tree = world.node_tree
    outputs = [n for n in tree.nodes if n.type == "OUTPUT_WORLD" and n.is_active_output] or \
              [n for n in tree.nodes if n.type == "OUTPUT_WORLD"]
    if not outputs or not outputs[0].inputs["Surface"].is_linked:
        return none
    node = outputs[0].inputs["Surface"].links[0].from_node
    if node.type != "BACKGROUND":
        warnings.append(f"World '{world.name}': '{node.name}' is not a Background node; using the world colour")
        return np.array(world.color[:3], np.float32), None, None
    color_in, strength_in = node.inputs["Color"], node.inputs["Strength"]
    if strength_in.is_linked:
        warnings.append(f"World '{world.name}': a linked Strength is approximated by its value")
    strength = float(strength_in.default_value)
    if color_in.is_linked:
        src = color_in.links[0].from_node
        if src.type == "TEX_ENVIRONMENT" and src.image is not None and src.projection == "EQUIRECTANGULAR":
            registry = MaterialRegistry(warnings)
            image = registry.textures[registry._texture(world, src.image)] * np.float32(strength)
            return np.zeros(3, np.float32), np.asarray(image, np.float32), _rotation(world, src, warnings)
        warnings.append(f"World '{world.name}': '{src.name}' ({src.type}) drives the background; approximated by "
                        "the constant colour (supported: an equirectangular Environment Texture)")
    return (np.array(color_in.default_value[:3], np.float32) * strength).astype(np.float32), None, None


def _euler_xyz(rx: float, ry: float, rz: float) -> np.ndarray:
    cx, sx, cy, sy, cz, sz = math.cos(rx), math.sin(rx), math.cos(ry), math.sin(ry), math.cos(rz), math.sin(rz)
    rot_x = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    rot_y = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rot_z = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rot_z @ rot_y @ rot_x


def _rotation(world, env, warnings: list):
    """World -> texture rotation from a Mapping node on the Environment Texture's Vector (None: identity)."""
    vec = env.inputs["Vector"]
    if not vec.is_linked:
        return None
    node = vec.links[0].from_node
    if node.type == "TEX_COORD":
        return None
    if node.type != "MAPPING":
        warnings.append(f"World '{world.name}': '{node.name}' ({node.type}) maps the environment; ignored")
        return None
    inp = node.inputs
    if any(s.is_linked for s in inp if s.name in ("Rotation", "Scale", "Location")):
        warnings.append(f"World '{world.name}': a linked Mapping input is approximated by its value")
    rot = _euler_xyz(*[float(a) for a in inp["Rotation"].default_value])
    if "Scale" in inp and not np.allclose(inp["Scale"].default_value[:], 1.0):
        warnings.append(f"World '{world.name}': the Mapping node's Scale is ignored (rotation only)")
    if node.vector_type == "TEXTURE":
        rot = rot.T
    elif node.vector_type not in ("POINT", "VECTOR"):
        warnings.append(f"World '{world.name}': Mapping type {node.vector_type} approximated as Point")
    return rot.astype(np.float32)
