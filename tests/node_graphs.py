"""Shader node graphs for the node tests: each a function ``graph(tree, socket)`` that builds nodes in a material's
tree and links a colour into ``socket``, in families of cases (name, graph) that cover each node's parameters.
Outputs stay non-negative (an emission colour below 0 is not a radiance)."""
from __future__ import annotations

import math

import numpy as np
from bpy_scenes import packed_image


def _node(tree, kind, **props):
    n = tree.nodes.new(kind)
    for k, v in props.items():
        setattr(n, k, v)
    return n


def _set(node, ident, value):
    sock = next(s for s in node.inputs if s.identifier == ident)
    sock.default_value = value


def _in(node, ident):
    return next(s for s in node.inputs if s.identifier == ident)


def _out(node, ident):
    return next(s for s in node.outputs if s.identifier == ident)


def _link(tree, out, inp):
    tree.links.new(out, inp)


def _coords(tree, which="Generated"):
    return _node(tree, "ShaderNodeTexCoord").outputs[which]


def _abs(tree, out):
    m = _node(tree, "ShaderNodeMath", operation="ABSOLUTE")
    _link(tree, out, m.inputs[0])
    return m.outputs[0]


def noise(dims="3D", kind="FBM", scale=4.0, detail=2.5, roughness=0.5, lacunarity=2.0, distortion=0.0, w=0.3,
          offset=1.0, gain=1.0, normalize=True, output="Color", positive=False):
    def graph(tree, socket):
        n = _node(tree, "ShaderNodeTexNoise", noise_dimensions=dims, noise_type=kind, normalize=normalize)
        for ident, v in (("Scale", scale), ("Detail", detail), ("Roughness", roughness), ("Lacunarity", lacunarity),
                         ("Distortion", distortion), ("W", w), ("Offset", offset), ("Gain", gain)):
            _set(n, ident, v)
        out = n.outputs[output]
        _link(tree, _abs(tree, out) if positive else out, socket)
    return graph


NOISE = [
    ("fbm 3D", noise()), ("fbm 3D raw", noise(normalize=False, output="Fac", positive=True)),
    ("fbm 2D distorted", noise("2D", distortion=1.0)), ("fbm 4D", noise("4D", w=0.7, detail=1.3)),
    ("fbm 1D", noise("1D", w=2.3)), ("multifractal", noise(kind="MULTIFRACTAL", detail=3, roughness=0.6,
                                                          output="Fac", positive=True)),
    ("ridged", noise(kind="RIDGED_MULTIFRACTAL", detail=2, gain=2.0, output="Fac", positive=True)),
    ("hybrid 2D", noise("2D", "HYBRID_MULTIFRACTAL", detail=3.5, gain=1.5, offset=0.5, output="Fac", positive=True)),
    ("hetero 4D distorted", noise("4D", "HETERO_TERRAIN", distortion=0.5, detail=2.2, offset=0.3, output="Fac",
                                  positive=True)),
    ("fbm lacunarity", noise(scale=7.0, detail=0.0, lacunarity=2.5, output="Fac")),
]


def checker(scale=3.0):
    def graph(tree, socket):
        c = _node(tree, "ShaderNodeTexChecker")
        _set(c, "Scale", scale)
        _set(c, "Color1", (0.9, 0.3, 0.1, 1))
        _set(c, "Color2", (0.1, 0.2, 0.7, 1))
        _link(tree, c.outputs["Color"], socket)
    return graph


def gradient(kind, coords="Object"):
    def graph(tree, socket):
        g = _node(tree, "ShaderNodeTexGradient", gradient_type=kind)
        _link(tree, _coords(tree, coords), g.inputs["Vector"])
        _link(tree, g.outputs["Color"], socket)
    return graph


def white_noise(dims="3D", cells=6.0, output="Color"):
    def graph(tree, socket):
        m = _node(tree, "ShaderNodeVectorMath", operation="SCALE")
        _link(tree, _coords(tree), m.inputs[0])
        _set(m, "Scale", cells)
        f = _node(tree, "ShaderNodeVectorMath", operation="FLOOR")
        _link(tree, m.outputs[0], f.inputs[0])
        wn = _node(tree, "ShaderNodeTexWhiteNoise", noise_dimensions=dims)
        _set(wn, "W", 1.5)
        _link(tree, f.outputs[0], wn.inputs["Vector"])
        _link(tree, wn.outputs[output], socket)
    return graph


def _checker_image():
    n = 8
    yy, xx = np.mgrid[0:n, 0:n]
    rgb = np.stack([(xx + yy) % 2 * 0.8 + 0.1, xx / (n - 1), yy / (n - 1)], axis=-1).astype(np.float32)
    return packed_image("NodeChecker", rgb)


def image(interpolation="Linear", extension="REPEAT", rotation=30.0, scale=1.7, output="Color"):
    def graph(tree, socket):
        img = _node(tree, "ShaderNodeTexImage", interpolation=interpolation, extension=extension)
        img.image = _checker_image()
        mp = _node(tree, "ShaderNodeMapping", vector_type="POINT")
        _set(mp, "Rotation", (0, 0, math.radians(rotation)))
        _set(mp, "Scale", (scale, scale, 1))
        _set(mp, "Location", (-0.3, -0.2, 0))
        _link(tree, _coords(tree, "UV"), mp.inputs["Vector"])
        _link(tree, mp.outputs[0], img.inputs["Vector"])
        _link(tree, img.outputs[output], socket)
    return graph


TEXTURES = [
    ("checker", checker()), ("checker fine", checker(7.5)),
    *[(f"gradient {k.lower()}", gradient(k)) for k in ("LINEAR", "QUADRATIC", "EASING", "DIAGONAL", "SPHERICAL",
                                                          "QUADRATIC_SPHERE", "RADIAL")],
    ("gradient generated", gradient("LINEAR", "Generated")),
    ("white noise 3D", white_noise()), ("white noise 2D value", white_noise("2D", 5.0, "Value")),
    ("white noise 4D", white_noise("4D", 4.0)),
    ("image linear repeat", image()), ("image closest extend", image("Closest", "EXTEND")),
    ("image cubic mirror", image("Cubic", "MIRROR")), ("image linear clip", image("Linear", "CLIP", 10.0, 1.3)),
    ("image alpha clip", image("Closest", "CLIP", -20.0, 1.4, "Alpha")),
]


def ramp(interpolation, mode="RGB", hue="NEAR"):
    def graph(tree, socket):
        g = _node(tree, "ShaderNodeTexGradient")
        r = _node(tree, "ShaderNodeValToRGB")
        cr = r.color_ramp
        cr.interpolation = interpolation
        cr.color_mode = mode
        if mode != "RGB":
            cr.hue_interpolation = hue
        cr.elements[0].position = 0.1
        cr.elements[0].color = (1, 0.1, 0, 1)
        e = cr.elements.new(0.45)
        e.color = (0.1, 0.9, 0.2, 1)
        cr.elements[-1].position = 0.85
        cr.elements[-1].color = (0.2, 0.3, 1.0, 1)
        _link(tree, g.outputs["Fac"], r.inputs["Fac"])
        _link(tree, r.outputs["Color"], socket)
    return graph


def _x_of(tree, coords="Generated"):
    s = _node(tree, "ShaderNodeSeparateXYZ")
    _link(tree, _coords(tree, coords), s.inputs[0])
    return s


def math_op(op, b=0.35, c=0.2, scale=3.0, clamp=False):
    def graph(tree, socket):
        s = _x_of(tree, "Object")
        pre = _node(tree, "ShaderNodeMath", operation="MULTIPLY")
        _link(tree, s.outputs["X"], pre.inputs[0])
        _set(pre, "Value_001", scale)
        m = _node(tree, "ShaderNodeMath", operation=op, use_clamp=clamp)
        _link(tree, pre.outputs[0], m.inputs[0])
        if op in {"ARCTAN2", "SMOOTH_MIN", "SMOOTH_MAX", "COMPARE"}:
            _link(tree, s.outputs["Y"], m.inputs[1])
        else:
            _set(m, "Value_001", b)
        _set(m, "Value_002", c)
        _link(tree, _abs(tree, m.outputs[0]), socket)
    return graph


def vector_op(op, b=(0.3, -0.5, 0.8), scale=1.5):
    def graph(tree, socket):
        m = _node(tree, "ShaderNodeVectorMath", operation=op)
        _link(tree, _coords(tree, "Object"), m.inputs[0])
        _set(m, "Vector_001", b)
        _set(m, "Vector_002", (0.5, 0.5, 0.5))
        _set(m, "Scale", scale)
        out = m.outputs["Value"] if op in {"DOT_PRODUCT", "DISTANCE", "LENGTH"} else m.outputs["Vector"]
        a = _node(tree, "ShaderNodeVectorMath", operation="ABSOLUTE")
        _link(tree, out, a.inputs[0])
        _link(tree, a.outputs[0], socket)
    return graph


def map_range(kind, clamp=True, vector=False):
    def graph(tree, socket):
        m = _node(tree, "ShaderNodeMapRange", interpolation_type=kind, clamp=clamp,
                  data_type="FLOAT_VECTOR" if vector else "FLOAT")
        if vector:
            _link(tree, _coords(tree), m.inputs["Vector"])
            _set(m, "From_Min_FLOAT3", (0.2, 0.1, 0.0))
            _set(m, "From_Max_FLOAT3", (0.8, 0.9, 1.0))
            _set(m, "Steps_FLOAT3", (4, 3, 2))
            _link(tree, m.outputs["Vector"], socket)
        else:
            _link(tree, _x_of(tree).outputs["X"], m.inputs["Value"])
            _set(m, "From Min", 0.2)
            _set(m, "From Max", 0.7)
            _set(m, "To Min", 0.1)
            _set(m, "To Max", 0.9)
            _set(m, "Steps", 3.0)
            _link(tree, m.outputs["Result"], socket)
    return graph


def color_node(kind, **inputs):
    """A colour converter fed by a Checker-and-Gradient mixture."""
    def graph(tree, socket):
        g = _node(tree, "ShaderNodeTexGradient", gradient_type="DIAGONAL")
        n = _node(tree, "ShaderNodeTexNoise")
        mix = _node(tree, "ShaderNodeMix", data_type="RGBA")
        _link(tree, g.outputs["Fac"], _in(mix, "Factor_Float"))
        _set(mix, "A_Color", (0.9, 0.2, 0.1, 1))
        _link(tree, n.outputs["Color"], _in(mix, "B_Color"))
        node = _node(tree, kind)
        for ident, v in inputs.items():
            _set(node, ident, v)
        col = next(s for s in node.inputs if s.type == "RGBA")
        _link(tree, _out(mix, "Result_Color"), col)
        _link(tree, node.outputs[0], socket)
    return graph


def separate_combine(mode):
    def graph(tree, socket):
        n = _node(tree, "ShaderNodeTexNoise")
        sep = _node(tree, "ShaderNodeSeparateColor", mode=mode)
        com = _node(tree, "ShaderNodeCombineColor", mode=mode)
        _link(tree, n.outputs["Color"], sep.inputs[0])
        _link(tree, sep.outputs[0], com.inputs[1])
        _link(tree, sep.outputs[1], com.inputs[2])
        _link(tree, sep.outputs[2], com.inputs[0])
        _link(tree, com.outputs[0], socket)
    return graph


def curves(kind):
    def graph(tree, socket):
        g = _node(tree, "ShaderNodeTexGradient")
        node = _node(tree, "ShaderNodeRGBCurve" if kind == "RGB" else "ShaderNodeFloatCurve")
        m = node.mapping
        for k, c in enumerate(m.curves):
            c.points.new(0.4, 0.2 + 0.2 * k)
        m.update()
        if kind == "RGB":
            r = _node(tree, "ShaderNodeValToRGB")
            _link(tree, g.outputs["Fac"], r.inputs["Fac"])
            _link(tree, r.outputs["Color"], node.inputs["Color"])
            _link(tree, node.outputs["Color"], socket)
        else:
            _link(tree, g.outputs["Fac"], node.inputs["Value"])
            _link(tree, node.outputs["Value"], socket)
    return graph


def vector_curves():
    """Vector Curves over Object coordinates scaled to [-0.8, 0.8], a point added to each curve (absolute)."""
    def graph(tree, socket):
        m = _node(tree, "ShaderNodeVectorMath", operation="SCALE")
        _link(tree, _coords(tree, "Object"), m.inputs[0])
        _set(m, "Scale", 1.6)
        node = _node(tree, "ShaderNodeVectorCurve")
        for k, c in enumerate(node.mapping.curves):
            c.points.new(-0.3 + 0.3 * k, 0.4 - 0.3 * k)
        node.mapping.update()
        _in(node, "Fac").default_value = 0.9
        _link(tree, m.outputs[0], node.inputs["Vector"])
        _link(tree, _vabs(tree, node.outputs["Vector"]), socket)
    return graph


def wavelength_node():
    """Wavelength over Generated X from 350 to 810 nm (black at both ends, outside the visible range)."""
    def graph(tree, socket):
        m = _node(tree, "ShaderNodeMapRange")
        _link(tree, _x_of(tree).outputs["X"], m.inputs["Value"])
        _set(m, "To Min", 350.0)
        _set(m, "To Max", 810.0)
        w = _node(tree, "ShaderNodeWavelength")
        _link(tree, m.outputs["Result"], w.inputs[0])
        _link(tree, w.outputs[0], socket)
    return graph


CONVERTERS = [
    *[(f"ramp {k.lower()}", ramp(k)) for k in ("LINEAR", "CONSTANT", "EASE", "CARDINAL", "B_SPLINE")],
    ("ramp hsv", ramp("LINEAR", "HSV", "FAR")), ("ramp hsl", ramp("LINEAR", "HSL", "CW")),
    *[(f"math {op.lower()}", math_op(op)) for op in ("POWER", "WRAP", "PINGPONG", "SMOOTH_MIN", "ARCTAN2", "SNAP",
                                                     "SINE", "LOGARITHM", "FRACT",
                                                     "TANH", "ROUND")],
    ("math sqrt", math_op("SQRT", scale=-3.0)), ("math compare", math_op("COMPARE", c=0.9)),
    ("math floored_modulo", math_op("FLOORED_MODULO", b=1.1)),
    ("math clamp", math_op("MULTIPLY", 1.7, clamp=True)),
    *[(f"vector {op.lower()}", vector_op(op)) for op in ("CROSS_PRODUCT", "REFLECT", "PROJECT", "REFRACT",
                                                        "LENGTH", "DISTANCE", "NORMALIZE", "WRAP", "SNAP",
                                                        "MODULO", "FACEFORWARD", "DOT_PRODUCT")],
    *[(f"map range {k.lower()}", map_range(k)) for k in ("LINEAR", "STEPPED", "SMOOTHSTEP", "SMOOTHERSTEP")],
    ("map range vector stepped", map_range("STEPPED", vector=True)),
    ("invert", color_node("ShaderNodeInvert", Fac=0.8)), ("gamma", color_node("ShaderNodeGamma", Gamma=2.2)),
    ("bright contrast", color_node("ShaderNodeBrightContrast", Bright=0.1, Contrast=0.6)),
    ("hue saturation", color_node("ShaderNodeHueSaturation", Hue=0.3, Saturation=1.4, Value=0.9, Fac=0.9)),
    ("rgb to bw", color_node("ShaderNodeRGBToBW")),
    ("separate combine hsv", separate_combine("HSV")), ("separate combine hsl", separate_combine("HSL")),
    ("rgb curves", curves("RGB")), ("float curve", curves("FLOAT")), ("vector curves", vector_curves()),
    ("wavelength", wavelength_node()),
]


def mix_color(blend, fac=0.7, clamp=False):
    def graph(tree, socket):
        g = _node(tree, "ShaderNodeTexGradient", gradient_type="DIAGONAL")
        r = _node(tree, "ShaderNodeValToRGB")
        r.color_ramp.elements[0].color = (0.9, 0.4, 0.1, 1)
        r.color_ramp.elements[1].color = (0.1, 0.3, 0.8, 1)
        _link(tree, g.outputs["Fac"], r.inputs["Fac"])
        n = _node(tree, "ShaderNodeTexNoise")
        m = _node(tree, "ShaderNodeMix", data_type="RGBA", blend_type=blend, clamp_result=clamp)
        _set(m, "Factor_Float", fac)
        _link(tree, r.outputs["Color"], _in(m, "A_Color"))
        _link(tree, n.outputs["Color"], _in(m, "B_Color"))
        out = _out(m, "Result_Color")
        if blend in {"SUBTRACT", "DIFFERENCE", "LINEAR_LIGHT"}:
            a = _node(tree, "ShaderNodeVectorMath", operation="ABSOLUTE")
            _link(tree, out, a.inputs[0])
            out = a.outputs[0]
        _link(tree, out, socket)
    return graph


def mix_vector(uniform=True):
    def graph(tree, socket):
        m = _node(tree, "ShaderNodeMix", data_type="VECTOR", factor_mode="UNIFORM" if uniform else "NON_UNIFORM")
        _link(tree, _coords(tree), _in(m, "A_Vector"))
        _set(m, "B_Vector", (0.9, 0.1, 0.4))
        if uniform:
            _link(tree, _x_of(tree).outputs["Y"], _in(m, "Factor_Float"))
        else:
            _link(tree, _coords(tree), _in(m, "Factor_Vector"))
        _link(tree, _out(m, "Result_Vector"), socket)
    return graph


BLENDS = ("MIX", "DARKEN", "MULTIPLY", "BURN", "LIGHTEN", "SCREEN", "DODGE", "ADD", "OVERLAY", "SOFT_LIGHT",
          "LINEAR_LIGHT", "DIFFERENCE", "EXCLUSION", "SUBTRACT", "DIVIDE", "HUE", "SATURATION", "COLOR", "VALUE")
MIXES = [*[(f"mix {b.lower()}", mix_color(b)) for b in BLENDS], ("mix add clamped", mix_color("ADD", 1.0, True)),
         ("mix vector", mix_vector()), ("mix vector non-uniform", mix_vector(False))]


def coords(which, op="ABSOLUTE", scale=1.0):
    def graph(tree, socket):
        m = _node(tree, "ShaderNodeVectorMath", operation="SCALE")
        _link(tree, _coords(tree, which), m.inputs[0])
        _set(m, "Scale", scale)
        a = _node(tree, "ShaderNodeVectorMath", operation=op)
        _link(tree, m.outputs[0], a.inputs[0])
        _link(tree, a.outputs[0], socket)
    return graph


def geometry(output, tilt=0.0):
    def graph(tree, socket):
        g = _node(tree, "ShaderNodeNewGeometry")
        out = g.outputs[output]
        if out.type == "VECTOR":
            a = _node(tree, "ShaderNodeVectorMath", operation="ABSOLUTE")
            _link(tree, out, a.inputs[0])
            out = a.outputs[0]
        _link(tree, out, socket)
    graph.setup = lambda obj: setattr(obj, "rotation_euler", (tilt, 0.4 * tilt, 0))
    return graph


def layer_weight(output, blend, tilt):
    def graph(tree, socket):
        lw = _node(tree, "ShaderNodeLayerWeight")
        _set(lw, "Blend", blend)
        _link(tree, lw.outputs[output], socket)
    graph.setup = lambda obj: setattr(obj, "rotation_euler", (tilt, 0, 0))
    return graph


def fresnel(ior, tilt):
    def graph(tree, socket):
        f = _node(tree, "ShaderNodeFresnel")
        _set(f, "IOR", ior)
        _link(tree, f.outputs[0], socket)
    graph.setup = lambda obj: setattr(obj, "rotation_euler", (tilt, 0, 0))
    return graph


def object_info(output):
    def graph(tree, socket):
        o = _node(tree, "ShaderNodeObjectInfo")
        out = o.outputs[output]
        if out.type == "VECTOR":
            a = _node(tree, "ShaderNodeVectorMath", operation="ABSOLUTE")
            _link(tree, out, a.inputs[0])
            out = a.outputs[0]
        _link(tree, out, socket)
    graph.setup = lambda obj: setattr(obj, "color", (0.3, 0.6, 0.9, 0.5))
    return graph


def color_attribute(domain="POINT", output="Color"):
    def graph(tree, socket):
        c = _node(tree, "ShaderNodeVertexColor", layer_name="Paint")
        _link(tree, c.outputs[output], socket)

    def setup(obj):
        mesh = obj.data
        attr = mesh.color_attributes.new("Paint", "FLOAT_COLOR", domain)
        n = len(attr.data)
        vals = np.array([[0.9, 0.1, 0.2, 0.3], [0.1, 0.8, 0.3, 0.9], [0.2, 0.3, 0.9, 0.6], [0.9, 0.9, 0.1, 1.0]],
                        np.float32)[np.arange(n) % 4]
        attr.data.foreach_set("color", vals.ravel())
    graph.setup = setup
    return graph


def group_reroute_mute():
    """A node group (Noise -> Math inside, a group input scaling the coordinates), reroutes, and a muted node."""
    def graph(tree, socket):
        import bpy
        grp = bpy.data.node_groups.get("NoiseGroup")
        if grp is None:
            grp = bpy.data.node_groups.new("NoiseGroup", "ShaderNodeTree")
            grp.interface.new_socket("Vector", in_out="INPUT", socket_type="NodeSocketVector")
            grp.interface.new_socket("Gain", in_out="INPUT", socket_type="NodeSocketFloat")
            grp.interface.new_socket("Result", in_out="OUTPUT", socket_type="NodeSocketColor")
            gi = grp.nodes.new("NodeGroupInput")
            go = grp.nodes.new("NodeGroupOutput")
            nz = grp.nodes.new("ShaderNodeTexNoise")
            rr = grp.nodes.new("NodeReroute")
            mx = grp.nodes.new("ShaderNodeMix")
            mx.data_type = "RGBA"
            mx.blend_type = "MULTIPLY"
            grp.links.new(gi.outputs[0], rr.inputs[0])
            grp.links.new(rr.outputs[0], nz.inputs["Vector"])
            grp.links.new(nz.outputs["Color"], _in(mx, "A_Color"))
            grp.links.new(gi.outputs[1], _in(mx, "Factor_Float"))
            _in(mx, "B_Color").default_value = (0.2, 0.9, 0.4, 1)
            grp.links.new(_out(mx, "Result_Color"), go.inputs[0])
        node = _node(tree, "ShaderNodeGroup")
        node.node_tree = grp
        node.inputs[1].default_value = 0.8
        muted = _node(tree, "ShaderNodeVectorMath", operation="SCALE")
        muted.mute = True  # passes its first input through
        _link(tree, _coords(tree, "Object"), muted.inputs[0])
        rr = _node(tree, "NodeReroute")
        _link(tree, muted.outputs[0], rr.inputs[0])
        _link(tree, rr.outputs[0], node.inputs[0])
        _link(tree, node.outputs[0], socket)
    return graph


def light_path(output="Is Camera Ray"):
    def graph(tree, socket):
        lp = _node(tree, "ShaderNodeLightPath")
        mix = _node(tree, "ShaderNodeMix", data_type="RGBA")
        _link(tree, lp.outputs[output], mix.inputs["Factor"])
        _in(mix, "A_Color").default_value = (0.9, 0.2, 0.1, 1.0)
        _in(mix, "B_Color").default_value = (0.1, 0.4, 0.8, 1.0)
        _link(tree, _out(mix, "Result_Color"), socket)
    return graph


def wireframe(size, pixel_size=False, turn=0.0):
    """The Wireframe node's Fac of a plane turned by ``turn`` about the view axis (its two triangles' edges), scaled
    to 0.7 so that its corners stay inside its own cell."""
    def graph(tree, socket):
        w = _node(tree, "ShaderNodeWireframe", use_pixel_size=pixel_size)
        _set(w, "Size", size)
        mix = _node(tree, "ShaderNodeMix", data_type="RGBA")  # lines over a grey ground (every cell lit)
        _link(tree, w.outputs["Fac"], mix.inputs["Factor"])
        _in(mix, "A_Color").default_value = (0.2, 0.3, 0.4, 1.0)
        _in(mix, "B_Color").default_value = (0.9, 0.8, 0.7, 1.0)
        _link(tree, _out(mix, "Result_Color"), socket)
    def setup(obj):
        obj.rotation_euler = (0, 0, turn)
        obj.scale = (0.7, 0.7, 0.7)
    graph.setup = setup
    return graph


def pass_index(output, value):
    """Object Info's Object / Material Index over 8, the object's / material's Pass Index set to ``value``."""
    def graph(tree, socket):
        o = _node(tree, "ShaderNodeObjectInfo")
        m = _node(tree, "ShaderNodeMath", operation="DIVIDE")
        _link(tree, o.outputs[output], m.inputs[0])
        m.inputs[1].default_value = 8.0
        _link(tree, m.outputs[0], socket)

    def setup(obj):
        if output == "Object Index":
            obj.pass_index = value
        else:
            obj.active_material.pass_index = value
    graph.setup = setup
    return graph


def camera_data(output, tilt=0.6):
    """Camera Data's View Vector (absolute), or its View Z Depth / View Distance scaled by 0.15, on a tilted plane."""
    def graph(tree, socket):
        c = _node(tree, "ShaderNodeCameraData")
        out = c.outputs[output]
        if out.type == "VECTOR":
            out = _vabs(tree, out)
        else:
            m = _node(tree, "ShaderNodeMath", operation="MULTIPLY")
            _link(tree, out, m.inputs[0])
            m.inputs[1].default_value = 0.15
            out = m.outputs[0]
        _link(tree, out, socket)
    graph.setup = lambda obj: setattr(obj, "rotation_euler", (tilt, 0.5 * tilt, 0))
    return graph


def normal_node(output, direction=(0.3, -0.5, 0.8), tilt=0.7):
    """The Normal node on a tilted plane: its Dot with the Geometry normal (absolute), or its own direction."""
    def graph(tree, socket):
        n = _node(tree, "ShaderNodeNormal")
        n.outputs["Normal"].default_value = direction
        _link(tree, _node(tree, "ShaderNodeNewGeometry").outputs["Normal"], n.inputs["Normal"])
        out = _abs(tree, n.outputs["Dot"]) if output == "Dot" else _vabs(tree, n.outputs["Normal"])
        _link(tree, out, socket)
    graph.setup = lambda obj: setattr(obj, "rotation_euler", (tilt, -0.4 * tilt, 0))
    return graph


def vector_transform(kind, src, dst, tilt=0.6):
    """Vector Transform of the Geometry Position (POINT, scaled to about [0, 1]), Incoming (VECTOR) or a constant
    direction (NORMAL: the inverse transpose of a non-uniform scale shows) on a tilted plane stretched to 0.9 x 0.55
    (an object transform with a non-uniform scale), absolute."""
    def graph(tree, socket):
        t = _node(tree, "ShaderNodeVectorTransform", vector_type=kind, convert_from=src, convert_to=dst)
        if kind == "NORMAL":
            t.inputs["Vector"].default_value = (0.6, 0.3, 0.74)
        else:
            source = "Position" if kind == "POINT" else "Incoming"
            _link(tree, _node(tree, "ShaderNodeNewGeometry").outputs[source], t.inputs["Vector"])
        out = t.outputs["Vector"]
        if kind == "POINT":
            m = _node(tree, "ShaderNodeVectorMath", operation="SCALE")
            _link(tree, out, m.inputs[0])
            _set(m, "Scale", 1.5 if dst == "OBJECT" else 0.3)
            out = m.outputs[0]
        _link(tree, _vabs(tree, out), socket)

    def setup(obj):
        obj.rotation_euler = (tilt, 0.5 * tilt, 0.3)
        obj.scale = (0.9, 0.55, 1.0)
    graph.setup = setup
    return graph


INPUTS = [
    ("generated", coords("Generated")), ("object", coords("Object", scale=1.5)), ("uv", coords("UV")),
    ("object normal", coords("Normal")), ("reflection", coords("Reflection")),
    ("position", geometry("Position")), ("normal tilted", geometry("Normal", 0.5)),
    ("true normal tilted", geometry("True Normal", -0.7)), ("incoming", geometry("Incoming", 0.3)),
    ("backfacing", geometry("Backfacing", 2.6)), ("parametric", geometry("Parametric")),
    *[(f"layer weight {o.lower()} {b}", layer_weight(o, b, t)) for o, b, t in
      (("Fresnel", 0.3, 0.6), ("Facing", 0.3, 0.9), ("Facing", 0.8, 0.4), ("Fresnel", 0.6, 1.1))],
    ("fresnel 1.45", fresnel(1.45, 1.0)), ("fresnel 2.4", fresnel(2.4, 0.5)),
    ("object random", object_info("Random")), ("object color", object_info("Color")),
    ("object location", object_info("Location")),
    ("color attribute point", color_attribute()), ("color attribute corner", color_attribute("CORNER")),
    ("color attribute alpha", color_attribute("POINT", "Alpha")),
    ("group reroute mute", group_reroute_mute()),
    ("camera", coords("Camera", scale=0.2)), ("window", coords("Window")),
    ("tangent tilted", geometry("Tangent", 0.6)),
    ("object index", pass_index("Object Index", 3)), ("material index", pass_index("Material Index", 5)),
    ("light path camera", light_path()),
    ("wireframe", wireframe(0.12, turn=0.3)), ("wireframe pixel size", wireframe(2.0, pixel_size=True, turn=-0.2)),
    ("camera data view vector", camera_data("View Vector")), ("camera data z depth", camera_data("View Z Depth")),
    ("camera data distance", camera_data("View Distance", -0.9)),
    ("normal dot", normal_node("Dot")), ("normal direction", normal_node("Normal")),
    *[(f"vector transform {k.lower()} {a.lower()} {b.lower()}", vector_transform(k, a, b)) for k, a, b in
      (("POINT", "WORLD", "OBJECT"), ("POINT", "OBJECT", "CAMERA"), ("VECTOR", "WORLD", "CAMERA"),
       ("VECTOR", "CAMERA", "OBJECT"), ("NORMAL", "WORLD", "OBJECT"), ("NORMAL", "OBJECT", "CAMERA"),
       ("NORMAL", "OBJECT", "WORLD"))],
]

def _vabs(tree, out):
    m = _node(tree, "ShaderNodeVectorMath", operation="ABSOLUTE")
    _link(tree, out, m.inputs[0])
    return m.outputs[0]


def voronoi(dims="3D", feature="F1", metric="EUCLIDEAN", scale=5.0, output="Distance", detail=0.0, roughness=0.5,
            lacunarity=2.0, smoothness=1.0, exponent=0.7, randomness=1.0, w=0.4, normalize=False, coords="Generated"):
    def graph(tree, socket):
        v = _node(tree, "ShaderNodeTexVoronoi", voronoi_dimensions=dims, feature=feature, distance=metric,
                  normalize=normalize)
        for ident, val in (("Scale", scale), ("Detail", detail), ("Roughness", roughness),
                           ("Lacunarity", lacunarity), ("Smoothness", smoothness), ("Exponent", exponent),
                           ("Randomness", randomness), ("W", w)):
            _set(v, ident, val)
        _link(tree, _coords(tree, coords), _in(v, "Vector"))
        out = _out(v, output)
        if output == "Position":
            out = _vabs(tree, out)
        elif output == "W":
            out = _abs(tree, out)
        _link(tree, out, socket)
    return graph


VORONOI = [
    ("f1 3D", voronoi()), ("f1 3D color", voronoi(output="Color")), ("f1 3D position", voronoi(output="Position")),
    ("f2 2D manhattan", voronoi("2D", "F2", "MANHATTAN")), ("f1 2D chebychev", voronoi("2D", metric="CHEBYCHEV")),
    ("f1 3D minkowski", voronoi(metric="MINKOWSKI", exponent=0.7)),
    ("smooth f1 3D", voronoi(feature="SMOOTH_F1", smoothness=0.8, output="Color")),
    ("smooth f1 2D distance", voronoi("2D", "SMOOTH_F1", smoothness=0.5)),
    ("edge 2D", voronoi("2D", "DISTANCE_TO_EDGE", randomness=0.8)), ("edge 3D", voronoi(feature="DISTANCE_TO_EDGE")),
    ("n-sphere 3D", voronoi(feature="N_SPHERE_RADIUS", output="Radius")),
    ("f1 4D", voronoi("4D", w=0.7, output="Color")), ("f2 4D w", voronoi("4D", "F2", w=0.35, output="W")),
    ("f1 1D", voronoi("1D", w=1.3, output="Color")), ("edge 1D", voronoi("1D", "DISTANCE_TO_EDGE", w=2.1)),
    ("f1 fractal normalized", voronoi(detail=2.5, roughness=0.6, normalize=True)),
    ("f2 fractal color", voronoi("2D", "F2", detail=1.5, output="Color", normalize=True)),
    ("edge fractal", voronoi(feature="DISTANCE_TO_EDGE", detail=2.0, lacunarity=2.5, normalize=True)),
    ("f1 fractal position", voronoi("2D", detail=1.7, output="Position")),
    ("f1 randomness", voronoi(randomness=0.4, scale=3.0, coords="Object")),
]


def wave(kind="BANDS", direction="X", profile="SIN", scale=2.0, distortion=0.0, detail=2.0, phase=0.0):
    def graph(tree, socket):
        t = _node(tree, "ShaderNodeTexWave", wave_type=kind, wave_profile=profile)
        if kind == "BANDS":
            t.bands_direction = direction
        else:
            t.rings_direction = direction
        for ident, val in (("Scale", scale), ("Distortion", distortion), ("Detail", detail),
                           ("Detail Scale", 1.5), ("Detail Roughness", 0.5), ("Phase Offset", phase)):
            _set(t, ident, val)
        _link(tree, t.outputs["Color"], socket)
    return graph


def magic(depth=2, scale=5.0, distortion=1.0, coords="Generated", stretch=1.0):
    def graph(tree, socket):
        t = _node(tree, "ShaderNodeTexMagic", turbulence_depth=depth)
        _set(t, "Scale", scale)
        _set(t, "Distortion", distortion)
        m = _node(tree, "ShaderNodeVectorMath", operation="SCALE")
        _link(tree, _coords(tree, coords), m.inputs[0])
        _set(m, "Scale", stretch)
        _link(tree, m.outputs[0], t.inputs["Vector"])
        _link(tree, t.outputs["Color"], socket)
    return graph


def brick(scale=3.0, offset=0.5, offset_frequency=2, squash=1.0, squash_frequency=2, smooth=0.5, bias=0.0,
          output="Color", mortar=0.03):
    def graph(tree, socket):
        t = _node(tree, "ShaderNodeTexBrick", offset=offset, offset_frequency=offset_frequency, squash=squash,
                  squash_frequency=squash_frequency)
        for ident, val in (("Scale", scale), ("Mortar Size", mortar), ("Mortar Smooth", smooth), ("Bias", bias),
                           ("Brick Width", 0.5), ("Row Height", 0.25)):
            _set(t, ident, val)
        _set(t, "Color1", (0.8, 0.3, 0.1, 1))
        _set(t, "Color2", (0.2, 0.5, 0.9, 1))
        _set(t, "Mortar", (0.05, 0.05, 0.05, 1))
        _link(tree, _coords(tree, "Object"), t.inputs["Vector"])
        _link(tree, t.outputs[output], socket)
    return graph


PATTERNS = [
    ("wave bands x", wave()), ("wave bands diagonal saw", wave(direction="DIAGONAL", profile="SAW", phase=0.7)),
    ("wave rings spherical tri", wave("RINGS", "SPHERICAL", "TRI", scale=1.5)),
    ("wave rings z distorted", wave("RINGS", "Z", distortion=3.0, detail=1.5)),
    ("wave bands y distorted", wave(direction="Y", distortion=5.0, detail=0.0)),
    ("magic depth 2", magic()), ("magic depth 5", magic(5, 3.0, 1.7)),
    ("magic beyond two pi", magic(3, 0.3, 1.2, coords="Object", stretch=25.0)), ("magic depth 0", magic(0, 4.0, 0.0)),
    ("brick", brick()), ("brick squashed", brick(4.0, 0.3, 3, 0.6, 2, 0.4, 0.2)),
    ("brick mortar fac", brick(smooth=0.7, output="Fac", mortar=0.1)),
]


def gabor(kind="2D", output="Value", scale=5.0, frequency=2.0, anisotropy=1.0, orientation=0.6,
          orientation_3d=(1.0, 0.5, 0.3)):
    def graph(tree, socket):
        n = _node(tree, "ShaderNodeTexGabor", gabor_type=kind)
        for ident, v in (("Scale", scale), ("Frequency", frequency), ("Anisotropy", anisotropy),
                         ("Orientation 2D", orientation), ("Orientation 3D", orientation_3d)):
            _set(n, ident, v)
        _link(tree, n.outputs[output], socket)
    return graph


GABOR = [
    ("gabor 2D value", gabor()), ("gabor 2D isotropic value", gabor(anisotropy=0.2, frequency=3.0)),
    ("gabor 2D phase", gabor(output="Phase", scale=2.0, frequency=1.0)),
    ("gabor 2D intensity", gabor(output="Intensity")),
    ("gabor 3D value", gabor("3D")), ("gabor 3D isotropic value", gabor("3D", anisotropy=0.4)),
    ("gabor 3D intensity", gabor("3D", output="Intensity", frequency=1.5)),
]

FAMILIES = {"noise": NOISE, "textures": TEXTURES, "converters": CONVERTERS, "mixes": MIXES, "inputs": INPUTS,
            "voronoi": VORONOI, "patterns": PATTERNS, "gabor": GABOR}
