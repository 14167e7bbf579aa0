"""The Principled BSDF's Coat as Cycles layers it (Blender 4.0+), exported as two components of a Mix row: the coat
(a dielectric GGX lobe of the Coat Roughness and Coat IOR about the Coat Normal, weighted by Coat Weight) and the
base (the Principled BSDF without its coat, weighted by the coat's layering factor and coloured by the Coat Tint's
transmittance, both per hit from the view: core/materials/nodes/ops_layers.py). One component is picked per hit,
as for any Mix (core/materials/mix.py): unbiased, with the pick's variance where Cycles evaluates both."""
from __future__ import annotations

#: Cycles' closure weight below which a layer is left out
CUTOFF = 1e-5


def coat_set(node) -> bool:
    """Whether a Principled BSDF node may have a coat (Coat Weight linked, or above the cut-off)."""
    sock = node.inputs.get("Coat Weight") if node.type == "BSDF_PRINCIPLED" else None
    return sock is not None and (sock.is_linked or float(sock.default_value) > CUTOFF)


def coat_normal_socket(node):
    """The socket the coat's normal comes from: Coat Normal where linked, else the BSDF's Normal (Cycles' default)."""
    sock = node.inputs.get("Coat Normal")
    return sock if sock is not None and sock.is_linked else node.inputs.get("Normal")


def coat_factors(g, node):
    """Registers of compiler ``g``: (coat weight, the base's layering factor, the base's colour factor or None for a
    white Coat Tint, the coat's reflectance toward the viewer); None where the Coat Weight folds to the cut-off or
    below (no coat)."""
    inp = node.inputs
    weight = g.value(inp["Coat Weight"], "float")
    if weight.const is not None and weight.constant_value() <= CUTOFF:
        return None
    tint = g.value(inp["Coat Tint"], "color")
    normal_socket = coat_normal_socket(node)
    normal = g.value(normal_socket, "vector", default="normal") if normal_socket is not None else \
        g.attribute("normal", "vector")
    layer, factor, reflectance = g.emit("coat_layer", {}, [weight, g.value(inp["Coat IOR"], "float"), tint, normal,
                                                          g.value(inp["Coat Roughness"], "float")],
                                        ("float", "color", "float"))
    white = tint.const is not None and tint.constant_value() == (1.0, 1.0, 1.0)
    return weight, layer, None if white else factor, reflectance


def base_albedo(row: dict) -> float:
    """A rough estimate of how much a Principled row reflects (the luminance of its constant colours; a varying
    input counts as its neutral value): what the pick between coat and base weighs the base's share by."""
    lum = sum(w * float(c) for w, c in zip((0.2126, 0.7152, 0.0722), row.get("base_color", (0.8, 0.8, 0.8))))
    f0, metal = float(row.get("f0", 0.04)), float(row.get("metallic", 0.0))
    return (1 - metal) * (lum * (1 - f0) + f0) + metal * max(lum, 0.05)


def coat_row(registry, material, node) -> dict:
    """The coat lobe as a table row: black base, the exact dielectric Fresnel of the Coat IOR (clamped to 1 or more)
    at the Coat Roughness, energy-preserving GGX (Cycles always compensates the coat), about the coat's normal."""
    inp = node.inputs
    g, varying = registry._compiler(material), {}
    row = {"base_color": (0.0, 0.0, 0.0), "metallic": 0.0, "multiscatter": 1.0, "specular_tint": (1.0, 1.0, 1.0)}
    row["roughness"] = registry._param(material, g, inp["Coat Roughness"], "float", "roughness", varying)
    ior = g.emit("math", {"op": "MAXIMUM"}, [g.value(inp["Coat IOR"], "float"), g.constant(1.0, "float"),
                                                    g.constant(0.0, "float")], ("float",))[0]
    f0 = g.emit("principled_f0", {}, [ior, g.constant(0.5, "float")], ("float",))[0]
    if f0.const is not None:
        row["f0"] = f0.constant_value()
    else:
        varying["f0"] = f0
    registry._normal(material, node, row, g, varying, socket=coat_normal_socket(node))
    return registry._with_program(row, g, varying)
