"""Shader-node handlers for the view, ray, space, light-profile and sky nodes: Camera Data, Light Path, Vector
Transform, Normal, IES Texture and Sky Texture (each returns its outputs as registers of the graph compiler, export/node_graph.py; the
vector operations are core/materials/nodes/)."""
from __future__ import annotations

import numpy as np

from ..core.lights import ies, sky


def camera_data(g, node, f):
    """Camera Data: the hit in the camera's frame (Texture Coordinate > Camera: x right, y up, +z forward) as a unit
    View Vector, its View Z Depth (z) and View Distance (length), as Cycles computes them."""
    if g.camera is None:
        g.warn(f"'{node.name}' (Camera Data) has no camera here; its outputs are 0")
        zero = g.constant(0.0, "float")
        return {"View Vector": g.constant(0.0, "vector"), "View Z Depth": zero, "View Distance": zero}
    cam = g.emit("camera_coords", {"camera": g.camera}, [g.attribute("position", "vector")], ("vector",))[0]
    zero_v, zero_f = g.constant(0.0, "vector"), g.constant(0.0, "float")
    unit = g.emit("vector_math", {"op": "NORMALIZE"}, [cam, zero_v, zero_v, zero_f], ("vector", "float"))[0]
    length = g.emit("vector_math", {"op": "LENGTH"}, [cam, zero_v, zero_v, zero_f], ("vector", "float"))[1]
    depth = g.emit("separate", {"mode": "RGB"}, [cam], ("float", "float", "float"))[2]
    return {"View Vector": unit, "View Z Depth": depth, "View Distance": length}


def vector_transform(g, node, f):
    """Vector Transform: a point, direction or normal between world, object and camera space (core ops_spaces)."""
    spaces = {node.convert_from, node.convert_to}
    if "CAMERA" in spaces and g.camera is None:
        g.warn(f"'{node.name}' (Vector Transform) has no camera here; camera space is taken as world space")
    params = {"type": node.vector_type, "from": node.convert_from, "to": node.convert_to, "camera": g.camera}
    return {"Vector": g.emit("vector_transform", params, [g.inp(node, "Vector", "vector", f)], ("vector",))[0]}


def normal(g, node, f):
    """Normal node: its own unit direction, and Dot, that direction against the unit input Normal (as Cycles)."""
    d = np.array(node.outputs["Normal"].default_value[:3], np.float64)
    d = d / max(np.linalg.norm(d), 1e-30)
    direction = g.constant(tuple(float(x) for x in d), "vector")
    inp = g.inp(node, "Normal", "vector", f)
    zero_v, zero_f = g.constant(0.0, "vector"), g.constant(0.0, "float")
    unit = g.emit("vector_math", {"op": "NORMALIZE"}, [inp, zero_v, zero_v, zero_f], ("vector", "float"))[0]
    dot = g.emit("vector_math", {"op": "DOT_PRODUCT"}, [direction, unit, zero_v, zero_f], ("vector", "float"))[1]
    return {"Normal": direction, "Dot": dot}


def _ies_text(node) -> tuple:
    """(the IES Texture's LM-63 text or None, where it was looked for)."""
    if node.mode == "INTERNAL":
        text = node.ies
        return (None if text is None else text.as_string()), "its internal text"
    import bpy
    path = bpy.path.abspath(node.filepath)
    try:
        with open(path, encoding="latin-1") as fh:
            return fh.read(), f"'{path}'"
    except OSError:
        return None, f"'{path}'"


def ies_texture(g, node, f):
    """IES Texture: Strength x the light profile of its internal text or external file (core/lights/ies.py) towards
    its Vector (unlinked: the incoming direction in object space, the direction from a lamp to the lit point); a
    profile that cannot be read is named and reads 100 everywhere, as Cycles gives it."""
    text, where = _ies_text(node)
    table = None
    if not text:
        g.warn(f"'{node.name}' (IES Texture): no profile in {where}; it reads {ies.UNREADABLE:g} everywhere")
    else:
        try:
            table = ies.parse(text)
        except ies.IesError as err:
            g.warn(f"'{node.name}' (IES Texture): {where} is not a readable IES profile ({err}); it reads "
                   f"{ies.UNREADABLE:g} everywhere")
    if node.inputs["Vector"].is_linked:
        vec = g.inp(node, "Vector", "vector", f)
    else:
        vec = g.emit("vector_transform", {"type": "NORMAL", "from": "WORLD", "to": "OBJECT", "camera": g.camera},
                     [g.attribute("incoming", "vector")], ("vector",))[0]
    strength = g.inp(node, "Strength", "float", f)
    return {"Fac": g.emit("ies_texture", {"table": table}, [vec, strength], ("float",))[0]}


def sky_texture(g, node, f):
    """Sky Texture: the sky's radiance towards its Vector (unlinked: Generated, in a world the direction), each of
    its four models as Cycles computes it (core/lights/sky.py)."""
    kind = node.sky_type
    sun = tuple(float(x) for x in node.sun_direction)
    if kind == "PREETHAM":
        model = sky.preetham_sky(sun, float(node.turbidity))
    elif kind == "HOSEK_WILKIE":
        model = sky.hosek_sky(sun, float(node.turbidity), float(node.ground_albedo))
    else:  # Blender 4.x calls the Single Scattering model Nishita, and its Aerosol density Dust
        aerosol = getattr(node, "aerosol_density", getattr(node, "dust_density", 1.0))
        if kind == "NISHITA":  # measured against Blender 4.5's Cycles: within 0.6 % above the horizon
            g.warn(f"'{node.name}' (Sky Texture): Nishita is rendered as Blender 5's Single Scattering; below the "
                   "horizon Blender 4.x fills the sky differently")
        model = sky.atmosphere_sky("SINGLE_SCATTERING" if kind == "NISHITA" else kind, bool(node.sun_disc),
                                   float(node.sun_size), float(node.sun_intensity), float(node.sun_elevation),
                                   float(node.sun_rotation), float(node.altitude), float(node.air_density),
                                   float(aerosol), float(getattr(node, "ozone_density", 1.0)))
    plain = not node.inputs["Vector"].is_linked
    vec = g.inp(node, "Vector", "vector", f, default="generated")
    return {"Color": g.emit("sky_texture", {"sky": model, "plain": plain}, [vec], ("color",))[0]}


def light_path(g, node, f):
    """Light Path, per hit as the path that reached it (core/materials/nodes/attributes.PATH_ATTRIBUTES: the ray's
    type and the bounces before it, carried along the path tracer's paths). Approximated and named: Transparent
    Depth (0), Portal Depth and Is Volume Scatter Ray (0); in a world every output but Is Camera Ray, Is Shadow Ray
    and Ray Length (as a camera ray's); in a lamp the depths (as a camera hit's light)."""
    attr = {"Is Camera Ray": "is_camera_ray", "Is Shadow Ray": "is_shadow_ray", "Ray Length": "ray_length",
            "Is Diffuse Ray": "is_diffuse_ray", "Is Glossy Ray": "is_glossy_ray", "Is Singular Ray": "is_singular_ray",
            "Is Reflection Ray": "is_reflection_ray", "Is Transmission Ray": "is_transmission_ray",
            "Ray Depth": "ray_depth", "Diffuse Depth": "diffuse_depth", "Glossy Depth": "glossy_depth",
            "Transmission Depth": "transmission_depth", "Transparent Depth": "transparent_depth"}
    exact = set(attr) - {"Transparent Depth"}
    if getattr(g, "world", False):
        exact = {"Is Camera Ray", "Is Shadow Ray", "Ray Length"}
    elif getattr(g, "falloffs", None) is not None:
        exact -= {"Ray Depth", "Diffuse Depth", "Glossy Depth", "Transmission Depth"}
    linked = [o.name for o in node.outputs if o.is_linked and o.name not in exact]
    if linked:
        g.warn(f"'{node.name}' (Light Path): {', '.join(linked)} approximated here")
    zero = g.constant(0.0, "float")
    out = {name: g.attribute(a, "float") for name, a in attr.items()}
    out.update({"Is Volume Scatter Ray": zero, "Portal Depth": zero})
    return out
