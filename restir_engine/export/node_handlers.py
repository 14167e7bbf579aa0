"""Shader nodes -> instructions of a node program (core/materials/nodes): one handler per Blender node type, called
by :class:`node_graph.GraphCompiler` with the compiler, the node and its group frame, returning {output socket
identifier: register}. Inputs are read through the compiler (``g.inp``), so constant inputs fold at export; options
that are approximated are named through ``g.warn``."""
from __future__ import annotations

import numpy as np

from . import object_properties
from .derived_attributes import POINTINESS, RANDOM_PER_ISLAND
from .node_graph import Reg
from .node_space_handlers import camera_data, ies_texture, light_path, normal, sky_texture, vector_transform

#: samples of a Color Ramp or curve table (Cycles' 257 entries over [0, 1])
TABLE_SIZE = 257


def _texcoord(g, node, f):
    if getattr(node, "object", None) is not None:
        g.warn(f"'{node.name}': coordinates of another object ('{node.object.name}') are approximated by this one's")
    out = {"Generated": g.attribute("generated", "vector"), "Normal": g.attribute("object_normal", "vector"),
           "UV": g.attribute("uv", "vector"), "Object": g.attribute("object", "vector"),
           "Reflection": g.attribute("reflection", "vector")}
    if g.camera is not None:
        pos = g.attribute("position", "vector")
        out["Camera"] = g.emit("camera_coords", {"camera": g.camera}, [pos], ("vector",))[0]
        out["Window"] = g.emit("window_coords", {"camera": g.camera}, [pos], ("vector",))[0]
    return out


def _tangent(g, node, f):
    if node.direction_type == "UV_MAP":
        g.attribute("tangent_uv", "vector")
        return {"Tangent": g.attribute("tangent_uv", "vector")}
    if node.axis != "Z":
        g.warn(f"'{node.name}': a radial tangent about {node.axis} is approximated by the one about Z")
    return {"Tangent": g.attribute("tangent", "vector")}


def _uvmap(g, node, f):
    """The render UV map, or the one the node names (read as the mesh's corner attribute of that name: (u, v, 0);
    0 where a mesh has no such map, as Cycles)."""
    if node.uv_map:
        return {"UV": g.attribute(f"attr:{node.uv_map}", "vector")}
    return {"UV": g.attribute("uv", "vector")}


def _geometry(g, node, f):
    return {"Position": g.attribute("position", "vector"), "Normal": g.attribute("normal", "vector"),
            "True Normal": g.attribute("true_normal", "vector"), "Incoming": g.attribute("incoming", "vector"),
            "Parametric": g.attribute("parametric", "vector"), "Backfacing": g.attribute("backfacing", "float"),
            "Tangent": g.attribute("tangent", "vector"),
            "Pointiness": g.attribute(f"attr_alpha:{POINTINESS}", "float"),
            "Random Per Island": g.attribute(f"attr_alpha:{RANDOM_PER_ISLAND}", "float")}


def _object_info(g, node, f):
    return {"Location": g.attribute("object_location", "vector"), "Color": g.attribute("object_color", "color"),
            "Alpha": g.attribute("object_alpha", "float"), "Random": g.attribute("object_random", "float"),
            "Object Index": g.attribute("object_index", "float"), "Material Index": g.constant(g.material_index, "float")}


def _color_attribute(g, node, f):
    name = node.layer_name
    return {"Color": g.attribute(f"attr:{name}", "color"), "Alpha": g.attribute(f"attr_alpha:{name}", "float")}


def _attribute(g, node, f):
    """Geometry: a colour attribute of the mesh; Object / Instancer: a property of the object (or its instancer)
    per instance; View Layer: a property of the view layer, scene or world (export/object_properties.py; where the
    compiler knows them: materials and the world)."""
    kind = node.attribute_type
    places = getattr(g, "view_layer", None)  # None: a compiler that does not know them
    if kind not in ("GEOMETRY", "OBJECT", "INSTANCER", "VIEW_LAYER") or (kind == "VIEW_LAYER" and places is None):
        return None
    name = node.attribute_name
    if not name:  # as Cycles: an Attribute node without a name finds nothing and gives 0 on every output
        zero = g.constant(0.0, "float")
        return {"Color": g.constant(0.0, "color"), "Vector": g.constant(0.0, "vector"), "Fac": zero, "Alpha": zero}
    if kind == "VIEW_LAYER":  # one value for the whole render: a constant
        if isinstance(places, object_properties.Places):
            places.read = True  # the viewport compiles the graphs again on an edit of these places
        r, gr, b, a = object_properties.first_value(places, name)
        return {"Color": g.constant((r, gr, b), "color"), "Vector": g.constant((r, gr, b), "vector"),
                "Fac": g.constant((r + gr + b) / 3.0, "float"), "Alpha": g.constant(a, "float")}
    if kind == "GEOMETRY":
        rgb, alpha = f"attr:{name}", f"attr_alpha:{name}"
    else:
        rgb, alpha = object_properties.read_names(kind, name)
    col = g.attribute(rgb, "color")
    return {"Color": col, "Vector": Reg(col.index, "vector", col.const), "Fac": g.convert(Reg(col.index, "vector"),
                                                                                          "float"),
            "Alpha": g.attribute(alpha, "float")}


def _fresnel(g, node, f):
    return {"Fac": g.emit("fresnel", {}, [g.inp(node, "IOR", "float", f),
                                          g.inp(node, "Normal", "vector", f, default="normal")], ("float",))[0]}


def _layer_weight(g, node, f):
    fr, fa = g.emit("layer_weight", {}, [g.inp(node, "Blend", "float", f),
                                         g.inp(node, "Normal", "vector", f, default="normal")], ("float", "float"))
    return {"Fresnel": fr, "Facing": fa}


def _wireframe(g, node, f):
    return {"Fac": g.emit("wireframe", {"pixel_size": bool(node.use_pixel_size)},
                          [g.inp(node, "Size", "float", f)], ("float",))[0]}


def _value(g, node, f):
    return {"Value": g.constant(node.outputs[0].default_value, "float")}


def _rgb(g, node, f):
    return {"Color": g.constant(tuple(node.outputs[0].default_value)[:3], "color")}


def _mapping(g, node, f):
    ins = [g.inp(node, "Vector", "vector", f), g.inp(node, "Location", "vector", f),
           g.inp(node, "Rotation", "vector", f), g.inp(node, "Scale", "vector", f)]
    return {"Vector": g.emit("mapping", {"type": node.vector_type}, ins, ("vector",))[0]}


def _vector_rotate(g, node, f):
    ins = [g.inp(node, k, kind, f) for k, kind in (("Vector", "vector"), ("Center", "vector"), ("Axis", "vector"),
                                                  ("Angle", "float"), ("Rotation", "vector"))]
    return {"Vector": g.emit("vector_rotate", {"type": node.rotation_type, "invert": bool(node.invert)}, ins,
                             ("vector",))[0]}


def _math(g, node, f):
    ins = [g.value(s, "float", frame=f) for s in list(node.inputs)[:3]]
    return {"Value": g.emit("math", {"op": node.operation, "clamp": bool(node.use_clamp)}, ins, ("float",))[0]}


def _vector_math(g, node, f):
    socks = list(node.inputs)
    ins = [g.value(s, "vector", frame=f) for s in socks[:3]] + [g.value(socks[3], "float", frame=f)]
    vec, val = g.emit("vector_math", {"op": node.operation}, ins, ("vector", "float"))
    return {"Vector": vec, "Value": val}


def _mix(g, node, f):
    dt = node.data_type
    if dt == "FLOAT":
        ins = [g.inp(node, "Factor_Float", "float", f), g.inp(node, "A_Float", "float", f),
               g.inp(node, "B_Float", "float", f)]
        return {"Result_Float": g.emit("mix_float", {"clamp_factor": bool(node.clamp_factor)}, ins, ("float",))[0]}
    if dt == "VECTOR":
        uniform = node.factor_mode == "UNIFORM"
        fac = g.inp(node, "Factor_Float", "float", f) if uniform else g.inp(node, "Factor_Vector", "vector", f)
        ins = [fac, g.inp(node, "A_Vector", "vector", f), g.inp(node, "B_Vector", "vector", f)]
        return {"Result_Vector": g.emit("mix_vector", {"clamp_factor": bool(node.clamp_factor)}, ins, ("vector",))[0]}
    if dt == "RGBA":
        ins = [g.inp(node, "Factor_Float", "float", f), g.inp(node, "A_Color", "color", f),
               g.inp(node, "B_Color", "color", f)]
        params = {"blend": node.blend_type, "clamp_factor": bool(node.clamp_factor),
                  "clamp_result": bool(node.clamp_result)}
        return {"Result_Color": g.emit("mix_color", params, ins, ("color",))[0]}
    return None


def _mix_rgb(g, node, f):
    ins = [g.inp(node, "Fac", "float", f), g.inp(node, "Color1", "color", f), g.inp(node, "Color2", "color", f)]
    params = {"blend": node.blend_type, "clamp_factor": True, "clamp_result": bool(node.use_clamp)}
    return {"Color": g.emit("mix_color", params, ins, ("color",))[0]}


def _map_range(g, node, f):
    params = {"interpolation": node.interpolation_type, "clamp": bool(node.clamp)}
    if node.data_type == "FLOAT_VECTOR":
        ins = [g.inp(node, k, "vector", f) for k in ("Vector", "From_Min_FLOAT3", "From_Max_FLOAT3", "To_Min_FLOAT3",
                                                     "To_Max_FLOAT3", "Steps_FLOAT3")]
        return {"Vector": g.emit("map_range", params, ins, ("vector",))[0]}
    ins = [g.inp(node, k, "float", f) for k in ("Value", "From Min", "From Max", "To Min", "To Max", "Steps")]
    return {"Result": g.emit("map_range", params, ins, ("float",))[0]}


def _clamp(g, node, f):
    ins = [g.inp(node, k, "float", f) for k in ("Value", "Min", "Max")]
    return {"Result": g.emit("clamp", {"type": node.clamp_type}, ins, ("float",))[0]}


def _invert(g, node, f):
    return {"Color": g.emit("invert", {}, [g.inp(node, "Fac", "float", f), g.inp(node, "Color", "color", f)],
                            ("color",))[0]}


def _rgb_to_bw(g, node, f):
    return {"Val": g.emit("rgb_to_bw", {}, [g.inp(node, "Color", "color", f)], ("float",))[0]}


def _gamma(g, node, f):
    return {"Color": g.emit("gamma", {}, [g.inp(node, "Color", "color", f), g.inp(node, "Gamma", "float", f)],
                            ("color",))[0]}


def _bright_contrast(g, node, f):
    ins = [g.inp(node, "Color", "color", f), g.inp(node, "Bright", "float", f), g.inp(node, "Contrast", "float", f)]
    return {"Color": g.emit("bright_contrast", {}, ins, ("color",))[0]}


def _hue_sat(g, node, f):
    ins = [g.inp(node, k, kind, f) for k, kind in (("Hue", "float"), ("Saturation", "float"), ("Value", "float"),
                                                  ("Fac", "float"), ("Color", "color"))]
    return {"Color": g.emit("hue_saturation", {}, ins, ("color",))[0]}


def _separate(names, mode_of, in_name, in_kind):
    def handler(g, node, f):
        regs = g.emit("separate", {"mode": mode_of(node)}, [g.inp(node, in_name, in_kind, f)],
                      ("float", "float", "float"))
        return dict(zip(names, regs))
    return handler


def _combine(names, mode_of, out_name, out_kind):
    def handler(g, node, f):
        ins = [g.inp(node, k, "float", f) for k in names]
        return {out_name: g.emit("combine", {"mode": mode_of(node)}, ins, (out_kind,))[0]}
    return handler


def _color_mode(node):
    return node.mode


def _color_ramp(g, node, f):
    ramp = node.color_ramp
    table = np.array([tuple(ramp.evaluate(i / (TABLE_SIZE - 1))) for i in range(TABLE_SIZE)], np.float32)
    color, alpha = g.emit("color_ramp", {"table": table, "interpolate": ramp.interpolation != "CONSTANT"},
                          [g.inp(node, "Fac", "float", f)], ("color", "float"))
    return {"Color": color, "Alpha": alpha}


def _curve_tables(mapping, curves, composed=None):
    """Tables (TABLE_SIZE,) of curves over the mapping's x range (each after the ``composed`` curve, if any),
    the range, and whether they extrapolate."""
    mapping.initialize()
    xs = [p.location[0] for c in mapping.curves for p in c.points]
    lo, hi = (min(xs), max(xs)) if xs else (0.0, 1.0)
    if hi - lo < 1e-6:
        lo, hi = 0.0, 1.0
    pos = lo + (hi - lo) * np.arange(TABLE_SIZE) / (TABLE_SIZE - 1)
    tables = []
    for c in curves:
        vals = []
        for x in pos:
            y = mapping.evaluate(composed, float(x)) if composed is not None else float(x)
            vals.append(mapping.evaluate(c, y))
        tables.append(np.array(vals, np.float32))
    return tables, (float(lo), float(hi)), mapping.extend == "EXTRAPOLATED"


def _rgb_curves(g, node, f):
    m = node.mapping
    tables, rng, extra = _curve_tables(m, list(m.curves)[:3], m.curves[3])
    ins = [g.inp(node, "Fac", "float", f), g.inp(node, "Color", "color", f)]
    return {"Color": g.emit("rgb_curves", {"tables": tables, "range": rng, "extrapolate": extra}, ins,
                            ("color",))[0]}


def _vector_curves(g, node, f):
    """Vector Curves: X, Y and Z each through their curve over the mapping's range (Cycles' curve lookup, as RGB
    Curves without the combined curve), mixed with the input by Fac."""
    m = node.mapping
    tables, rng, extra = _curve_tables(m, list(m.curves)[:3])
    ins = [g.inp(node, "Fac", "float", f), g.inp(node, "Vector", "vector", f)]
    return {"Vector": g.emit("rgb_curves", {"tables": tables, "range": rng, "extrapolate": extra}, ins,
                             ("vector",))[0]}


def _float_curve(g, node, f):
    m = node.mapping
    tables, rng, extra = _curve_tables(m, [m.curves[0]])
    ins = [g.inp(node, "Factor", "float", f), g.inp(node, "Value", "float", f)]
    return {"Value": g.emit("float_curve", {"table": tables[0], "range": rng, "extrapolate": extra}, ins,
                            ("float",))[0]}


def _image(g, node, f):
    img = node.image
    if img is None:  # Cycles: an Image Texture without an image is magenta
        return {"Color": g.constant((1.0, 0.0, 1.0), "color"), "Alpha": g.constant(1.0, "float")}
    if node.projection != "FLAT":
        g.warn(f"'{node.name}': {node.projection} projection is approximated by flat projection")
    params = {"tex": g.texture(img, False), "interpolation": node.interpolation, "extension": node.extension}
    if node.outputs["Alpha"].is_linked:
        params["alpha_tex"] = g.texture(img, True)
    color, alpha = g.emit("image", params, [g.inp(node, "Vector", "vector", f, default="uv")], ("color", "float"))
    return {"Color": color, "Alpha": alpha}


def _environment(g, node, f):
    img = node.image
    if img is None:
        return {"Color": g.constant((1.0, 0.0, 1.0), "color")}
    if node.projection != "EQUIRECTANGULAR":
        g.warn(f"'{node.name}': the {node.projection} projection is approximated by equirectangular")
    params = {"tex": g.texture(img, False), "interpolation": node.interpolation}
    return {"Color": g.emit("environment", params, [g.inp(node, "Vector", "vector", f, default="generated")],
                            ("color",))[0]}


def _dims(node) -> int:
    return int(str(getattr(node, "noise_dimensions", "3D"))[0])


def _noise(g, node, f):
    ins = [g.inp(node, "Vector", "vector", f, default="generated")] + [
        g.inp(node, k, "float", f) for k in ("W", "Scale", "Detail", "Roughness", "Lacunarity", "Offset", "Gain",
                                            "Distortion")]
    params = {"dims": _dims(node), "type": getattr(node, "noise_type", "FBM"),
              "normalize": bool(getattr(node, "normalize", True)), "color": node.outputs["Color"].is_linked}
    fac, color = g.emit("noise", params, ins, ("float", "color"))
    return {"Fac": fac, "Color": color}


def _white_noise(g, node, f):
    ins = [g.inp(node, "Vector", "vector", f, default="generated"), g.inp(node, "W", "float", f)]
    value, color = g.emit("white_noise", {"dims": _dims(node)}, ins, ("float", "color"))
    return {"Value": value, "Color": color}


def _gabor(g, node, f):
    """Gabor Texture (core/materials/nodes/gabor.py): Value, Phase, Intensity."""
    ins = [g.inp(node, "Vector", "vector", f, default="generated"), g.inp(node, "Scale", "float", f),
           g.inp(node, "Frequency", "float", f), g.inp(node, "Anisotropy", "float", f),
           g.inp(node, "Orientation 2D", "float", f), g.inp(node, "Orientation 3D", "vector", f)]
    value, phase, intensity = g.emit("gabor_texture", {"dims": 3 if node.gabor_type == "3D" else 2}, ins,
                                     ("float", "float", "float"))
    return {"Value": value, "Phase": phase, "Intensity": intensity}


def _checker(g, node, f):
    ins = [g.inp(node, "Vector", "vector", f, default="generated"), g.inp(node, "Color1", "color", f),
           g.inp(node, "Color2", "color", f), g.inp(node, "Scale", "float", f)]
    color, fac = g.emit("checker", {}, ins, ("color", "float"))
    return {"Color": color, "Fac": fac}


def _gradient(g, node, f):
    color, fac = g.emit("gradient", {"type": node.gradient_type},
                        [g.inp(node, "Vector", "vector", f, default="generated")], ("color", "float"))
    return {"Color": color, "Fac": fac}


def _voronoi(g, node, f):
    ins = [g.inp(node, "Vector", "vector", f, default="generated")] + [
        g.inp(node, k, "float", f) for k in ("W", "Scale", "Detail", "Roughness", "Lacunarity", "Smoothness",
                                            "Exponent", "Randomness")]
    params = {"dims": int(str(node.voronoi_dimensions)[0]), "feature": node.feature, "metric": node.distance,
              "normalize": bool(getattr(node, "normalize", False))}
    dist, color, pos, w, radius = g.emit("voronoi", params, ins, ("float", "color", "vector", "float", "float"))
    return {"Distance": dist, "Color": color, "Position": pos, "W": w, "Radius": radius}


def _wave(g, node, f):
    ins = [g.inp(node, "Vector", "vector", f, default="generated")] + [
        g.inp(node, k, "float", f) for k in ("Scale", "Distortion", "Detail", "Detail Scale", "Detail Roughness",
                                            "Phase Offset")]
    bands = node.wave_type == "BANDS"
    params = {"type": node.wave_type, "direction": node.bands_direction if bands else node.rings_direction,
              "profile": node.wave_profile}
    color, fac = g.emit("wave", params, ins, ("color", "float"))
    return {"Color": color, "Fac": fac}


def _magic(g, node, f):
    import bpy  # the wrap of the coordinates changed in Blender 5.2

    ins = [g.inp(node, "Vector", "vector", f, default="generated"), g.inp(node, "Scale", "float", f),
           g.inp(node, "Distortion", "float", f)]
    params = {"depth": int(node.turbulence_depth), "wrap_scaled": tuple(bpy.app.version[:2]) >= (5, 2)}
    color, fac = g.emit("magic", params, ins, ("color", "float"))
    return {"Color": color, "Fac": fac}


def _brick(g, node, f):
    ins = [g.inp(node, "Vector", "vector", f, default="generated"), g.inp(node, "Color1", "color", f),
           g.inp(node, "Color2", "color", f), g.inp(node, "Mortar", "color", f)] + [
        g.inp(node, k, "float", f) for k in ("Scale", "Mortar Size", "Mortar Smooth", "Bias", "Brick Width",
                                            "Row Height")]
    params = {"offset": float(node.offset), "offset_frequency": int(node.offset_frequency),
              "squash": float(node.squash), "squash_frequency": int(node.squash_frequency)}
    color, fac = g.emit("brick", params, ins, ("color", "float"))
    return {"Color": color, "Fac": fac}


def _normal_map(g, node, f):
    space = node.space
    color = g.inp(node, "Color", "color", f)
    strength = g.inp(node, "Strength", "float", f)
    params = {"space": space}
    if space == "TANGENT":
        g.attribute("tangent_uv", "vector")  # (read by the operation; named so that the export makes tangents)
        if node.uv_map:  # that map's tangents, where a mesh has it (export/meshes.py reads them as an attribute)
            params["uv_map"] = node.uv_map
            g.attribute(f"attr:tangent@{node.uv_map}", "vector")
            g.attribute(f"attr_alpha:tangent@{node.uv_map}", "float")
    for name in ("normal", "backfacing"):
        g.attribute(name, "vector" if name == "normal" else "float")
    return {"Normal": g.emit("normal_map", params, [strength, color], ("vector",))[0]}


def _bump(g, node, f):
    normal_in = g.inp(node, "Normal", "vector", f, default="normal")
    height = node.inputs["Height"]
    sub = type(g)(g._textures, g._warn)
    h = sub.value(height, "float", frame=f)
    if h.const is not None:  # a constant height bumps nothing
        return {"Normal": normal_in}
    g.reads |= sub.reads | {"true_normal", "footprint"}
    program = sub.program({"height": h})
    ins = [g.inp(node, "Strength", "float", f), g.inp(node, "Distance", "float", f), normal_in]
    params = {"height": program, "invert": bool(getattr(node, "invert", False))}
    return {"Normal": g.emit("bump", params, ins, ("vector",))[0]}


def _blackbody(g, node, f):
    return {"Color": g.emit("blackbody", {}, [g.inp(node, "Temperature", "float", f)], ("color",))[0]}


def _wavelength(g, node, f):
    return {"Color": g.emit("wavelength", {}, [g.inp(node, "Wavelength", "float", f)], ("color",))[0]}


def _light_falloff(g, node, f):
    """Every output is the Strength; the distance factor of the output used is recorded where the graph is a lamp's
    (``g.falloffs``, a list: the lamp applies it per receiver) and approximated by the physical one elsewhere."""
    strength = g.inp(node, "Strength", "float", f)
    smooth = g.inp(node, "Smooth", "float", f)
    used = [k for k, name in enumerate(("Quadratic", "Linear", "Constant")) if node.outputs[name].is_linked]
    lamp = getattr(g, "falloffs", None)
    if lamp is not None and smooth.const is not None:
        lamp.append((node.name, used, float(smooth.const)))
        return {"Quadratic": strength, "Linear": strength, "Constant": strength}
    if set(used) - {0}:
        g.warn(f"'{node.name}' (Light Falloff): Linear and Constant falloff are approximated by the physical "
               "(quadratic) falloff outside lamps")
    if smooth.const is None or float(smooth.const) != 0.0:
        g.warn(f"'{node.name}' (Light Falloff): Smooth is not supported here (treated as 0)")
    return {"Quadratic": strength, "Linear": strength, "Constant": strength}


def _ambient_occlusion(g, node, f):
    g.warn(f"'{node.name}' (Ambient Occlusion) is taken as unoccluded (AO 1, Color passed through)")
    return {"Color": g.inp(node, "Color", "color", f), "AO": g.constant(1.0, "float")}


def _bevel(g, node, f):
    g.warn(f"'{node.name}' (Bevel) is not rounded: its Normal is the surface's")
    return {"Normal": g.inp(node, "Normal", "vector", f, default="normal")}


HANDLERS = {
    "TEX_COORD": _texcoord, "TANGENT": _tangent, "LIGHT_PATH": light_path, "UVMAP": _uvmap,
    "NEW_GEOMETRY": _geometry, "OBJECT_INFO": _object_info,
    "VERTEX_COLOR": _color_attribute, "ATTRIBUTE": _attribute, "FRESNEL": _fresnel, "LAYER_WEIGHT": _layer_weight,
    "VALUE": _value, "RGB": _rgb, "MAPPING": _mapping, "VECTOR_ROTATE": _vector_rotate, "MATH": _math,
    "VECT_MATH": _vector_math, "MIX": _mix, "MIX_RGB": _mix_rgb, "MAP_RANGE": _map_range, "CLAMP": _clamp,
    "INVERT": _invert, "RGBTOBW": _rgb_to_bw, "GAMMA": _gamma, "BRIGHTCONTRAST": _bright_contrast,
    "HUE_SAT": _hue_sat,
    "SEPXYZ": _separate(("X", "Y", "Z"), lambda n: "RGB", "Vector", "vector"),
    "COMBXYZ": _combine(("X", "Y", "Z"), lambda n: "RGB", "Vector", "vector"),
    "SEPARATE_COLOR": _separate(("Red", "Green", "Blue"), _color_mode, "Color", "color"),
    "COMBINE_COLOR": _combine(("Red", "Green", "Blue"), _color_mode, "Color", "color"),
    "SEPRGB": _separate(("R", "G", "B"), lambda n: "RGB", "Image", "color"),
    "COMBRGB": _combine(("R", "G", "B"), lambda n: "RGB", "Image", "color"),
    "SEPHSV": _separate(("H", "S", "V"), lambda n: "HSV", "Color", "color"),
    "COMBHSV": _combine(("H", "S", "V"), lambda n: "HSV", "Color", "color"),
    "VALTORGB": _color_ramp, "CURVE_RGB": _rgb_curves, "CURVE_FLOAT": _float_curve, "CURVE_VEC": _vector_curves,
    "CAMERA": camera_data, "NORMAL": normal, "VECT_TRANSFORM": vector_transform, "TEX_IMAGE": _image,
    "TEX_ENVIRONMENT": _environment,
    "TEX_NOISE": _noise, "TEX_WHITE_NOISE": _white_noise, "TEX_CHECKER": _checker, "TEX_GRADIENT": _gradient,
    "NORMAL_MAP": _normal_map, "BUMP": _bump, "TEX_VORONOI": _voronoi, "TEX_WAVE": _wave, "TEX_MAGIC": _magic,
    "TEX_BRICK": _brick, "BLACKBODY": _blackbody, "WAVELENGTH": _wavelength, "LIGHT_FALLOFF": _light_falloff,
    "AMBIENT_OCCLUSION": _ambient_occlusion, "BEVEL": _bevel, "WIREFRAME": _wireframe, "TEX_IES": ies_texture,
    "TEX_GABOR": _gabor, "TEX_SKY": sky_texture,
}
