"""A material's shader node graph -> a vectorized node program (core/materials/nodes).

:class:`GraphCompiler` follows links back from the sockets a closure reads, through node groups (flattened),
reroutes and muted nodes, and emits one instruction per node output it needs; sockets that are not linked are
constants, and a node whose inputs are all constant is evaluated here (constant folding), so a socket whose graph
does not vary over the surface costs nothing at render time. Socket types convert as Blender converts them
(colour -> float: luminance; vector -> float: the mean; float -> vector / colour: splat). Nodes the evaluator does
not know give their output socket's default value, named in one warning."""
from __future__ import annotations

import numpy as np

from ..core.materials.nodes.program import READS_HITS, Program, evaluate_constant

#: samples of a Color Ramp or curve table (Cycles' 257 entries over [0, 1])
TABLE_SIZE = 257
#: node group levels followed (recursive groups are cut off with a warning)
MAX_GROUP_DEPTH = 64

_KIND = {"VALUE": "float", "INT": "float", "BOOLEAN": "float", "VECTOR": "vector", "RGBA": "color"}


class Reg:
    """A value in a program: its register, kind ("float", "vector", "color") and constant value (or None)."""

    __slots__ = ("index", "kind", "const")

    def __init__(self, index: int, kind: str, const=None):
        self.index, self.kind, self.const = index, kind, const

    def constant_value(self):
        """The constant as a Python float or RGB tuple."""
        c = np.asarray(self.const, np.float32)
        return float(c.reshape(-1)[0]) if self.kind == "float" else tuple(float(x) for x in c.reshape(3))


class Frame:
    """A node group being compiled: the group node (None at the top) and the frame it sits in."""

    def __init__(self, group_node=None, parent=None):
        self.group_node, self.parent = group_node, parent
        self.depth = 0 if parent is None else parent.depth + 1


class GraphCompiler:
    """Compiles sockets of one material's node tree. ``textures(image, alpha)`` returns the texture index of an
    image's colour (or alpha) for the material table; ``warn(reason)`` reports an approximation."""

    def __init__(self, textures, warn):
        self._textures, self._warn = textures, warn
        self.ops: list = []
        self.consts: dict = {}
        self.reads: set = set()
        self._next = 0
        self._vectors: set = set()
        self._memo: dict = {}
        self._frames: dict = {}
        self.top = Frame()
        self.camera = None        # the core Camera of Texture Coordinate's Camera / Window outputs (None: unknown)
        self.material_index = 0.0  # the material's Pass Index (Object Info > Material Index)

    # -- registers --------------------------------------------------------------------------------------------
    def _new(self, kind: str, const=None) -> Reg:
        r = Reg(self._next, kind, const)
        self._next += 1
        if kind != "float":
            self._vectors.add(r.index)
        if const is not None:
            self.consts[r.index] = const
        return r

    def constant(self, value, kind: str) -> Reg:
        if kind == "float":
            return self._new(kind, np.float32(np.asarray(value, np.float32).reshape(-1)[0]))
        v = np.asarray(value, np.float32).reshape(-1)[:3]
        if v.size == 1:
            v = np.repeat(v, 3)
        return self._new(kind, v.reshape(3, 1).copy())

    def emit(self, op: str, params: dict, ins: list, kinds: tuple) -> list:
        """Output registers of one operation; folded into constants when every input is one."""
        if op not in READS_HITS and all(r.const is not None for r in ins):
            got = evaluate_constant(op, params, *[r.const for r in ins])
            got = got if len(kinds) > 1 else (got,)
            return [self._new(k, np.asarray(g, np.float32) if k == "float" else
                              np.asarray(g, np.float32).reshape(3, 1)) for g, k in zip(got, kinds)]
        outs = [self._new(k) for k in kinds]
        self.ops.append((op, tuple(o.index for o in outs), tuple(r.index for r in ins), params))
        return outs

    def attribute(self, name: str, kind: str) -> Reg:
        key = ("attr", name)
        if key not in self._memo:
            self.reads.add(name)
            self._memo[key] = self.emit("attribute", {"name": name}, [], (kind,))[0]
        return self._memo[key]

    def convert(self, reg: Reg, kind: str) -> Reg:
        if reg.kind == kind or {reg.kind, kind} == {"vector", "color"}:
            return reg if reg.kind == kind else Reg(reg.index, kind, reg.const)
        if kind == "float":
            return self.emit("color_to_float" if reg.kind == "color" else "vector_to_float", {}, [reg], ("float",))[0]
        return self.emit("float_to_vector", {}, [reg], (kind,))[0]

    def program(self, outputs: dict, constants: bool = False, keep=()) -> Program | None:
        """A Program computing ``outputs`` (field -> Reg) that vary (all of them with ``constants``, and those named
        in ``keep`` whether they vary or not); None when none is left."""
        varying = {f: r for f, r in outputs.items() if r is not None and (constants or r.const is None or f in keep)}
        if not varying:
            return None
        return Program(ops=list(self.ops), consts=dict(self.consts),
                       outputs={f: (r.index, "float" if r.kind == "float" else "rgb") for f, r in varying.items()},
                       reads=tuple(sorted(self.reads)), vectors=tuple(sorted(self._vectors)))

    # -- sockets ----------------------------------------------------------------------------------------------
    def value(self, socket, kind: str | None = None, default: str | None = None, frame: Frame | None = None) -> Reg:
        """The value arriving at input ``socket`` as ``kind`` (its own kind when None); ``default`` names the hit
        attribute an unlinked socket reads instead of its value (a texture's Vector: "generated" or "uv")."""
        frame = frame or self.top
        kind = kind or _KIND.get(socket.type, "float")
        link = next((lk for lk in socket.links if not lk.is_muted and lk.is_valid), None) if socket.is_linked else None
        if link is None:
            if default is not None:
                return self.convert(self.attribute(default, "vector" if default != "backfacing" else "float"), kind)
            if not hasattr(socket, "default_value"):
                return self.constant(0.0, kind)
            return self.constant(_socket_default(socket), kind)
        got = self.output(link.from_node, link.from_socket, frame)
        return self.convert(got, kind)

    def output(self, node, socket, frame: Frame) -> Reg:
        """The value of output ``socket`` of ``node``."""
        key = (id(frame), node.name, socket.identifier)
        if key in self._memo:
            return self._memo[key]
        if node.type == "REROUTE":
            got = self.value(node.inputs[0], None, frame=frame) if node.inputs else self.constant(0.0, "float")
            got = self.convert(got, _KIND.get(socket.type, got.kind)) if socket.type in _KIND else got
        elif node.mute:
            got = self._muted(node, socket, frame)
        elif node.type == "GROUP":
            got = self._group(node, socket, frame)
        elif node.type == "GROUP_INPUT":
            got = self._group_input(socket, frame)
        else:
            handler = _HANDLERS.get(node.type)
            outs = handler(self, node, frame) if handler is not None else None
            if outs is None or socket.identifier not in outs:
                self._warn(f"'{node.name}' ({node.type}) is not supported here; its output '{socket.name}' is "
                           "approximated by a constant")
                got = self.constant(_socket_default(socket) if hasattr(socket, "default_value") else 0.0,
                                    _KIND.get(socket.type, "float"))
            else:
                for ident, reg in outs.items():
                    self._memo[(id(frame), node.name, ident)] = reg
                got = outs[socket.identifier]
        self._memo[key] = got
        return got

    def _muted(self, node, socket, frame):
        for lk in node.internal_links:
            if lk.to_socket.identifier == socket.identifier:
                return self.value(lk.from_socket, _KIND.get(socket.type, "float"), frame=frame)
        return self.constant(0.0, _KIND.get(socket.type, "float"))

    def _group(self, node, socket, frame):
        tree = node.node_tree
        kind = _KIND.get(socket.type, "float")
        if tree is None:
            return self.constant(0.0, kind)
        if frame.depth >= MAX_GROUP_DEPTH:
            self._warn(f"node groups nested deeper than {MAX_GROUP_DEPTH} levels are cut off")
            return self.constant(0.0, kind)
        key = (id(frame), node.name)
        inner = self._frames.get(key)
        if inner is None:
            inner = self._frames[key] = Frame(node, frame)
        outs = [n for n in tree.nodes if n.type == "GROUP_OUTPUT"]
        out = next((n for n in outs if getattr(n, "is_active_output", False)), outs[0] if outs else None)
        if out is None:
            return self.constant(0.0, kind)
        target = next((s for s in out.inputs if s.identifier == socket.identifier), None)
        if target is None:
            return self.constant(0.0, kind)
        return self.value(target, kind, frame=inner)

    def _group_input(self, socket, frame):
        kind = _KIND.get(socket.type, "float")
        group = frame.group_node
        if group is None:
            return self.constant(0.0, kind)
        target = next((s for s in group.inputs if s.identifier == socket.identifier), None)
        if target is None:
            return self.constant(0.0, kind)
        return self.value(target, kind, frame=frame.parent)

    # -- helpers for handlers -----------------------------------------------------------------------------------
    def inp(self, node, ident: str, kind: str | None = None, frame=None, default: str | None = None) -> Reg:
        sock = next((s for s in node.inputs if s.identifier == ident), None)
        if sock is None:
            sock = node.inputs.get(ident)
        if sock is None:
            return self.constant(0.0, kind or "float")
        return self.value(sock, kind, default=default, frame=frame)

    def texture(self, image, alpha: bool) -> int:
        return self._textures(image, alpha)

    def warn(self, reason: str) -> None:
        self._warn(reason)


def _socket_default(socket):
    v = socket.default_value
    try:
        return tuple(v)[:3]
    except TypeError:
        return float(v)


# -- node handlers: node -> {output identifier: Reg} --------------------------------------------------------------
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


def _light_path(g, node, f):
    linked = [o.name for o in node.outputs if o.is_linked and o.name not in ("Is Camera Ray", "Ray Length")]
    if linked:
        g.warn(f"'{node.name}' (Light Path): {', '.join(linked)} approximated (camera hits read as a camera ray, "
               "other hits as a reflection of depth 1)")
    camera = g.attribute("is_camera_ray", "float")
    one_minus = g.emit("one_minus", {}, [camera], ("float",))[0]
    zero = g.constant(0.0, "float")
    return {"Is Camera Ray": camera, "Is Shadow Ray": zero, "Is Diffuse Ray": one_minus, "Is Glossy Ray": zero,
            "Is Singular Ray": zero, "Is Reflection Ray": one_minus, "Is Transmission Ray": zero,
            "Is Volume Scatter Ray": zero, "Ray Length": g.attribute("ray_length", "float"),
            "Ray Depth": one_minus, "Diffuse Depth": one_minus, "Glossy Depth": zero, "Transparent Depth": zero,
            "Transmission Depth": zero, "Portal Depth": zero}


def _uvmap(g, node, f):
    if node.uv_map:
        g.warn(f"'{node.name}' names UV map '{node.uv_map}'; the render UV map is used")
    return {"UV": g.attribute("uv", "vector")}


def _geometry(g, node, f):
    return {"Position": g.attribute("position", "vector"), "Normal": g.attribute("normal", "vector"),
            "True Normal": g.attribute("true_normal", "vector"), "Incoming": g.attribute("incoming", "vector"),
            "Parametric": g.attribute("parametric", "vector"), "Backfacing": g.attribute("backfacing", "float"),
            "Tangent": g.attribute("tangent", "vector")}


def _object_info(g, node, f):
    return {"Location": g.attribute("object_location", "vector"), "Color": g.attribute("object_color", "color"),
            "Alpha": g.attribute("object_alpha", "float"), "Random": g.attribute("object_random", "float"),
            "Object Index": g.attribute("object_index", "float"), "Material Index": g.constant(g.material_index, "float")}


def _color_attribute(g, node, f):
    name = node.layer_name
    return {"Color": g.attribute(f"attr:{name}", "color"), "Alpha": g.attribute(f"attr_alpha:{name}", "float")}


def _attribute(g, node, f):
    if node.attribute_type != "GEOMETRY":
        return None
    name = node.attribute_name
    col = g.attribute(f"attr:{name}", "color")
    return {"Color": col, "Vector": Reg(col.index, "vector", col.const), "Fac": g.convert(Reg(col.index, "vector"),
                                                                                          "float"),
            "Alpha": g.attribute(f"attr_alpha:{name}", "float")}


def _fresnel(g, node, f):
    return {"Fac": g.emit("fresnel", {}, [g.inp(node, "IOR", "float", f),
                                          g.inp(node, "Normal", "vector", f, default="normal")], ("float",))[0]}


def _layer_weight(g, node, f):
    fr, fa = g.emit("layer_weight", {}, [g.inp(node, "Blend", "float", f),
                                         g.inp(node, "Normal", "vector", f, default="normal")], ("float", "float"))
    return {"Fresnel": fr, "Facing": fa}


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
    if space == "TANGENT":
        if node.uv_map:
            g.warn(f"'{node.name}' names UV map '{node.uv_map}'; the render UV map's tangents are used")
        g.attribute("tangent_uv", "vector")  # (read by the operation; named so that the export makes tangents)
    for name in ("normal", "backfacing"):
        g.attribute(name, "vector" if name == "normal" else "float")
    return {"Normal": g.emit("normal_map", {"space": space}, [strength, color], ("vector",))[0]}


def _bump(g, node, f):
    normal_in = g.inp(node, "Normal", "vector", f, default="normal")
    height = node.inputs["Height"]
    sub = GraphCompiler(g._textures, g._warn)
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


def _light_falloff(g, node, f):
    strength = g.inp(node, "Strength", "float", f)
    if node.outputs["Linear"].is_linked or node.outputs["Constant"].is_linked:
        g.warn(f"'{node.name}' (Light Falloff): Linear and Constant falloff are approximated by the physical "
               "(quadratic) falloff")
    smooth = g.inp(node, "Smooth", "float", f)
    if smooth.const is None or float(smooth.const) != 0.0:
        g.warn(f"'{node.name}' (Light Falloff): Smooth is not supported (treated as 0)")
    return {"Quadratic": strength, "Linear": strength, "Constant": strength}


_HANDLERS = {
    "TEX_COORD": _texcoord, "TANGENT": _tangent, "LIGHT_PATH": _light_path, "UVMAP": _uvmap,
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
    "VALTORGB": _color_ramp, "CURVE_RGB": _rgb_curves, "CURVE_FLOAT": _float_curve, "TEX_IMAGE": _image,
    "TEX_ENVIRONMENT": _environment,
    "TEX_NOISE": _noise, "TEX_WHITE_NOISE": _white_noise, "TEX_CHECKER": _checker, "TEX_GRADIENT": _gradient,
    "NORMAL_MAP": _normal_map, "BUMP": _bump, "TEX_VORONOI": _voronoi, "TEX_WAVE": _wave, "TEX_MAGIC": _magic,
    "TEX_BRICK": _brick, "BLACKBODY": _blackbody, "LIGHT_FALLOFF": _light_falloff,
}
