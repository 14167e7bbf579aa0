"""Small Blender scenes for the integration tests (building blocks shared with the harness)."""
from __future__ import annotations

import math

import bpy
import mathutils
import numpy as np

from harness.render import configure_cycles, configure_restir, render_scene
from harness.scenes import (black_world, build_cornell, camera, diffuse, emission, enable_nodes, light, plane,
                            principled, reset)

__all__ = ["camera", "configure_cycles", "configure_restir", "cornell_box", "diffuse", "emission", "enable_nodes",
           "light", "plane", "render_passes", "reset"]


def cornell_box(light_kind="EMISSIVE", size=(48, 48)):
    """The harness's Cornell box (floor z=0, open towards -Y where the camera is), lit by its emissive quad
    facing down, or instead by an area light, a point light, a spot, a sun, or (NEGATIVE) the area light and a
    point lamp of negative power."""
    scene = build_cornell(size=size)
    if light_kind != "EMISSIVE":
        bpy.data.objects.remove(bpy.data.objects["Lamp"])
    if light_kind in ("AREA", "NEGATIVE"):
        light("AREA", (0, 0, 1.98), energy=30.0, color=(1, 0.9, 0.8), size=0.6)
    if light_kind == "NEGATIVE":  # a point lamp of negative power beside the area light: it subtracts light
        light("POINT", (0.4, 0.0, 0.6), energy=-6.0, shadow_soft_size=0.1)
    elif light_kind == "POINT":
        light("POINT", (0, 0, 1.5), energy=40.0, color=(1, 0.9, 0.8), shadow_soft_size=0.1)
    elif light_kind == "SPOT":
        light("SPOT", (0, 0, 1.9), energy=80.0, spot_size=math.radians(70), spot_blend=0.3, shadow_soft_size=0.05)
    elif light_kind == "SUN":
        bpy.data.objects.remove(bpy.data.objects["Ceiling"])
        light("SUN", (0, 0, 5), (math.radians(20), 0, 0), energy=3.0, angle=math.radians(2))
    return scene


def render_passes(scene) -> dict:
    """Render the current frame and return {pass name: (h, w, c) float32, row 0 at the bottom}."""
    return render_scene(scene)[0]


# Materials of the sphere grid (rows top to bottom): (kind, base colour, roughness, extra inputs).
# P = Principled BSDF, G = Glossy BSDF, D = Diffuse BSDF.
SPHERE_GRID = [
    [("P", (0.8, 0.5, 0.3), r, {}) for r in (0.1, 0.25, 0.5, 0.75, 1.0)]
    + [("P", (0.8, 0.5, 0.3), 0.5, {"Specular IOR Level": 0.0})],
    [("P", (0.9, 0.6, 0.3), r, {"Metallic": 1.0}) for r in (0.1, 0.25, 0.5, 0.75, 1.0)]
    + [("P", (0.9, 0.6, 0.3), 0.4, {"Metallic": 1.0, "Specular Tint": (0.4, 0.7, 1.0, 1.0)})],
    [("P", (0.3, 0.5, 0.8), 0.3, {"IOR": 1.2}), ("P", (0.3, 0.5, 0.8), 0.8, {"IOR": 1.2}),
     ("P", (0.3, 0.5, 0.8), 0.3, {"IOR": 2.0}), ("P", (0.3, 0.5, 0.8), 0.8, {"IOR": 2.0}),
     ("P", (0.3, 0.5, 0.8), 0.3, {"Specular IOR Level": 1.0}),
     ("P", (0.3, 0.5, 0.8), 0.3, {"Specular Tint": (1.0, 0.5, 0.5, 1.0)})],
    [("G", (0.8, 0.8, 0.8), 0.3, {}), ("G", (0.9, 0.5, 0.2), 0.7, {}), ("D", (0.7, 0.7, 0.7), 0.0, {}),
     ("P", (0.7, 0.7, 0.7), 0.4, {"Metallic": 0.5}), ("P", (1.0, 1.0, 1.0), 1.0, {}),
     ("P", (0.0, 0.0, 0.0), 0.5, {})],
]


# Mix and Add shaders (one row): ("MIX", fac or "TEX" (a checker image), A, B) / ("ADD", A, B), leaves as above.
MIX_GRID = [[
    ("MIX", 0.3, ("D", (0.8, 0.2, 0.1), 0.0, {}), ("G", (1.0, 1.0, 1.0), 0.3, {})),
    ("ADD", ("D", (0.4, 0.4, 0.4), 0.0, {}), ("G", (0.5, 0.5, 0.5), 0.5, {})),
    ("MIX", 0.5, ("P", (0.2, 0.6, 0.3), 0.2, {}), ("P", (0.9, 0.7, 0.4), 0.8, {"Metallic": 1.0})),
    ("MIX", "TEX", ("D", (0.8, 0.1, 0.1), 0.0, {}), ("D", (0.1, 0.2, 0.8), 0.0, {})),
    ("MIX", 0.6, ("MIX", 0.5, ("D", (0.6, 0.6, 0.2), 0.0, {}), ("G", (0.8, 0.8, 0.8), 0.2, {})),
     ("P", (0.3, 0.3, 0.9), 0.6, {})),
    ("ADD", ("E", (1.0, 0.5, 0.2), 0.5, {}), ("P", (0.5, 0.5, 0.5), 0.4, {})),
]]

# Principled Coat (one row, leaves as in SPHERE_GRID): a clear coat on red plastic, a tinted coat on white, a
# lacquered metal, the coat alone on black (IOR 2, rough: the lobe and its energy compensation), a half-weight
# tinted coat of IOR 1.3 on green, and a coated Principled inside a Mix shader.
_COAT = {"Coat Weight": 1.0, "Coat Roughness": 0.15}
COAT_GRID = [[
    ("P", (0.8, 0.1, 0.1), 0.5, dict(_COAT)),
    ("P", (0.8, 0.8, 0.8), 0.5, {"Coat Weight": 1.0, "Coat Roughness": 0.3, "Coat Tint": (0.9, 0.4, 0.2, 1.0)}),
    ("P", (0.9, 0.7, 0.4), 0.4, {"Metallic": 1.0, "Coat Weight": 0.5, "Coat Roughness": 0.25}),
    ("P", (0.0, 0.0, 0.0), 0.5, {"Coat Weight": 1.0, "Coat Roughness": 0.5, "Coat IOR": 2.0}),
    ("P", (0.2, 0.7, 0.2), 0.6, {"Coat Weight": 0.5, "Coat IOR": 1.3, "Coat Roughness": 0.2,
                                 "Coat Tint": (0.5, 0.8, 1.0, 1.0)}),
    ("MIX", 0.5, ("P", (0.1, 0.2, 0.8), 0.4, dict(_COAT)), ("D", (0.7, 0.7, 0.7), 0.0, {})),
]]

# Coats whose inputs vary or interact (coat_graph_spheres wires the graphs): Coat Weight from a Noise Texture, a
# bumped Normal the coat follows, a bump on the Coat Normal alone, emission under a tinted coat, Coat Roughness
# from a Noise Texture at IOR 1.8, a coat on a half-transparent (Alpha 0.6) base.
COAT_GRAPH_GRID = [[
    ("P", (0.8, 0.3, 0.1), 0.5, {"Coat Weight": 1.0, "Coat Roughness": 0.2}),
    ("P", (0.3, 0.6, 0.8), 0.4, {"Coat Weight": 1.0, "Coat Roughness": 0.1}),
    ("P", (0.7, 0.7, 0.7), 0.5, {"Coat Weight": 1.0, "Coat Roughness": 0.3}),
    ("P", (0.1, 0.1, 0.1), 0.5, {"Coat Weight": 1.0, "Coat Roughness": 0.2, "Coat Tint": (0.3, 0.5, 1.0, 1.0),
                                 "Emission Color": (1.0, 0.5, 0.2, 1.0), "Emission Strength": 2.0}),
    ("P", (0.5, 0.5, 0.5), 0.5, {"Coat Weight": 1.0, "Coat IOR": 1.8}),
    ("P", (0.8, 0.8, 0.2), 0.5, {"Coat Weight": 1.0, "Coat Roughness": 0.2, "Alpha": 0.6}),
]]


# Anisotropic GGX (one row): Principled metals (Anisotropic 0.8; 0.5 at Rotation 0.125), a red dielectric at
# Anisotropic 1, Glossy BSDFs (Anisotropy 0.8; -0.6 at Rotation 0.3), and a metal whose Tangent is the UV map's
# (aniso_spheres wires it); the others take the default radial tangent about the object's Z axis.
ANISO_GRID = [[
    ("P", (0.9, 0.6, 0.3), 0.3, {"Metallic": 1.0, "Anisotropic": 0.8}),
    ("P", (0.8, 0.8, 0.8), 0.5, {"Metallic": 1.0, "Anisotropic": 0.5, "Anisotropic Rotation": 0.125}),
    ("P", (0.8, 0.1, 0.1), 0.25, {"Anisotropic": 1.0}),
    ("G", (0.8, 0.8, 0.8), 0.4, {"Anisotropy": 0.8}),
    ("G", (0.9, 0.5, 0.2), 0.4, {"Anisotropy": -0.6, "Rotation": 0.3}),
    ("P", (0.7, 0.8, 0.9), 0.35, {"Metallic": 1.0, "Anisotropic": 0.9}),
]]


# Principled Sheen (one row): Weight 1 at Sheen Roughness 0.5 and 0.2 on blue, a half-weight rough sheen on red (its
# Tint a Noise Texture: sheen_spheres), a sheen over a metal, the sheen alone over a black base, a sheen on grey (its
# Roughness a Noise Texture).
SHEEN_GRID = [[
    ("P", (0.2, 0.4, 0.8), 0.5, {"Sheen Weight": 1.0, "Sheen Roughness": 0.5}),
    ("P", (0.2, 0.4, 0.8), 0.5, {"Sheen Weight": 1.0, "Sheen Roughness": 0.2}),
    ("P", (0.8, 0.2, 0.2), 0.4, {"Sheen Weight": 0.5, "Sheen Roughness": 0.8, "Sheen Tint": (1.0, 0.8, 0.6, 1.0)}),
    ("P", (0.9, 0.6, 0.3), 0.4, {"Metallic": 1.0, "Sheen Weight": 1.0, "Sheen Roughness": 0.5}),
    ("P", (0.0, 0.0, 0.0), 0.3, {"Sheen Weight": 1.0, "Sheen Roughness": 0.3}),
    ("P", (0.5, 0.5, 0.5), 0.5, {"Sheen Weight": 1.0, "Sheen Roughness": 1.0}),
]]


def sheen_spheres(size=(144, 24), sheen=True):
    """material_spheres of :data:`SHEEN_GRID` (every Sheen Weight 0 without ``sheen``), the third sphere's Sheen
    Tint and the last's Sheen Roughness from Noise Textures."""
    grid = SHEEN_GRID if sheen else [[(k, c, r, {**e, "Sheen Weight": 0.0}) for k, c, r, e in SHEEN_GRID[0]]]
    scene = material_spheres("AREA", size, grid)
    for c, socket, output in ((2, "Sheen Tint", "Color"), (5, "Sheen Roughness", "Fac")):
        tree = bpy.data.materials[f"M0{c}"].node_tree
        noise = tree.nodes.new("ShaderNodeTexNoise")
        noise.inputs["Scale"].default_value = 6.0
        tree.links.new(noise.outputs[output], tree.nodes["Principled BSDF"].inputs[socket])
    return scene


# Subsurface scattering (Principled Random Walk unless named): (base, roughness, Subsurface Weight, Radius, Scale,
# extra inputs, method). Scales are per Blender series: 5.2's Random Walk takes Radius x Scale as the mean free path,
# 5.0's divides it by 4π (subsurface_spheres picks the series' column), so both see light bleed through the 0.4 spheres
SSS_GRID = [
    ((0.8, 0.5, 0.3), 0.5, 1.0, (1.0, 0.2, 0.1), (1.5, 0.15), {}, "RANDOM_WALK"),
    ((0.9, 0.9, 0.9), 0.3, 1.0, (1.0, 1.0, 1.0), (3.0, 0.3), {}, "RANDOM_WALK"),
    ((0.2, 0.6, 0.8), 0.4, 0.5, (0.5, 1.0, 1.0), (2.0, 0.2), {}, "RANDOM_WALK"),
    ((0.8, 0.6, 0.5), 0.5, 1.0, (1.0, 0.4, 0.2), (3.0, 3.0), {}, "RANDOM_WALK_SKIN"),
    ((0.7, 0.7, 0.3), 0.5, 1.0, (1.0, 1.0, 1.0), (2.0, 0.2), {"Subsurface Anisotropy": 0.5}, "RANDOM_WALK"),
    ((0.6, 0.3, 0.6), 0.2, 1.0, (1.0, 0.5, 1.0), (2.0, 0.2), {}, "RANDOM_WALK"),
]


def subsurface_spheres(size=(144, 24), sss=True):
    """material_spheres of :data:`SSS_GRID` (every Subsurface Weight 0 without ``sss``: what rendering the share as
    the diffuse lobe gives), the last sphere's Subsurface Weight from a Noise Texture."""
    mfp = bpy.app.version >= (5, 2, 0)
    grid = [[("P", c, r, {"Subsurface Weight": w if sss else 0.0, "Subsurface Radius": rad,
                          "Subsurface Scale": sc[1] if mfp else sc[0], **extra})
             for c, r, w, rad, sc, extra, _method in SSS_GRID]]
    scene = material_spheres("AREA", size, grid)
    for k, (*_rest, method) in enumerate(SSS_GRID):
        node = bpy.data.materials[f"M0{k}"].node_tree.nodes["Principled BSDF"]
        node.subsurface_method = method
        if method == "RANDOM_WALK_SKIN":  # (the socket is found by name only while the method shows it)
            node.inputs["Subsurface IOR"].default_value = 1.3
    if sss:
        tree = bpy.data.materials[f"M0{len(SSS_GRID) - 1}"].node_tree
        noise = tree.nodes.new("ShaderNodeTexNoise")
        noise.inputs["Scale"].default_value = 4.0
        tree.links.new(noise.outputs["Fac"], tree.nodes["Principled BSDF"].inputs["Subsurface Weight"])
    return scene


def aniso_spheres(size=(144, 24), isotropic=False):
    """material_spheres of :data:`ANISO_GRID`, the last sphere's Tangent from a Tangent node (UV map); with
    ``isotropic`` every Anisotropic / Anisotropy set to 0 (what ignoring anisotropy would render)."""
    grid = ANISO_GRID
    if isotropic:
        grid = [[(k, c, r, {key: (0.0 if key in ("Anisotropic", "Anisotropy") else v) for key, v in extra.items()})
                 for k, c, r, extra in row] for row in ANISO_GRID]
    scene = material_spheres("AREA", size, grid)
    tree = bpy.data.materials["M05"].node_tree
    tan = tree.nodes.new("ShaderNodeTangent")
    tan.direction_type = "UV_MAP"
    tree.links.new(tan.outputs["Tangent"], tree.nodes["Principled BSDF"].inputs["Tangent"])
    return scene


def coat_graph_spheres(size=(144, 24)):
    """material_spheres of :data:`COAT_GRAPH_GRID` with its node graphs wired in (see there)."""
    scene = material_spheres("AREA", size, COAT_GRAPH_GRID)

    def node_tree(c):
        tree = bpy.data.materials[f"M0{c}"].node_tree
        return tree, tree.nodes["Principled BSDF"]

    def noise(tree, scale):
        n = tree.nodes.new("ShaderNodeTexNoise")
        n.inputs["Scale"].default_value = scale
        return n

    def bump(tree, height, strength):
        b = tree.nodes.new("ShaderNodeBump")
        b.inputs["Strength"].default_value = strength
        tree.links.new(height, b.inputs["Height"])
        return b

    tree, p = node_tree(0)
    tree.links.new(noise(tree, 6.0).outputs["Fac"], p.inputs["Coat Weight"])
    tree, p = node_tree(1)
    vor = tree.nodes.new("ShaderNodeTexVoronoi")
    vor.inputs["Scale"].default_value = 8.0
    tree.links.new(bump(tree, vor.outputs["Distance"], 0.6).outputs["Normal"], p.inputs["Normal"])
    tree, p = node_tree(2)
    tree.links.new(bump(tree, noise(tree, 10.0).outputs["Fac"], 0.8).outputs["Normal"], p.inputs["Coat Normal"])
    tree, p = node_tree(4)
    tree.links.new(noise(tree, 4.0).outputs["Fac"], p.inputs["Coat Roughness"])
    return scene


def point_cloud_scene(size=(96, 64)):
    """A point cloud made by Geometry Nodes (Mesh to Points on a 5 x 4 grid, radius 0.3; Cycles traces each point
    as a sphere; the points carry no material: Blender's default) above a grey floor, and one
    point cloud datablock of three points of radii 0.15-0.35 with a blue Diffuse, lit by an area light."""
    scene = reset()
    plane("Floor", 10, (0, 0, 0), material=diffuse("Floor", (0.5, 0.5, 0.5)))
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=4, y_subdivisions=3, size=3.0, location=(-0.6, 0.5, 0.6))
    grid = bpy.context.active_object
    tree = bpy.data.node_groups.new("ToPoints", "GeometryNodeTree")
    tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    gin, gout = tree.nodes.new("NodeGroupInput"), tree.nodes.new("NodeGroupOutput")
    to_points = tree.nodes.new("GeometryNodeMeshToPoints")
    to_points.inputs["Radius"].default_value = 0.3
    tree.links.new(gin.outputs[0], to_points.inputs["Mesh"])
    tree.links.new(to_points.outputs[0], gout.inputs[0])
    grid.modifiers.new("Points", "NODES").node_group = tree
    cloud = bpy.data.pointclouds.new("Cloud") if hasattr(bpy.data, "pointclouds") else None
    if cloud is not None and hasattr(cloud, "resize"):  # bpy 5.1+
        cloud.resize(3)
        cloud.attributes["position"].data.foreach_set("vector", np.array([1.6, -0.6, 0.35, 2.1, 0.4, 0.25, 1.2, 0.6,
                                                                          0.5], np.float32))
        cloud.attributes.new("radius", "FLOAT", "POINT").data.foreach_set("value", np.array([0.35, 0.25, 0.15],
                                                                                             np.float32))
        cloud.materials.append(diffuse("Cloud", (0.1, 0.3, 0.8)))
        scene.collection.objects.link(bpy.data.objects.new("Cloud", cloud))
    light("AREA", (-1.5, -2.0, 4.0), (math.radians(30), 0, math.radians(-20)), energy=150.0, size=2.0)
    camera((0.3, -5.5, 3.0), (math.radians(62), 0, 0), lens=32)
    black_world(scene)
    scene.render.resolution_x, scene.render.resolution_y = size
    return scene


def packed_image(name, rgb: np.ndarray):
    """A Non-Color float image made in memory from ``rgb`` (h, w, 3), row 0 at the bottom, alpha 1, packed."""
    h, w = rgb.shape[:2]
    img = bpy.data.images.new(name, w, h, float_buffer=True)
    img.colorspace_settings.name = "Non-Color"
    px = np.ones((h, w, 4), np.float32)
    px[..., :3] = rgb
    img.pixels.foreach_set(px.ravel())
    img.pack()
    return img


def checker_image(name="Checker", n=8):
    """An n x n black/white checker (Non-Color), made in memory."""
    ij = (np.add.outer(np.arange(n), np.arange(n)) % 2).astype(np.float32)
    return packed_image(name, np.repeat(ij[..., None], 3, axis=2))


def _shader_node(tree, spec):
    """A shader node for a grid spec (leaf or MIX/ADD), linked below; returns the node."""
    nodes, links = tree.nodes, tree.links
    kind = spec[0]
    if kind in ("MIX", "ADD"):
        node = nodes.new("ShaderNodeMixShader" if kind == "MIX" else "ShaderNodeAddShader")
        subs = spec[2:] if kind == "MIX" else spec[1:]
        shader_inputs = [s for s in node.inputs if s.type == "SHADER"]
        for socket, sub_spec in zip(shader_inputs, subs):
            links.new(_shader_node(tree, sub_spec).outputs[0], socket)
        if kind == "MIX":
            if spec[1] == "TEX":
                tex = nodes.new("ShaderNodeTexImage")
                tex.image = bpy.data.images.get("Checker") or checker_image()
                tex.interpolation = "Closest"
                links.new(tex.outputs["Color"], node.inputs["Fac"])
            else:
                node.inputs["Fac"].default_value = spec[1]
        return node
    _k, color, roughness, extra = spec
    if kind == "D":
        node = nodes.new("ShaderNodeBsdfDiffuse")
        node.inputs["Color"].default_value = (*color, 1)
        node.inputs["Roughness"].default_value = 0.0
    elif kind == "G":
        node = nodes.new("ShaderNodeBsdfGlossy")
        node.inputs["Color"].default_value = (*color, 1)
        node.inputs["Roughness"].default_value = roughness
    elif kind == "E":
        node = nodes.new("ShaderNodeEmission")
        node.inputs["Color"].default_value = (*color, 1)
        node.inputs["Strength"].default_value = roughness
    else:
        node = nodes.new("ShaderNodeBsdfPrincipled")
        node.inputs["Base Color"].default_value = (*color, 1)
        node.inputs["Roughness"].default_value = roughness
        for key, value in extra.items():
            node.inputs[key].default_value = value
    return node


def _spec_material(name, spec):
    m = bpy.data.materials.new(name)
    enable_nodes(m)
    tree = m.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    tree.links.new(_shader_node(tree, spec).outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    return m


# Rough diffuse (Oren–Nayar): Diffuse BSDFs of roughness 0.3 / 0.6 / 1, Principled Diffuse Roughness 0.5 / 1,
# and a Lambert Diffuse BSDF beside them.
ROUGH_DIFFUSE_GRID = [[("D", (0.8, 0.5, 0.3), 0.3, {}), ("D", (0.8, 0.5, 0.3), 0.6, {}), ("D", (0.8, 0.5, 0.3), 1.0, {}),
                       ("P", (0.3, 0.6, 0.8), 0.5, {"Diffuse Roughness": 0.5}),
                       ("P", (0.3, 0.6, 0.8), 0.5, {"Diffuse Roughness": 1.0}), ("D", (0.8, 0.5, 0.3), 0.0, {})]]


def _grid_material(name, kind, color, roughness, extra):
    if kind == "D":
        m = diffuse(name, color)
        m.node_tree.nodes["Diffuse BSDF"].inputs["Roughness"].default_value = roughness
        return m
    if kind == "G":
        m = bpy.data.materials.new(name)
        enable_nodes(m)
        nodes = m.node_tree.nodes
        nodes.remove(nodes["Principled BSDF"])
        g = nodes.new("ShaderNodeBsdfGlossy")
        g.inputs["Color"].default_value = (*color, 1)
        g.inputs["Roughness"].default_value = roughness
        for key, value in extra.items():
            g.inputs[key].default_value = value
        m.node_tree.links.new(g.outputs[0], nodes["Material Output"].inputs["Surface"])
        return m
    m = principled(name, color, roughness=roughness)
    b = m.node_tree.nodes["Principled BSDF"]
    for key, value in extra.items():
        b.inputs[key].default_value = value
    return m


def material_spheres(light_kind="AREA", size=(144, 96), grid=None):
    """A 6-column grid of smooth spheres (one cell of the image each; :data:`SPHERE_GRID` by default, 4 rows, or
    :data:`MIX_GRID`) in front of a grey Diffuse wall, seen by an orthographic camera along +Y, lit from the upper
    left front by an area light or an emissive quad of the same size. Every view angle of every material is in
    the image (sphere rims are grazing). ``size`` must keep one cell square (width / 6 = height / rows)."""
    scene = reset()
    grid = SPHERE_GRID if grid is None else grid
    top = (len(grid) - 1) / 2
    for r, row in enumerate(grid):
        for c, spec in enumerate(row):
            bpy.ops.mesh.primitive_uv_sphere_add(radius=0.4, location=(c - 2.5, 0, top - r), segments=32,
                                                 ring_count=16)
            obj = bpy.context.active_object
            bpy.ops.object.shade_smooth()
            mat = _spec_material(f"M{r}{c}", spec) if spec[0] in ("MIX", "ADD") else _grid_material(f"M{r}{c}", *spec)
            obj.data.materials.append(mat)
    plane("Wall", 1, (0, 1.5, 0), (math.pi / 2, 0, 0), material=diffuse("Wall", (0.5, 0.5, 0.5)), scale=(8, 6, 1))
    rot = (math.radians(45), 0, math.radians(-30))
    if light_kind == "AREA":
        light("AREA", (-2.5, -4.5, 4.0), rot, energy=2000.0, size=3.0)
    else:
        plane("Lamp", 3.0, (-2.5, -4.5, 4.0), rot, material=emission("Lamp", (1, 1, 1), 60.0))
    camera((0, -6, 0), (math.radians(90), 0, 0), ortho_scale=6.0)
    black_world(scene)
    scene.render.resolution_x, scene.render.resolution_y = size
    return scene


def grazing_floor(size=(96, 64)):
    """Four floor strips running away from a low perspective camera (Principled roughness 1, Principled 0.5,
    metal 0.5, Diffuse BSDF), lit by two area lights: the far image rows see the floor at grazing angles."""
    scene = reset()
    mats = [principled("Rough", (0.6, 0.6, 0.6), roughness=1.0), principled("Mid", (0.6, 0.6, 0.6), roughness=0.5),
            principled("Metal", (0.9, 0.8, 0.6), roughness=0.5, metallic=1.0), diffuse("Diffuse", (0.6, 0.6, 0.6))]
    for i, m in enumerate(mats):
        plane(f"Strip{i}", 1, (-1.5 + i, 6, 0), material=m, scale=(1, 14, 1))
    light("AREA", (-2, 4, 3), (math.radians(-30), 0, 0), energy=400.0, size=2.0)
    light("AREA", (2, 12, 3), (math.radians(30), 0, 0), energy=600.0, size=3.0)
    camera((0, -1.5, 0.6), (math.radians(70), 0, 0), lens=22)
    black_world(scene)
    scene.render.resolution_x, scene.render.resolution_y = size
    return scene


def _with_uvs(obj):
    """Give a quad made by ``plane`` a UV map covering it once."""
    uv = obj.data.uv_layers.new(name="UVMap")
    uv.data.foreach_set("uv", np.array([0, 0, 1, 0, 1, 1, 0, 1], np.float32))
    return obj


def alpha_scene(size=(96, 64)):
    """Cut-outs: a Principled plane of Alpha 0.4 and a plane whose Mix(Transparent, Diffuse) factor is a checker
    image, standing on a floor in front of an orange wall; an area light above and in front casts their shadows on
    the floor, and the camera sees the wall through them."""
    scene = reset()
    plane("Floor", 8, (0, 0, 0), material=diffuse("Floor", (0.7, 0.7, 0.7)))
    plane("Wall", 8, (0, 2, 2), (math.pi / 2, 0, 0), material=diffuse("Wall", (0.8, 0.5, 0.2)))
    glass = principled("Veil", (0.2, 0.4, 0.9), roughness=0.6)
    glass.node_tree.nodes["Principled BSDF"].inputs["Alpha"].default_value = 0.4
    plane("Veil", 1.6, (-1.0, 0.5, 0.9), (math.pi / 2, 0, 0.3), material=glass)
    def checker(tree):
        tex = tree.nodes.new("ShaderNodeTexImage")
        tex.image = bpy.data.images.get("Checker") or checker_image()
        tex.interpolation = "Closest"
        return tex.outputs["Color"]
    fence = see_through("Fence", (0.2, 0.8, 0.3), checker, transparent_at_one=False)
    _with_uvs(plane("Fence", 1.6, (1.0, 0.5, 0.9), (math.pi / 2, 0, -0.3), material=fence))
    light("AREA", (0, -1.5, 3.5), (math.radians(35), 0, 0), energy=500.0, size=1.5)
    camera((0, -4, 1.0), (math.radians(90), 0, 0), lens=30)
    black_world(scene)
    scene.render.resolution_x, scene.render.resolution_y = size
    return scene


def see_through(name, color, factor, transparent_at_one):
    """A material mixing a Diffuse ``color`` and a Transparent BSDF by the socket ``factor(tree)`` returns (nodes it
    adds to the material's tree): the Transparent BSDF where the factor reads 1 (``transparent_at_one``) or where
    it reads 0."""
    mat = bpy.data.materials.new(name)
    enable_nodes(mat)
    tree = mat.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    mix = tree.nodes.new("ShaderNodeMixShader")
    clear = tree.nodes.new("ShaderNodeBsdfTransparent")
    body = tree.nodes.new("ShaderNodeBsdfDiffuse")
    body.inputs["Color"].default_value = (*color, 1)
    tree.links.new(factor(tree), mix.inputs["Fac"])
    first, second = (body, clear) if transparent_at_one else (clear, body)
    tree.links.new(first.outputs[0], mix.inputs[1])
    tree.links.new(second.outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    return mat


def _ray_switched(name, color, output):
    """:func:`see_through`, transparent to the rays Light Path ``output`` marks."""
    return see_through(name, color, lambda tree: tree.nodes.new("ShaderNodeLightPath").outputs[output], True)


def light_path_scene(size=(96, 64)):
    """Surfaces that hide from one kind of ray through Light Path: a red plane transparent to shadow rays (seen,
    casting no shadow) and a blue one transparent to camera rays (unseen, casting its shadow), over a floor in front
    of a wall, under an area light."""
    scene = reset()
    plane("Floor", 8, (0, 0, 0), material=diffuse("Floor", (0.7, 0.7, 0.7)))
    plane("Wall", 8, (0, 2, 2), (math.pi / 2, 0, 0), material=diffuse("Wall", (0.6, 0.6, 0.5)))
    plane("NoShadow", 1.4, (-1.0, 0.3, 0.9), (math.pi / 2, 0, 0.3),
          material=_ray_switched("NoShadow", (0.8, 0.1, 0.1), "Is Shadow Ray"))
    plane("Unseen", 1.4, (1.0, 0.3, 0.9), (math.pi / 2, 0, -0.3),
          material=_ray_switched("Unseen", (0.1, 0.2, 0.8), "Is Camera Ray"))
    light("AREA", (0, -1.5, 3.5), (math.radians(35), 0, 0), energy=500.0, size=1.5)
    camera((0, -4, 1.0), (math.radians(90), 0, 0), lens=30)
    black_world(scene)
    scene.render.resolution_x, scene.render.resolution_y = size
    return scene


def shadowless_veils_scene(size=(96, 64)):
    """Principled sheets of Alpha 0.5 whose Material > Transparent Shadows is off (as the glTF importer leaves blended
    materials), under an area light and a constant grey world: a sheet standing on the floor and an open box over
    it, in front of a wall. Cycles blocks the lamp's shadow rays at them as if opaque but lights with the constant
    world through rays that bounce off the surfaces, which pass them as transparent."""
    scene = reset()
    plane("Floor", 8, (0, 0, 0), material=diffuse("Floor", (0.7, 0.7, 0.7)))
    plane("Wall", 8, (0, 2, 2), (math.pi / 2, 0, 0), material=diffuse("Wall", (0.6, 0.6, 0.5)))
    veil = principled("Veil", (0.2, 0.4, 0.9), roughness=0.6)
    veil.node_tree.nodes["Principled BSDF"].inputs["Alpha"].default_value = 0.5
    veil.use_transparent_shadow = False
    plane("Sheet", 1.4, (-1.0, 0.3, 0.9), (math.pi / 2, 0, 0.3), material=veil)
    bpy.ops.mesh.primitive_cube_add(size=1.2, location=(1.0, 0.3, 0.6))
    box = bpy.context.active_object
    box.data.materials.append(veil)
    light("AREA", (0, -1.5, 3.5), (math.radians(35), 0, 0), energy=300.0, size=1.5)
    camera((0, -4, 1.2), (math.radians(85), 0, 0), lens=30)
    world = bpy.data.worlds.new("Grey")
    enable_nodes(world)
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.35, 0.35, 0.35, 1)
    scene.world = world
    scene.render.resolution_x, scene.render.resolution_y = size
    return scene


def tinted_scene(size=(96, 64)):
    """Coloured transparency: a plane of a red Transparent BSDF alone, and a plane mixing a Diffuse (0.4) with a
    Transparent BSDF whose Color is a blue-to-yellow gradient along the plane (a per-hit tint), standing on a floor
    in front of a light wall; an area light above and in front throws their coloured shadows on the floor, and the
    camera sees the wall through them."""
    scene = reset()
    plane("Floor", 8, (0, 0, 0), material=diffuse("Floor", (0.7, 0.7, 0.7)))
    plane("Wall", 8, (0, 2, 2), (math.pi / 2, 0, 0), material=diffuse("Wall", (0.8, 0.8, 0.7)))
    red = bpy.data.materials.new("RedFilm")
    enable_nodes(red)
    tree = red.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    film = tree.nodes.new("ShaderNodeBsdfTransparent")
    film.inputs["Color"].default_value = (0.9, 0.25, 0.15, 1)
    tree.links.new(film.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    plane("RedFilm", 1.6, (-1.0, 0.5, 0.9), (math.pi / 2, 0, 0.3), material=red)
    glaze = bpy.data.materials.new("Glaze")
    enable_nodes(glaze)
    tree = glaze.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    mix = tree.nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = 0.4
    clear = tree.nodes.new("ShaderNodeBsdfTransparent")
    coord = tree.nodes.new("ShaderNodeTexCoord")
    grad = tree.nodes.new("ShaderNodeTexGradient")
    ramp = tree.nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].color = (0.15, 0.35, 0.95, 1)
    ramp.color_ramp.elements[1].color = (0.95, 0.85, 0.1, 1)
    tree.links.new(coord.outputs["UV"], grad.inputs["Vector"])
    tree.links.new(grad.outputs["Fac"], ramp.inputs["Fac"])
    tree.links.new(ramp.outputs["Color"], clear.inputs["Color"])
    green = tree.nodes.new("ShaderNodeBsdfDiffuse")
    green.inputs["Color"].default_value = (0.3, 0.7, 0.3, 1)
    tree.links.new(clear.outputs[0], mix.inputs[1])
    tree.links.new(green.outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    _with_uvs(plane("Glaze", 1.6, (1.0, 0.5, 0.9), (math.pi / 2, 0, -0.3), material=glaze))
    light("AREA", (0, -1.5, 3.5), (math.radians(35), 0, 0), energy=500.0, size=1.5)
    camera((0, -4, 1.0), (math.radians(90), 0, 0), lens=30)
    black_world(scene)
    scene.render.resolution_x, scene.render.resolution_y = size
    return scene


def sky_image(name="Sky", h=64, w=128, sun=(0.0, 40.0)):
    """An equirectangular float image: a dim blue sky, dark ground and a small bright sun at (azimuth, elevation)
    degrees (Blender's Environment Texture convention: u = 1/2 - atan2(y, x)/2π, v = 1 - θ/π), packed."""
    img = bpy.data.images.new(name, w, h, float_buffer=True)
    px = np.zeros((h, w, 4), np.float32)
    px[..., 3] = 1
    px[h // 2:, :, :3] = (0.15, 0.25, 0.45)
    px[:h // 2, :, :3] = (0.05, 0.04, 0.03)
    az, el = np.radians(sun[0]), np.radians(sun[1])
    col = int((0.5 - az / (2 * np.pi)) % 1.0 * w)
    row = int((1.0 - (np.pi / 2 - el) / np.pi) * h)
    px[row:row + 2, col:col + 2, :3] = (400.0, 350.0, 300.0)
    img.pixels.foreach_set(px.ravel())
    img.pack()
    return img


def world_scene(kind="IMAGE", size=(96, 64), rotation_z=0.0):
    """Spheres (diffuse, rough Principled, metal) on a grey floor under the world: an environment image (sky with
    a sun, :func:`sky_image`, its Mapping rotated by ``rotation_z`` radians), a constant colour, a procedural
    gradient sky ("GRADIENT": a Color Ramp over the direction's height, Strength from a Math node) or the sky image
    multiplied by a colour by a Noise of the direction ("MIXED") or lighting with the sky image and seen by the
    camera as a flat colour (Light Path > Is Camera Ray, "CAMERA_RAY"); no lamps."""
    scene = reset()
    plane("Floor", 20, (0, 0, 0), material=diffuse("Floor", (0.5, 0.5, 0.5)))
    for x, mat in ((-1.2, diffuse("D", (0.8, 0.3, 0.2))), (0.0, principled("P", (0.3, 0.6, 0.8), roughness=0.4)),
                   (1.2, principled("M", (0.9, 0.8, 0.6), roughness=0.3, metallic=1.0))):
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(x, 0, 0.5), segments=32, ring_count=16)
        bpy.ops.object.shade_smooth()
        bpy.context.active_object.data.materials.append(mat)
    world = bpy.data.worlds.new("World")
    enable_nodes(world)
    tree = world.node_tree
    bg = tree.nodes["Background"]
    if kind == "IMAGE":
        env = tree.nodes.new("ShaderNodeTexEnvironment")
        env.image = sky_image()
        mapping = tree.nodes.new("ShaderNodeMapping")
        mapping.inputs["Rotation"].default_value = (0.0, 0.0, rotation_z)
        coords = tree.nodes.new("ShaderNodeTexCoord")
        tree.links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
        tree.links.new(mapping.outputs["Vector"], env.inputs["Vector"])
        tree.links.new(env.outputs["Color"], bg.inputs["Color"])
    elif kind == "GRADIENT":  # a procedural sky: a ramp over the direction's height, strength through Math
        coords = tree.nodes.new("ShaderNodeTexCoord")
        sep = tree.nodes.new("ShaderNodeSeparateXYZ")
        tree.links.new(coords.outputs["Generated"], sep.inputs["Vector"])
        ramp = tree.nodes.new("ShaderNodeValToRGB")
        ramp.color_ramp.elements[0].position = 0.45
        ramp.color_ramp.elements[0].color = (0.05, 0.04, 0.03, 1)
        ramp.color_ramp.elements[1].position = 0.8
        ramp.color_ramp.elements[1].color = (0.5, 0.7, 1.0, 1)
        remap = tree.nodes.new("ShaderNodeMapRange")
        remap.inputs["From Min"].default_value = -1.0
        tree.links.new(sep.outputs["Z"], remap.inputs["Value"])
        tree.links.new(remap.outputs["Result"], ramp.inputs["Fac"])
        tree.links.new(ramp.outputs["Color"], bg.inputs["Color"])
        math_node = tree.nodes.new("ShaderNodeMath")
        math_node.operation = "MULTIPLY"
        math_node.inputs[0].default_value = 0.75
        math_node.inputs[1].default_value = 2.0
        tree.links.new(math_node.outputs[0], bg.inputs["Strength"])
    elif kind == "MIXED":  # the sky image tinted by a noise of the direction
        env = tree.nodes.new("ShaderNodeTexEnvironment")
        env.image = sky_image()
        noise = tree.nodes.new("ShaderNodeTexNoise")
        noise.inputs["Scale"].default_value = 2.0
        mix = tree.nodes.new("ShaderNodeMix")
        mix.data_type = "RGBA"
        mix.blend_type = "MULTIPLY"
        tree.links.new(noise.outputs["Fac"], mix.inputs["Factor"])
        tree.links.new(env.outputs["Color"], mix.inputs[6])
        mix.inputs[7].default_value = (1.0, 0.5, 0.2, 1.0)
        tree.links.new(mix.outputs[2], bg.inputs["Color"])
    elif kind == "CAMERA_RAY":  # lit by the sky image, seen as a flat grey-blue backdrop (Light Path)
        env = tree.nodes.new("ShaderNodeTexEnvironment")
        env.image = sky_image()
        path = tree.nodes.new("ShaderNodeLightPath")
        mix = tree.nodes.new("ShaderNodeMix")
        mix.data_type = "RGBA"
        tree.links.new(path.outputs["Is Camera Ray"], mix.inputs["Factor"])
        tree.links.new(env.outputs["Color"], mix.inputs[6])
        mix.inputs[7].default_value = (0.2, 0.25, 0.35, 1.0)
        tree.links.new(mix.outputs[2], bg.inputs["Color"])
    else:
        bg.inputs["Color"].default_value = (0.4, 0.5, 0.7, 1)
    if kind not in {"GRADIENT"}:
        bg.inputs["Strength"].default_value = 1.0
    scene.world = world
    camera((0, -4.5, 1.6), (math.radians(75), 0, 0), lens=35)
    scene.render.resolution_x, scene.render.resolution_y = size
    return scene


def bump_normal_image(name="Bumps", n=64, waves=4, slope=0.6):
    """A tangent-space normal map (Non-Color) of ridges along u: normal ∝ (-slope cos(2π waves u), 0, 1)."""
    u = (np.arange(n) + 0.5) / n
    nx = -slope * np.cos(2 * np.pi * waves * u)
    nrm = np.stack([nx, np.zeros(n), np.ones(n)], axis=1)
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    return packed_image(name, np.broadcast_to((0.5 + 0.5 * nrm)[None, :, :], (n, n, 3)))


def _image_normal(name, image, node_type, image_socket, **inputs):
    """A Principled BSDF (roughness 0.4) whose Normal comes from a ``node_type`` node (inputs set from
    ``inputs``) fed by an Image Texture of ``image`` on its ``image_socket``; returns (material, node)."""
    m = principled(name, (0.7, 0.6, 0.5), roughness=0.4)
    tree = m.node_tree
    tex = tree.nodes.new("ShaderNodeTexImage")
    tex.image = image
    node = tree.nodes.new(node_type)
    for key, value in inputs.items():
        node.inputs[key].default_value = value
    tree.links.new(tex.outputs["Color"], node.inputs[image_socket])
    tree.links.new(node.outputs["Normal"], tree.nodes["Principled BSDF"].inputs["Normal"])
    return m, node


def _ridged(name, strength):
    image = bpy.data.images.get("Bumps") or bump_normal_image()
    return _image_normal(name, image, "ShaderNodeNormalMap", "Color", Strength=strength)[0]


def normal_map_scene(size=(96, 64), sphere=False):
    """A floor (Normal Map strength 1) and a wall behind it (rotated 90° about its normal, strength 0.5) whose
    Principled BSDFs (roughness 0.4) have a tangent-space Normal Map of ridges (:func:`bump_normal_image`), lit by
    a low area light from the side: the ridges' facets light up or not. ``sphere`` adds a normal-mapped UV sphere
    (smooth MikkTSpace tangents; see docs/CONVENTIONS.md for what differs from Cycles there)."""
    scene = reset()
    _with_uvs(plane("Floor", 4, (0, 0, 0), material=_ridged("Ridged", 1.0)))
    _with_uvs(plane("Wall", 4, (0, 2, 2), (math.pi / 2, 0, 0), material=_ridged("Ridged wall", 0.5)))
    bpy.data.objects["Wall"].rotation_euler = (math.pi / 2, math.pi / 2, 0)
    if sphere:
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.6, location=(0.6, 0.4, 0.6), segments=32, ring_count=16)
        bpy.ops.object.shade_smooth()
        bpy.context.active_object.data.materials.append(_ridged("Ridged sphere", 1.0))
    light("AREA", (-3, 0.5, 1.2), (0, math.radians(-70), 0), energy=300.0, size=1.0)
    camera((0, -3.2, 2.4), (math.radians(55), 0, 0), lens=30)
    black_world(scene)
    scene.render.resolution_x, scene.render.resolution_y = size
    return scene


def ridge_height_image(name="Heights", n=64, waves=4):
    """A Non-Color height map of ridges along u: H = 0.5 + 0.5 sin(2π waves u), grey."""
    h = 0.5 + 0.5 * np.sin(2 * np.pi * waves * (np.arange(n) + 0.5) / n)
    return packed_image(name, np.broadcast_to(h[None, :, None], (n, n, 3)))


def _bumped(name, strength, distance, invert=False):
    image = bpy.data.images.get("Heights") or ridge_height_image()
    m, bump = _image_normal(name, image, "ShaderNodeBump", "Height", Strength=strength, Distance=distance)
    bump.invert = invert
    return m


def bump_scene(size=(96, 64)):
    """:func:`normal_map_scene`'s layout with Bump nodes on a height map of ridges (:func:`ridge_height_image`)
    instead of normal maps: the floor at strength 1, distance 0.3 (slopes up to 0.47 over its 4 m); the wall
    at strength 0.5, distance 0.3, inverted."""
    scene = reset()
    _with_uvs(plane("Floor", 4, (0, 0, 0), material=_bumped("Bumped", 1.0, 0.3)))
    _with_uvs(plane("Wall", 4, (0, 2, 2), (math.pi / 2, 0, 0), material=_bumped("Bumped wall", 0.5, 0.3, True)))
    bpy.data.objects["Wall"].rotation_euler = (math.pi / 2, math.pi / 2, 0)
    light("AREA", (-3, 0.5, 1.2), (0, math.radians(-70), 0), energy=300.0, size=1.0)
    camera((0, -3.2, 2.4), (math.radians(55), 0, 0), lens=30)
    black_world(scene)
    scene.render.resolution_x, scene.render.resolution_y = size
    return scene


def glass_material(name, kind, ior=1.45, color=(1.0, 1.0, 1.0), transmission=1.0, roughness=0.0):
    """A glass: kind "GLASS" (Glass BSDF), "REFRACTION" (Refraction BSDF) or "PRINCIPLED" (Transmission Weight
    ``transmission``), smooth unless ``roughness``."""
    if kind in ("GLASS", "REFRACTION"):
        from harness.scenes import _replace_surface
        m, g = _replace_surface(name, "ShaderNodeBsdfGlass" if kind == "GLASS" else "ShaderNodeBsdfRefraction")
        g.inputs["Color"].default_value = (*color, 1)
        g.inputs["Roughness"].default_value = roughness
        g.inputs["IOR"].default_value = ior
        return m
    m = principled(name, color, roughness=roughness)
    b = m.node_tree.nodes["Principled BSDF"]
    b.inputs["IOR"].default_value = ior
    b.inputs["Transmission Weight"].default_value = transmission
    return m


def glass_scene(size=(96, 64), only=None, window=False, roughness=None, materials=None):
    """Three smooth glass spheres in front of a checkered wall on a grey floor, lit by an area light from above
    and the front: a Glass BSDF (IOR 1.45), a tinted Principled with Transmission 1 (IOR 1.5) and a red Principled
    with Transmission 0.5 (half glass, half diffuse under a clear coat of reflection); ``only``: just that one;
    ``window``: a 2 cm glass pane across the lower half of the view in front of them; ``roughness``: the three
    spheres' roughness (r, r, r) instead of smooth; ``materials``: three materials for the spheres instead."""
    scene = reset()
    plane("Floor", 8, (0, 0, 0), material=diffuse("Floor", (0.5, 0.5, 0.5)))
    wall = principled("Checker wall", (1, 1, 1), roughness=1.0)
    tex = wall.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = checker_image("Wall checker", 8)
    tex.interpolation = "Closest"
    wall.node_tree.links.new(tex.outputs["Color"], wall.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
    _with_uvs(plane("Wall", 6, (0, 1.2, 2), (math.pi / 2, 0, 0), material=wall))
    r = roughness or (0.0, 0.0, 0.0)
    specs = [(-1.1, glass_material("Glass", "GLASS", roughness=r[0])),
             (0.0, glass_material("Tinted", "PRINCIPLED", 1.5, (0.8, 0.9, 1.0), roughness=r[1])),
             (1.1, glass_material("Half", "PRINCIPLED", 1.5, (0.8, 0.3, 0.2), transmission=0.5, roughness=r[2]))]
    if materials is not None:
        specs = [(x, m()) for (x, _old), m in zip(specs, materials)]
    for x, mat in specs if only is None else [specs[only]]:
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(x, 0.0, 0.5), segments=48, ring_count=24)
        bpy.ops.object.shade_smooth()
        bpy.context.active_object.data.materials.append(mat)
    if window:
        bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0.0, -2.6, 0.6))
        pane = bpy.context.active_object
        pane.scale = (4.0, 0.02, 1.2)
        pane.data.materials.append(glass_material("Pane", "GLASS", 1.5))
    light("AREA", (0, -2.0, 3.5), (math.radians(30), 0, 0), energy=400.0, size=2.0)
    camera((0, -4.2, 1.3), (math.radians(83), 0, 0), lens=35)
    black_world(scene)
    scene.render.resolution_x, scene.render.resolution_y = size
    return scene


def refraction_scene(size=(96, 64)):
    """glass_scene with Refraction BSDFs: smooth (IOR 1.45), tinted and rough (0.3), IOR 1.2 slightly rough (0.1)."""
    return glass_scene(size, materials=[lambda: glass_material("Refraction", "REFRACTION"),
                                        lambda: glass_material("Tinted refraction", "REFRACTION", 1.45,
                                                               (0.9, 0.6, 0.3), roughness=0.3),
                                        lambda: glass_material("Low refraction", "REFRACTION", 1.2, roughness=0.1)])


def absorbing_glass_scene(size=(96, 64)):
    """glass_scene with smooth Glass BSDFs (IOR 1.45) filled with Volume Absorption: amber (Color (0.9, 0.5, 0.2),
    Density 2 per metre of the 1 m spheres), blue through a Mix Shader of two absorptions (Color (0.2, 0.4, 0.9),
    Density 3 at factor 0.5 with Density 0), and a Principled glass with a dense green (Color (0.3, 0.9, 0.3),
    Density 4)."""
    def absorbing(name, kind, color, density, mix=False):
        def make():
            m = glass_material(name, kind)
            tree = m.node_tree
            out = next(n for n in tree.nodes if n.type == "OUTPUT_MATERIAL")
            vol = tree.nodes.new("ShaderNodeVolumeAbsorption")
            vol.inputs["Color"].default_value = (*color, 1)
            vol.inputs["Density"].default_value = density
            if not mix:
                tree.links.new(vol.outputs[0], out.inputs["Volume"])
                return m
            clear = tree.nodes.new("ShaderNodeVolumeAbsorption")
            clear.inputs["Density"].default_value = 0.0
            mixer = tree.nodes.new("ShaderNodeMixShader")
            mixer.inputs[0].default_value = 0.5
            tree.links.new(clear.outputs[0], mixer.inputs[1])
            tree.links.new(vol.outputs[0], mixer.inputs[2])
            tree.links.new(mixer.outputs[0], out.inputs["Volume"])
            return m
        return make
    return glass_scene(size, materials=[absorbing("Amber", "GLASS", (0.9, 0.5, 0.2), 2.0),
                                        absorbing("Blue", "GLASS", (0.2, 0.4, 0.9), 3.0, mix=True),
                                        absorbing("Green", "PRINCIPLED", (0.3, 0.9, 0.3), 4.0)])


def beckmann_glass_scene(size=(96, 64)):
    """glass_scene with Glass BSDFs of the Beckmann distribution: roughness 0.3 (IOR 1.45), 0.5 tinted, 0.15 (IOR
    1.2)."""
    def beckmann(name, ior, color, roughness):
        def make():
            m = glass_material(name, "GLASS", ior, color, roughness=roughness)
            m.node_tree.nodes["Glass BSDF"].distribution = "BECKMANN"
            return m
        return make
    return glass_scene(size, materials=[beckmann("Beckmann", 1.45, (1, 1, 1), 0.3),
                                        beckmann("Tinted Beckmann", 1.45, (0.9, 0.6, 0.3), 0.5),
                                        beckmann("Low Beckmann", 1.2, (1, 1, 1), 0.15)])


def node_planes(graphs, cols: int, px: int = 16, name="Nodes"):
    """Emission planes facing an orthographic camera, one per ``graphs`` entry in a grid of ``cols`` columns
    (row 0 at the top), each ``px`` pixels square: ``graph(tree, color_socket)`` wires nodes into the Emission
    shader's Color (strength 1); ``graph.setup(obj)``, where present, sets up its plane. Planes are 1 x 1 with a
    UV map covering them; Generated coordinates span [0, 1]
    over each, object coordinates [-0.5, 0.5]. No lights, a black world: each pixel is its pattern's radiance."""
    scene = reset()
    black_world(scene)
    rows = (len(graphs) + cols - 1) // cols
    for k, graph in enumerate(graphs):
        r, c = divmod(k, cols)
        mat = emission(f"{name}{k}", (1, 1, 1), 1.0)
        tree = mat.node_tree
        graph(tree, tree.nodes["Emission"].inputs["Color"])
        obj = _with_uvs(plane(f"{name}Plane{k}", 1.0, (c + 0.5 - cols / 2, rows / 2 - r - 0.5, 0), material=mat))
        if hasattr(graph, "setup"):  # per-object state the graph reads (a tilt, a colour attribute, Object Color)
            graph.setup(obj)
    camera((0, 0, 5), (0, 0, 0), ortho_scale=max(cols, rows))
    scene.render.resolution_x, scene.render.resolution_y = cols * px, rows * px
    return scene


def derived_attributes_scene(size=(128, 64)):
    """Geometry > Pointiness (red) and Random Per Island (green) through an Emission shader (blue 0.2), seen by a
    camera under a black world: a Suzanne under a Subdivision Surface (three islands: the head and the eyes) and
    one mesh of eight rotated cubes (eight islands) under a three-segment Bevel. Each pixel is the attributes'
    value; no lights."""
    import bmesh
    scene = reset()
    black_world(scene)
    mat = emission("Derived", (1, 1, 1), 1.0)
    tree = mat.node_tree
    geo = tree.nodes.new("ShaderNodeNewGeometry")
    comb = tree.nodes.new("ShaderNodeCombineColor")
    comb.inputs["Blue"].default_value = 0.2
    tree.links.new(geo.outputs["Pointiness"], comb.inputs["Red"])
    tree.links.new(geo.outputs["Random Per Island"], comb.inputs["Green"])
    tree.links.new(comb.outputs["Color"], tree.nodes["Emission"].inputs["Color"])
    bpy.ops.mesh.primitive_monkey_add(location=(-1.3, 0, 0))
    monkey = bpy.context.object
    monkey.data.materials.append(mat)
    sub = monkey.modifiers.new("Subdivision", "SUBSURF")
    sub.levels = sub.render_levels = 1
    bm = bmesh.new()
    rng = np.random.default_rng(7)
    for k in range(8):
        rot = rng.uniform(0, math.pi, 3)
        m = (mathutils.Matrix.Translation(((k % 4) * 0.55 + 0.55, 0, (k // 4) * 0.6 - 0.3)) @
             mathutils.Euler(rot).to_matrix().to_4x4() @ mathutils.Matrix.Scale(0.22, 4))
        bmesh.ops.create_cube(bm, size=1.0, matrix=m)
    data = bpy.data.meshes.new("Cubes")
    bm.to_mesh(data)
    bm.free()
    cubes = bpy.data.objects.new("Cubes", data)
    scene.collection.objects.link(cubes)
    data.materials.append(mat)
    bevel = cubes.modifiers.new("Bevel", "BEVEL")
    bevel.width, bevel.segments = 0.05, 3
    camera((0, -6, 0), (math.pi / 2, 0, 0), lens=50.0)
    scene.render.resolution_x, scene.render.resolution_y = size
    return scene


def _with_falloff(lamp_obj, output, strength, smooth=0.0):
    """Wire a Light Falloff node's ``output`` (Quadratic, Linear, Constant) into the lamp's Emission Strength."""
    data = lamp_obj.data
    if data.node_tree is None:  # Blender 5.0 lights still make their node tree on use_nodes
        data.use_nodes = True
    tree = data.node_tree
    em = next(n for n in tree.nodes if n.type == "EMISSION")
    fo = tree.nodes.new("ShaderNodeLightFalloff")
    fo.inputs["Strength"].default_value = strength
    fo.inputs["Smooth"].default_value = smooth
    tree.links.new(fo.outputs[output], em.inputs["Strength"])


def falloff_scene(size=(96, 64)):
    """A long grey floor and a back wall lit by three lamps whose strength goes through Light Falloff nodes: a point
    lamp with Linear falloff, a spot lamp with Constant falloff and Smooth 2, and a small area lamp with Quadratic
    falloff and Smooth 1; the camera looks down the floor, so the lit points lie at distances of 0.5 to 6 m."""
    scene = reset()
    black_world(scene)
    floor_mat = diffuse("Floor", (0.6, 0.6, 0.6))
    plane("Floor", 1.0, (0, 2, 0), material=floor_mat, scale=(4, 8, 1))
    plane("Wall", 1.0, (0, 6, 2), rotation=(math.pi / 2, 0, 0), material=diffuse("Wall", (0.5, 0.6, 0.7)),
          scale=(4, 4, 1))
    _with_falloff(light("POINT", (-1.0, 0.0, 1.0), energy=40.0, shadow_soft_size=0.1), "Linear", 1.0)
    _with_falloff(light("SPOT", (1.0, 3.0, 2.5), rotation=(0.5, 0, 0), energy=20.0, shadow_soft_size=0.1,
                        spot_size=1.2, spot_blend=0.3), "Constant", 0.3, smooth=2.0)
    _with_falloff(light("AREA", (0.0, 4.0, 1.5), rotation=(-1.2, 0, 0), energy=60.0, size=0.5), "Quadratic", 1.0,
                  smooth=1.0)
    camera((0, -2.5, 1.6), (math.radians(70), 0, 0), lens=24.0)
    scene.render.resolution_x, scene.render.resolution_y = size
    return scene


def node_materials_scene(size=(96, 64)):
    """Lit materials whose inputs come from node graphs: a floor whose Roughness and Metallic come from a Checker
    through Map Range and whose Base Color is Noise through a Color Ramp; a sphere with Base Color from a Gradient
    of object coordinates and Roughness from Noise; a sphere mixing Diffuse and Glossy by a Layer Weight's Facing;
    a quad light whose emission is a Checker (a textured light by node program), and an area light."""
    import node_graphs as ng
    scene = reset()
    floor = bpy.data.materials.new("NodeFloor")
    enable_nodes(floor)
    t = floor.node_tree
    b = t.nodes["Principled BSDF"]
    chk = ng._node(t, "ShaderNodeTexChecker")
    ng._set(chk, "Scale", 4.0)
    mr = ng._node(t, "ShaderNodeMapRange")
    ng._set(mr, "To Min", 0.15)
    ng._set(mr, "To Max", 0.8)
    t.links.new(chk.outputs["Fac"], mr.inputs["Value"])
    t.links.new(mr.outputs["Result"], b.inputs["Roughness"])
    inv = ng._node(t, "ShaderNodeMath", operation="SUBTRACT")
    ng._set(inv, "Value", 1.0)
    t.links.new(chk.outputs["Fac"], inv.inputs[1])
    t.links.new(inv.outputs[0], b.inputs["Metallic"])
    ng.ramp("EASE")(t, b.inputs["Base Color"])
    plane("Floor", 4.0, (0, 0, 0), material=floor)
    s1 = bpy.data.materials.new("NodeSphere")
    enable_nodes(s1)
    t = s1.node_tree
    b = t.nodes["Principled BSDF"]
    ng.gradient("LINEAR")(t, b.inputs["Base Color"])
    ng.noise(output="Fac", scale=3.0)(t, b.inputs["Roughness"])
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(-0.7, 0.2, 0.5), segments=32, ring_count=16)
    bpy.ops.object.shade_smooth()
    bpy.context.active_object.data.materials.append(s1)
    s2 = bpy.data.materials.new("NodeMix")
    enable_nodes(s2)
    t = s2.node_tree
    t.nodes.remove(t.nodes["Principled BSDF"])
    mix = t.nodes.new("ShaderNodeMixShader")
    d = t.nodes.new("ShaderNodeBsdfDiffuse")
    d.inputs["Color"].default_value = (0.8, 0.2, 0.1, 1)
    gl = t.nodes.new("ShaderNodeBsdfGlossy")
    gl.inputs["Roughness"].default_value = 0.3
    lw = t.nodes.new("ShaderNodeLayerWeight")
    lw.inputs["Blend"].default_value = 0.4
    t.links.new(lw.outputs["Facing"], mix.inputs["Fac"])
    t.links.new(d.outputs[0], mix.inputs[1])
    t.links.new(gl.outputs[0], mix.inputs[2])
    t.links.new(mix.outputs[0], t.nodes["Material Output"].inputs["Surface"])
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.45, location=(0.75, -0.1, 0.45), segments=32, ring_count=16)
    bpy.ops.object.shade_smooth()
    bpy.context.active_object.data.materials.append(s2)
    lamp = emission("NodeLamp", (1, 1, 1), 12.0)
    ng.checker(2.0)(lamp.node_tree, lamp.node_tree.nodes["Emission"].inputs["Color"])
    _with_uvs(plane("NodeLampQuad", 1.2, (0, 1.9, 1.4), (math.radians(-60), 0, 0), material=lamp))
    light("AREA", (-1.5, -1.5, 2.5), (math.radians(40), 0, math.radians(-45)), energy=150.0, size=1.0)
    camera((0, -3.6, 2.2), (math.radians(62), 0, 0), lens=35)
    black_world(scene)
    scene.render.resolution_x, scene.render.resolution_y = size
    return scene


def bumped_materials_scene(size=(96, 64)):
    """Shading normals from node graphs, lit: a floor bumped by a Voronoi F1 distance (and coloured by Brick), a
    sphere bumped by Noise (Strength 0.7, over a Principled base), a sphere whose tangent-space Normal Map takes a
    Noise colour mixed towards flat, and a cube with a world-space Normal Map of a Wave; an area light and a point
    light."""
    import node_graphs as ng
    scene = reset()

    def principled(name, color, rough):
        m = bpy.data.materials.new(name)
        enable_nodes(m)
        b = m.node_tree.nodes["Principled BSDF"]
        b.inputs["Base Color"].default_value = (*color, 1)
        b.inputs["Roughness"].default_value = rough
        return m, m.node_tree, b

    floor, t, b = principled("BumpFloor", (0.7, 0.7, 0.7), 0.35)
    vor = ng._node(t, "ShaderNodeTexVoronoi")
    ng._set(vor, "Scale", 3.0)
    bump = ng._node(t, "ShaderNodeBump")
    ng._set(bump, "Distance", 0.3)
    t.links.new(vor.outputs["Distance"], bump.inputs["Height"])
    t.links.new(bump.outputs["Normal"], b.inputs["Normal"])
    ng.brick(scale=2.0)(t, b.inputs["Base Color"])
    plane("Floor", 4.0, (0, 0, 0), material=floor)
    s1, t, b = principled("BumpSphere", (0.8, 0.4, 0.2), 0.3)
    nz = ng._node(t, "ShaderNodeTexNoise")
    ng._set(nz, "Scale", 6.0)
    bump = ng._node(t, "ShaderNodeBump", invert=True)
    ng._set(bump, "Strength", 0.7)
    t.links.new(nz.outputs["Fac"], bump.inputs["Height"])
    t.links.new(bump.outputs["Normal"], b.inputs["Normal"])
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(-0.75, 0.2, 0.5), segments=32, ring_count=16)
    bpy.ops.object.shade_smooth()
    bpy.context.active_object.data.materials.append(s1)
    s2, t, b = principled("MappedSphere", (0.3, 0.5, 0.8), 0.25)
    nz = ng._node(t, "ShaderNodeTexNoise")
    ng._set(nz, "Scale", 4.0)
    mix = ng._node(t, "ShaderNodeMix", data_type="RGBA")
    mix.inputs["Factor"].default_value = 0.6
    ng._in(mix, "A_Color").default_value = (0.5, 0.5, 1.0, 1.0)
    t.links.new(nz.outputs["Color"], ng._in(mix, "B_Color"))
    nm = ng._node(t, "ShaderNodeNormalMap", space="TANGENT")
    t.links.new(ng._out(mix, "Result_Color"), nm.inputs["Color"])
    t.links.new(nm.outputs["Normal"], b.inputs["Normal"])
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.45, location=(0.75, -0.1, 0.45), segments=32, ring_count=16)
    bpy.ops.object.shade_smooth()
    bpy.context.active_object.data.materials.append(s2)
    s3, t, b = principled("WorldMappedCube", (0.6, 0.6, 0.3), 0.4)
    wave = ng._node(t, "ShaderNodeTexWave")
    ng._set(wave, "Scale", 3.0)
    comb = ng._node(t, "ShaderNodeCombineXYZ")
    t.links.new(wave.outputs["Fac"], comb.inputs["X"])
    comb.inputs["Y"].default_value = 0.5
    comb.inputs["Z"].default_value = 1.0
    nm = ng._node(t, "ShaderNodeNormalMap", space="WORLD")
    ng._set(nm, "Strength", 0.5)
    t.links.new(comb.outputs["Vector"], nm.inputs["Color"])
    t.links.new(nm.outputs["Normal"], b.inputs["Normal"])
    bpy.ops.mesh.primitive_cube_add(size=0.5, location=(0.0, 0.9, 0.25), rotation=(0, 0, 0.5))
    bpy.context.active_object.data.materials.append(s3)
    light("AREA", (-1.5, -1.5, 2.5), (math.radians(40), 0, math.radians(-45)), energy=150.0, size=1.0)
    light("POINT", (1.5, -0.5, 1.6), (0, 0, 0), energy=60.0)
    camera((0, -3.6, 2.2), (math.radians(62), 0, 0), lens=35)
    black_world(scene)
    scene.render.resolution_x, scene.render.resolution_y = size
    return scene


def panorama_scene(kind, size=(64, 32)):
    """A panoramic camera ``kind`` in a room of emission walls, one colour per direction, over a diffuse checker
    floor they light, looking along +Y turned by 10°, with a bright tag ahead: what a pixel sees tells its
    direction."""
    import node_graphs as ng
    scene = reset()
    black_world(scene)
    faces = [((0, 3, 0), (math.radians(90), 0, 0), (0.9, 0.2, 0.2)), ((0, -3, 0), (math.radians(90), 0, 0),
             (0.2, 0.9, 0.2)), ((3, 0, 0), (0, math.radians(90), 0), (0.2, 0.3, 0.9)),
             ((-3, 0, 0), (0, math.radians(90), 0), (0.9, 0.8, 0.2)), ((0, 0, 3), (0, 0, 0), (0.8, 0.3, 0.9)),
             ((0, 0, -3), (0, 0, 0), None)]
    for k, (loc, rot, color) in enumerate(faces):
        if color is None:  # the floor: a diffuse checker lit by the walls
            mat = bpy.data.materials.new("PanoFloor")
            enable_nodes(mat)
            ng.checker(4.0)(mat.node_tree, mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"])
        else:
            mat = emission(f"PanoWall{k}", color, 1.0)
        plane(f"PanoWall{k}", 6.0, loc, rot, material=mat)
    tag = emission("PanoTag", (1.0, 1.0, 1.0), 3.0)  # a bright square ahead and up-right: orientation
    plane("PanoTag", 1.0, (1.0, 2.9, 0.8), (math.radians(90), 0, 0), material=tag)
    camera((0.2, -0.3, 0.1), (math.radians(90), 0, math.radians(10)))
    cam = scene.camera.data
    cam.type = "PANO"
    cam.panorama_type = kind
    if kind == "EQUIRECTANGULAR":
        cam.latitude_min, cam.latitude_max = math.radians(-70), math.radians(80)
        cam.longitude_min, cam.longitude_max = math.radians(-150), math.radians(170)
    elif kind == "FISHEYE_EQUIDISTANT":
        cam.fisheye_fov = math.radians(200)
    cam.clip_start = 0.01
    scene.render.resolution_x, scene.render.resolution_y = size
    return scene


def motion_blur_scene(size=(96, 64), shutter=1.0, camera_pans=False, spin=True, deform=False):
    """Frame 2 of an animation under an area light: a cube flies across a diffuse floor (1 m per frame, linear
    keys), a glowing bar spins about its centre (90° per frame, linear), with ``camera_pans`` the camera turns 8°
    per frame, with ``deform`` a glowing sheet's vertices slide 0.6 m per frame (a shape key); Render > Motion Blur
    on with ``shutter`` (frames)."""
    scene = reset()
    black_world(scene)
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.frame_start, scene.frame_end = 1, 3
    plane("Floor", 8.0, (0, 0, 0), material=diffuse("Floor", (0.7, 0.7, 0.7)))
    light("AREA", (0, 0, 3.0), energy=200.0, size=1.0)
    bpy.ops.mesh.primitive_cube_add(size=0.6, location=(-1.5, -0.4, 0.5))
    cube = bpy.context.active_object
    cube.data.materials.append(diffuse("Cube", (0.8, 0.3, 0.2)))
    cube.keyframe_insert("location", frame=1)
    cube.location.x = 0.5
    cube.keyframe_insert("location", frame=3)
    keyed = [cube]
    if spin:
        bar = plane("Bar", 1.0, (1.2, 0.6, 0.8), material=emission("Bar", (0.3, 0.6, 1.0), 4.0), scale=(1.0, 0.15, 1))
        bar.keyframe_insert("rotation_euler", frame=1)
        bar.rotation_euler.z = math.pi
        bar.keyframe_insert("rotation_euler", frame=3)
        keyed.append(bar)
    if deform:
        bpy.ops.mesh.primitive_grid_add(x_subdivisions=8, y_subdivisions=2, size=1.2, location=(-0.6, 1.0, 0.05))
        sheet = bpy.context.active_object
        sheet.data.materials.append(emission("Sheet", (1.0, 0.8, 0.3), 3.0))
        sheet.shape_key_add(name="Basis")
        up = sheet.shape_key_add(name="Sweep")
        for v in up.data:
            v.co.x += 1.2  # the sheet's vertices slide 1.2 m along x (its object stays)
        up.value = 0.0
        up.keyframe_insert("value", frame=1)
        up.value = 1.0
        up.keyframe_insert("value", frame=3)
        keyed.append(sheet.data.shape_keys)
    cam = camera((0, -4.5, 3.5), (math.radians(52), 0, 0), lens=30.0)
    if camera_pans:
        cam.keyframe_insert("rotation_euler", frame=1)
        cam.rotation_euler.z = math.radians(16)
        cam.keyframe_insert("rotation_euler", frame=3)
        keyed.append(cam)
    for obj in keyed:
        for fc in _anim_fcurves(obj):
            for k in fc.keyframe_points:
                k.interpolation = "LINEAR"
    scene.frame_set(2)
    scene.render.use_motion_blur = True
    scene.render.motion_blur_shutter = shutter
    return scene


def _anim_fcurves(obj):
    from harness.scenes import _fcurves
    return _fcurves(obj)


def translucent_material(name, color, mix_with=None, textured=False):
    """A Translucent BSDF of ``color``; ``mix_with``: half of it a Diffuse BSDF of that colour (Mix Shader at 0.5);
    ``textured``: its Color from the checker image through the plane's UVs."""
    m = bpy.data.materials.new(name)
    enable_nodes(m)
    tree = m.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    node = tree.nodes.new("ShaderNodeBsdfTranslucent")
    node.inputs["Color"].default_value = (*color, 1)
    if textured:
        tex = tree.nodes.new("ShaderNodeTexImage")
        tex.image = bpy.data.images.get("Checker") or checker_image()
        tex.interpolation = "Closest"
        tree.links.new(tex.outputs["Color"], node.inputs["Color"])
    out = node
    if mix_with is not None:
        dif = tree.nodes.new("ShaderNodeBsdfDiffuse")
        dif.inputs["Color"].default_value = (*mix_with, 1)
        out = tree.nodes.new("ShaderNodeMixShader")
        out.inputs["Fac"].default_value = 0.5
        tree.links.new(dif.outputs[0], out.inputs[1])
        tree.links.new(node.outputs[0], out.inputs[2])
    tree.links.new(out.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    return m


def translucent_scene(size=(96, 64), back="AREA"):
    """Four upright 1 x 1.4 panels in a row facing the camera, lit from behind (``back``: an area light the camera
    does not see, or a sun) and weakly from the front, on a grey floor: a white Translucent BSDF, a green one, a Mix
    of Diffuse and Translucent at 0.5, and a checker-textured Translucent. The panels' fronts show the light they
    pass through; the floor in front of them is lit through them."""
    scene = reset()
    black_world(scene)
    plane("Floor", 10, (0, 0, 0), material=diffuse("Floor", (0.5, 0.5, 0.5)))
    mats = [translucent_material("Translucent", (0.8, 0.8, 0.8)),
            translucent_material("Green translucent", (0.3, 0.8, 0.2)),
            translucent_material("Leaf", (0.6, 0.7, 0.3), mix_with=(0.5, 0.6, 0.2)),
            translucent_material("Textured translucent", (1, 1, 1), textured=True)]
    for k, mat in enumerate(mats):
        _with_uvs(plane(f"Panel{k}", 1.0, (-1.65 + 1.1 * k, 0, 0.8), (math.pi / 2, 0, 0), material=mat,
                        scale=(1, 1.4, 1)))
    if back == "AREA":
        lamp = light("AREA", (0, 2.0, 1.2), (math.radians(-90), 0, 0), energy=600.0, size=4.0)
        lamp.visible_camera = False
    else:
        light("SUN", (0, 3, 3), (math.radians(-60), 0, 0), energy=4.0, angle=math.radians(3))
    light("AREA", (0, -3.0, 2.5), (math.radians(50), 0, 0), energy=60.0, size=1.5)
    camera((0, -4.5, 1.0), (math.radians(88), 0, 0), lens=35)
    scene.render.resolution_x, scene.render.resolution_y = size
    return scene


def shadow_catcher_scene(size=(64, 48), transparent=False, catcher_pass=False):
    """A red cube and a white sphere on a grey floor that is a shadow catcher (Object > Visibility > Mask > Shadow
    Catcher), lit by an area light under a blue-grey world; ``transparent``: Film > Transparent (set again after
    configure_cycles, which turns it off); ``catcher_pass``: the Shadow Catcher pass is written (Cycles' and ours)."""
    scene = reset()
    world = bpy.data.worlds.new("Sky")
    enable_nodes(world)
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.2, 0.3, 0.5, 1)
    scene.world = world
    plane("Floor", 6, (0, 0, 0), material=diffuse("Floor", (0.8, 0.8, 0.8))).is_shadow_catcher = True
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(-0.6, 0, 0.5))
    bpy.context.active_object.data.materials.append(diffuse("Red", (0.8, 0.1, 0.1)))
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.4, location=(0.7, -0.3, 0.4), segments=32, ring_count=16)
    bpy.ops.object.shade_smooth()
    bpy.context.active_object.data.materials.append(diffuse("White", (0.8, 0.8, 0.8)))
    light("AREA", (1, -1, 3), energy=300.0, size=1.0)
    camera((0, -5, 2.5), (math.radians(65), 0, 0), lens=35)
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.film_transparent = transparent
    layer = scene.view_layers[0]
    layer.cycles.use_pass_shadow_catcher = catcher_pass
    layer.restir.use_pass_shadow_catcher = catcher_pass
    return scene


def _lamp_tree(lamp_obj):
    """(node tree, its Emission node) of a lamp, nodes on."""
    data = lamp_obj.data
    data.use_nodes = True
    tree = data.node_tree
    return tree, next(n for n in tree.nodes if n.type == "EMISSION")


#: the lamps of :func:`textured_lamp_scene`
TEXTURED_LAMPS = ("point", "spot", "area", "rotated", "attributes")


def textured_lamp_scene(kind: str, size=(64, 64)):
    """A white diffuse floor seen from above (orthographic) lit by one lamp whose Emission comes from a node graph
    that varies over it, as artists texture lamps: ``point`` a tiny point lamp whose Color is a Checker of Texture
    Coordinate Normal (an IES-like pattern) and whose Strength grows along the Normal's X; ``spot`` a spot lamp of radius 0.15
    projecting a 16 x 16 image of colour ramps and squares through Texture Coordinate UV (a gobo); ``area`` a
    rectangular area lamp whose Color is its UV and whose Strength is a Checker of Object coordinates; ``rotated`` a
    turned, scaled point lamp of radius 0.15 (a sphere: its Normal is the sphere's at the light point) whose Color is
    a Gradient of Normal (object space) and Strength its UV's Y; ``attributes`` a point
    lamp whose Color is an Attribute node of Object type (a custom property of the lamp object) times a Checker of
    its Normal, and whose Strength is a View Layer attribute (a custom property of the scene)."""
    import node_graphs as ng
    scene = reset()
    black_world(scene)
    plane("Floor", 8.0, (0, 0, 0), material=diffuse("Floor", (0.8, 0.8, 0.8)))
    camera((0, 0, 10), (0, 0, 0), ortho_scale=4.0)
    scene.render.resolution_x, scene.render.resolution_y = size
    if kind in ("point", "rotated", "attributes"):
        lamp = light("POINT", (0.2, -0.1, 1.0), energy=60.0, shadow_soft_size=0.0)
    elif kind == "spot":
        # a radius: the cone's edge is blurred by where on the sphere the light leaves (Cycles' attenuation of the
        # direction from the light point, not from the centre)
        lamp = light("SPOT", (0.0, 0.0, 2.0), energy=150.0, shadow_soft_size=0.15, spot_size=1.3, spot_blend=0.1)
        lamp.rotation_euler = (0.0, 0.15, 0.4)
    else:
        lamp = light("AREA", (0.1, 0.0, 0.8), energy=40.0, shape="RECTANGLE", size=1.2, size_y=0.7)
        lamp.rotation_euler = (0.0, 0.0, 0.5)
    t, em = _lamp_tree(lamp)
    tc = ng._node(t, "ShaderNodeTexCoord")
    if kind == "point":
        chk = ng._node(t, "ShaderNodeTexChecker")
        ng._set(chk, "Scale", 3.0)
        chk.inputs["Color1"].default_value = (1.0, 0.3, 0.1, 1.0)
        chk.inputs["Color2"].default_value = (0.1, 0.4, 1.0, 1.0)
        t.links.new(tc.outputs["Normal"], chk.inputs["Vector"])
        t.links.new(chk.outputs["Color"], em.inputs["Color"])
        sep = ng._node(t, "ShaderNodeSeparateXYZ")
        t.links.new(tc.outputs["Normal"], sep.inputs[0])
        mad = ng._node(t, "ShaderNodeMath", operation="MULTIPLY_ADD")
        mad.inputs[1].default_value, mad.inputs[2].default_value = 0.5, 1.0
        t.links.new(sep.outputs["X"], mad.inputs[0])
        t.links.new(mad.outputs[0], em.inputs["Strength"])
    elif kind == "spot":
        i, j = np.meshgrid(np.arange(16), np.arange(16))
        gobo = np.stack([i / 15, j / 15, ((i // 4 + j // 4) % 2) * 0.8 + 0.1], axis=2).astype(np.float32)
        tex = ng._node(t, "ShaderNodeTexImage")
        tex.image = packed_image("Gobo", gobo)
        t.links.new(tc.outputs["UV"], tex.inputs["Vector"])
        t.links.new(tex.outputs["Color"], em.inputs["Color"])
    elif kind == "area":
        t.links.new(tc.outputs["UV"], em.inputs["Color"])
        chk = ng._node(t, "ShaderNodeTexChecker")
        ng._set(chk, "Scale", 2.0)
        t.links.new(tc.outputs["Object"], chk.inputs["Vector"])
        mad = ng._node(t, "ShaderNodeMath", operation="ADD")
        mad.inputs[1].default_value = 0.3
        t.links.new(chk.outputs["Fac"], mad.inputs[0])
        t.links.new(mad.outputs[0], em.inputs["Strength"])
    elif kind == "attributes":
        lamp["tint"] = (1.0, 0.45, 0.2)
        scene["glow"] = 1.7
        obj_attr = ng._node(t, "ShaderNodeAttribute", attribute_type="OBJECT", attribute_name="tint")
        chk = ng._node(t, "ShaderNodeTexChecker")
        ng._set(chk, "Scale", 2.5)
        chk.inputs["Color2"].default_value = (0.3, 0.6, 1.0, 1.0)
        t.links.new(tc.outputs["Normal"], chk.inputs["Vector"])
        t.links.new(obj_attr.outputs["Color"], chk.inputs["Color1"])
        t.links.new(chk.outputs["Color"], em.inputs["Color"])
        layer_attr = ng._node(t, "ShaderNodeAttribute", attribute_type="VIEW_LAYER", attribute_name="glow")
        t.links.new(layer_attr.outputs["Fac"], em.inputs["Strength"])
    else:
        lamp.rotation_euler = (0.3, -0.2, 0.7)
        lamp.scale = (1.0, 1.5, 1.0)
        lamp.data.shadow_soft_size = 0.15  # a sphere: its Normal is the sphere's at the light point
        grad = ng._node(t, "ShaderNodeTexGradient")
        t.links.new(tc.outputs["Normal"], grad.inputs["Vector"])
        ramp = ng._node(t, "ShaderNodeValToRGB")
        ramp.color_ramp.elements[0].color = (0.1, 0.2, 1.0, 1.0)
        ramp.color_ramp.elements[1].color = (1.0, 0.6, 0.1, 1.0)
        t.links.new(grad.outputs["Fac"], ramp.inputs["Fac"])
        t.links.new(ramp.outputs["Color"], em.inputs["Color"])
        sep = ng._node(t, "ShaderNodeSeparateXYZ")
        t.links.new(tc.outputs["UV"], sep.inputs[0])
        mad = ng._node(t, "ShaderNodeMath", operation="ADD")
        mad.inputs[1].default_value = 0.25
        t.links.new(sep.outputs["Y"], mad.inputs[0])
        t.links.new(mad.outputs[0], em.inputs["Strength"])
    return scene


def srgb_byte_image(name="Texels", n=8):
    """An n x n 8-bit image in the sRGB colour space (as a PNG or JPEG from disk is), packed: saturated colours and
    greys side by side, so a magnified edge between two texels shows where the interpolation happens (sRGB values, as
    Cycles interpolates such images, or linear ones)."""
    i, j = np.meshgrid(np.arange(n), np.arange(n))
    rng = np.random.default_rng(11)
    px = np.ones((n, n, 4), np.float32)
    px[..., :3] = rng.choice([0.0, 0.1, 0.5, 0.9, 1.0], size=(n, n, 3))
    px[(i + j) % 3 == 0, :3] = 0.0
    img = bpy.data.images.new(name, n, n)
    img.colorspace_settings.name = "sRGB"
    img.pixels.foreach_set(px.ravel())
    img.pack()
    return img


#: how :func:`srgb_texture_planes` reads its image, one plane each
SRGB_READS = ("linear", "cubic", "closest", "mapped", "strength")


def srgb_texture_planes(px: int = 32):
    """Emission planes (:func:`node_planes`, one per :data:`SRGB_READS` entry) each showing :func:`srgb_byte_image`
    magnified (4 pixels per texel at ``px`` 32): its Color straight into the Emission (Linear: the material's image
    path), with Cubic or Closest interpolation, through a Mapping node (the node program's lookup), and as the
    Emission Strength (the colour read as a float, white emission)."""
    import node_graphs as ng

    def graph(kind):
        def wire(tree, color_socket):  # called after node_planes resets the file: the image made on first use
            img = bpy.data.images.get("Texels") or srgb_byte_image("Texels")
            tex = ng._node(tree, "ShaderNodeTexImage")
            tex.image = img
            tex.interpolation = {"cubic": "Cubic", "closest": "Closest"}.get(kind, "Linear")
            if kind == "mapped":
                tc = ng._node(tree, "ShaderNodeTexCoord")
                mp = ng._node(tree, "ShaderNodeMapping")
                mp.inputs["Scale"].default_value = (0.75, 0.75, 1.0)
                tree.links.new(tc.outputs["UV"], mp.inputs["Vector"])
                tree.links.new(mp.outputs["Vector"], tex.inputs["Vector"])
            if kind == "strength":
                tree.links.new(tex.outputs["Color"], color_socket.node.inputs["Strength"])
            else:
                tree.links.new(tex.outputs["Color"], color_socket)
        return wire
    return node_planes([graph(k) for k in SRGB_READS], 3, px, name="Srgb")


def ies_text(kind: str) -> str:
    """An LM-63 profile (photometric type C): ``full`` 0-180° vertical by 0-360° horizontal, lopsided (brighter
    towards +X, a lobe at 30° from straight down); ``quadrant`` a downlight given over 0-90° in both, which Cycles
    mirrors to the four quadrants."""
    if kind == "full":
        v = np.arange(0.0, 181.0, 15.0)
        h = np.arange(0.0, 361.0, 45.0)
        cd = [[(400 + 300 * np.cos(np.radians(a))) * np.exp(-((b - 30) / 35) ** 2) + 20 for b in v] for a in h]
    else:
        v = np.arange(0.0, 91.0, 10.0)
        h = np.array([0.0, 30.0, 60.0, 90.0])
        cd = [[(900 - 300 * a / 90) * np.cos(np.radians(b)) ** 2 + 50 for b in v] for a in h]
    rows = ["IESNA:LM-63-2002", "[TEST] restir_engine", "[MANUFAC] none", "TILT=NONE",
            f"1 1000 1.5 {len(v)} {len(h)} 1 2 0.3 0.3 0.1", "1.0 1.0 60"]
    rows.append(" ".join(f"{x:g}" for x in v))
    rows.append(" ".join(f"{x:g}" for x in h))
    rows += [" ".join(f"{x:.3f}" for x in col) for col in cd]
    return "\n".join(rows) + "\n"


#: the lamps of :func:`ies_lamp_scene`
IES_LAMPS = ("full", "quadrant", "turned")


def ies_lamp_scene(kind: str, size=(64, 64)):
    """A white floor seen from above lit by a small point lamp 1 m up whose Emission Strength is an IES Texture
    (:func:`ies_text`, internal text, unlinked vector): ``full`` the lopsided profile, ``quadrant`` the mirrored
    downlight, ``turned`` the lopsided profile on a lamp turned about Z and tilted."""
    import node_graphs as ng
    scene = reset()
    black_world(scene)
    plane("Floor", 8.0, (0, 0, 0), material=diffuse("Floor", (0.8, 0.8, 0.8)))
    camera((0, 0, 10), (0, 0, 0), ortho_scale=4.0)
    scene.render.resolution_x, scene.render.resolution_y = size
    lamp = light("POINT", (0.1, 0.2, 1.0), energy=20.0, shadow_soft_size=0.0)
    if kind == "turned":
        lamp.rotation_euler = (0.25, 0.0, 0.9)
    t, em = _lamp_tree(lamp)
    text = bpy.data.texts.new(f"profile_{kind}.ies")
    text.write(ies_text("quadrant" if kind == "quadrant" else "full"))
    node = ng._node(t, "ShaderNodeTexIES")
    node.mode = "INTERNAL"
    node.ies = text
    t.links.new(node.outputs["Fac"], em.inputs["Strength"])
    return scene


def sky_scene(model="MULTIPLE_SCATTERING", size=(128, 64), view="SEEN", **settings):
    """The world a Sky Texture of ``model`` with the node's ``settings`` (Sun Elevation / Rotation in radians as
    the node holds them); ``view`` "SEEN": an equirectangular camera over the whole sphere and nothing else, each
    pixel the sky in its direction; "HORIZON": 7° across the horizon towards +Y; "DISC": 2° about the sun (of Sun
    Rotation 0); "LIT": spheres (diffuse, rough Principled, metal) on a grey floor lit by it."""
    scene = reset()
    world = bpy.data.worlds.new("Sky")
    enable_nodes(world)
    tree = world.node_tree
    node = tree.nodes.new("ShaderNodeTexSky")
    node.sky_type = model
    for k, v in settings.items():
        setattr(node, k, v)
    tree.links.new(node.outputs["Color"], tree.nodes["Background"].inputs["Color"])
    scene.world = world
    if view == "HORIZON":  # a narrow view towards +Y (where a Sun Rotation of 0 puts the sun) across the horizon
        camera((0, 0, 0), (math.radians(90), 0, 0), lens=300)
    elif view == "DISC":  # a 2° view of the sun's disc (Sun Rotation 0 puts it towards +Y)
        camera((0, 0, 0), (math.radians(90) + settings.get("sun_elevation", math.radians(15)), 0, 0), lens=1000)
    elif view == "SEEN":
        camera((0, 0, 0), (math.radians(90), 0, 0))
        cam = scene.camera.data
        cam.type = "PANO"
        cam.panorama_type = "EQUIRECTANGULAR"
        cam.latitude_min, cam.latitude_max = math.radians(-90), math.radians(90)
        cam.longitude_min, cam.longitude_max = math.radians(-180), math.radians(180)
    else:
        plane("Floor", 20, (0, 0, 0), material=diffuse("Floor", (0.5, 0.5, 0.5)))
        for x, mat in ((-1.2, diffuse("D", (0.8, 0.3, 0.2))),
                       (0.0, principled("P", (0.3, 0.6, 0.8), roughness=0.4)),
                       (1.2, principled("M", (0.9, 0.8, 0.6), roughness=0.3, metallic=1.0))):
            bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(x, 0, 0.5), segments=32, ring_count=16)
            bpy.ops.object.shade_smooth()
            bpy.context.active_object.data.materials.append(mat)
        camera((0, -4.5, 1.6), (math.radians(75), 0, 0), lens=35)
    scene.render.resolution_x, scene.render.resolution_y = size
    return scene


def _path_coloured(name, rgb_of):
    """A diffuse Principled BSDF whose Base Color is Combine Color of three Light Path terms: ``rgb_of`` maps
    "R", "G", "B" to (output name, scale, offset), each channel offset + scale x that output."""
    m = principled(name, (0.5, 0.5, 0.5), roughness=1.0)
    tree = m.node_tree
    lp = tree.nodes.new("ShaderNodeLightPath")
    comb = tree.nodes.new("ShaderNodeCombineColor")
    for channel, (output, scale, offset) in rgb_of.items():
        ma = tree.nodes.new("ShaderNodeMath")
        ma.operation = "MULTIPLY_ADD"
        tree.links.new(lp.outputs[output], ma.inputs[0])
        ma.inputs[1].default_value = scale
        ma.inputs[2].default_value = offset
        tree.links.new(ma.outputs[0], comb.inputs[{"R": "Red", "G": "Green", "B": "Blue"}[channel]])
    tree.links.new(comb.outputs["Color"], tree.nodes["Principled BSDF"].inputs["Base Color"])
    return m


def light_path_types_scene(size=(96, 64)):
    """Surfaces coloured by the ray that reaches them (Light Path's ray types and depths), seen directly, in a
    mirror, a rough metal and a glass sphere and by diffuse bounces: the floor red by Is Glossy Ray, green by Ray
    Depth, blue by Is Transmission Ray; the back wall red by Diffuse Depth, green by Glossy Depth, blue by Is
    Singular Ray; a side wall red by Is Reflection Ray, green by Transmission Depth, blue by Is Diffuse Ray; under
    an area light."""
    scene = reset()
    floor = _path_coloured("PathFloor", {"R": ("Is Glossy Ray", 0.6, 0.2), "G": ("Ray Depth", -0.2, 0.7),
                                         "B": ("Is Transmission Ray", 0.6, 0.2)})
    wall = _path_coloured("PathWall", {"R": ("Diffuse Depth", 0.3, 0.2), "G": ("Glossy Depth", 0.3, 0.2),
                                       "B": ("Is Singular Ray", 0.6, 0.2)})
    side = _path_coloured("PathSide", {"R": ("Is Reflection Ray", 0.5, 0.3), "G": ("Transmission Depth", 0.2, 0.3),
                                       "B": ("Is Diffuse Ray", 0.5, 0.3)})
    plane("Floor", 8, (0, 0, 0), material=floor)
    plane("Wall", 8, (0, 2.5, 2), (math.pi / 2, 0, 0), material=wall)
    plane("Side", 8, (2.6, 0, 2), (0, math.pi / 2, 0), material=side)
    for x, mat in ((-1.3, principled("Mirror", (0.9, 0.9, 0.9), roughness=0.0, metallic=1.0)),
                   (0.0, glass_material("PathGlass", "GLASS")),
                   (1.3, principled("RoughMetal", (0.9, 0.8, 0.7), roughness=0.35, metallic=1.0))):
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.55, location=(x, 0.4, 0.55), segments=32, ring_count=16)
        bpy.ops.object.shade_smooth()
        bpy.context.active_object.data.materials.append(mat)
    light("AREA", (0, -1.0, 3.8), (math.radians(20), 0, 0), energy=600.0, size=1.5)
    camera((0, -4.5, 1.4), (math.radians(80), 0, 0), lens=30)
    black_world(scene)
    scene.render.resolution_x, scene.render.resolution_y = size
    return scene
