"""Sheen rows: the Sheen BSDF (velvet, glTF's sheen) and the Principled BSDF's Sheen layer (Weight, Roughness,
Tint), which Cycles puts on top of the rest of the BSDF (coat, base and emission), dimming it by the sheen's albedo
toward the viewer R(μo) (core/materials/nodes/ops_layers.sheen_albedo). The Microfiber lobe is core/materials/sheen.py's
separable lobe of Cycles' measured albedo (reported as an approximation); Ashikhmin's lobe (the Sheen BSDF's other
distribution) is a diffuse of its average albedo (:data:`SHEEN_ALBEDO`)."""
from __future__ import annotations

import numpy as np

#: The Sheen BSDF's albedo under a uniform white world, averaged over view directions with weight cos θ (the lobe's
#: share of the light it receives), at roughness SHEEN_ROUGHNESS, measured from Cycles (Blender 5.2, one bounce)
SHEEN_ROUGHNESS = (0.0, 0.1, 0.3, 0.5, 0.75, 1.0)
SHEEN_ALBEDO = {"MICROFIBER": (0.0, 0.00003, 0.0178, 0.0967, 0.260, 0.434),
                "ASHIKHMIN": (0.0, 0.0006, 0.0499, 0.156, 0.304, 0.434)}
#: Cycles' closure weight below which a layer is left out
CUTOFF = 1e-5


def _normal(g, node):
    sock = node.inputs.get("Normal")
    return g.value(sock, "vector", default="normal") if sock is not None else g.attribute("normal", "vector")


def sheen_row(registry, material, node) -> dict:
    """The row of a Sheen BSDF ``node``: Microfiber as core/materials/sheen.py's separable lobe of its Color and
    Roughness (either from any graph: the program's "base_color" and "sheen_roughness"); Ashikhmin as a diffuse of its
    Color times the lobe's mean albedo (:data:`SHEEN_ALBEDO`). Named in a warning. ``registry``: the MaterialRegistry."""
    registry._warn(material, f"'{node.name}' (Sheen BSDF) is approximated by a separable lobe of its measured "
                   "albedo")
    g, varying = registry._compiler(material), {}
    row = {"f0": 0.0, "metallic": 0.0}
    if getattr(node, "distribution", "MICROFIBER") == "MICROFIBER":
        rough = registry._param(material, g, node.inputs["Roughness"], "float", "sheen_roughness", varying)
        row["sheen_roughness"] = max(float(np.clip(rough, 0, 1)), 1e-3)
        row["base_color"] = registry._param(material, g, node.inputs["Color"], "color", "base_color", varying)
    else:
        rough = float(np.clip(registry._float_input(material, node.inputs["Roughness"]), 0, 1))
        albedo = float(np.interp(rough, SHEEN_ROUGHNESS, SHEEN_ALBEDO["ASHIKHMIN"]))
        colour = g.emit("scale", {}, [g.value(node.inputs["Color"], "color"), g.constant(albedo, "float")],
                        ("color",))[0]
        if colour.const is not None:
            row["base_color"] = colour.constant_value()
        else:
            row["base_color"] = (1.0, 1.0, 1.0)
            varying["base_color"] = colour
    registry._normal(material, node, row, g, varying)
    return registry._with_program(row, g, varying)


def sheen_set(node) -> bool:
    """Whether a Principled BSDF node may have a sheen layer (Sheen Weight linked, or above the cut-off)."""
    sock = node.inputs.get("Sheen Weight") if node.type == "BSDF_PRINCIPLED" else None
    return sock is not None and (sock.is_linked or float(sock.default_value) > CUTOFF)


def sheen_layer(registry, material, g, node):
    """A Principled BSDF's sheen as a Mix component, registers of compiler ``g`` where they vary: (its row: the
    sheen lobe of the Sheen Tint and Roughness, its weight Sheen Weight, the layering factor of what lies under it
    1 - Sheen Weight x max(Tint) x R(μo, Sheen Roughness), the component's reflectance estimate); None where the
    weight folds to the cut-off or below. Weight, Roughness and Tint may come from any graph."""
    inp = node.inputs
    weight = g.value(inp["Sheen Weight"], "float")
    if weight.const is not None and weight.constant_value() <= CUTOFF:
        return None
    registry._warn(material, f"'{node.name}' (Principled) Sheen is approximated by a separable lobe of its "
                   "measured albedo")
    rough = g.value(inp["Sheen Roughness"], "float")
    albedo = g.emit("sheen_albedo", {}, [rough, _normal(g, node)], ("float",))[0]
    rg, rvarying = registry._compiler(material), {}
    row = {"f0": 0.0, "metallic": 0.0}
    r = registry._param(material, rg, inp["Sheen Roughness"], "float", "sheen_roughness", rvarying)
    row["sheen_roughness"] = max(float(np.clip(r, 0, 1)), 1e-3)
    row["base_color"] = registry._param(material, rg, inp["Sheen Tint"], "color", "base_color", rvarying)
    registry._normal(material, node, row, rg, rvarying)  # the sheen follows the Principled BSDF's Normal
    row = registry._with_program(row, rg, rvarying)
    tint = g.value(inp["Sheen Tint"], "color")
    if tint.const is not None:
        brightest = g.constant(max(max(float(c), 0.0) for c in tint.constant_value()[:3]), "float")
    else:
        rgb = g.emit("separate", {"mode": "RGB"}, [tint], ("float", "float", "float"))
        brightest = g.emit("math", {"op": "MAXIMUM"}, [rgb[0], g.emit("math", {"op": "MAXIMUM"}, [rgb[1], rgb[2],
                           g.constant(0.0, "float")], ("float",))[0], g.constant(0.0, "float")], ("float",))[0]
    dim = g.emit("multiply", {}, [g.emit("multiply", {}, [weight, albedo], ("float",))[0], brightest],
                 ("float",))[0]
    layer = g.emit("one_minus", {}, [g.emit("saturate", {}, [dim], ("float",))[0]], ("float",))[0]
    reflectance = g.emit("math", {"op": "MAXIMUM"}, [dim, g.constant(1e-3, "float"), g.constant(0.0, "float")],
                         ("float",))[0]
    return row, weight, layer, reflectance
