"""The Sheen BSDF (velvet, glTF's sheen), approximated by a Lambertian of its average reflectance."""
from __future__ import annotations

import numpy as np

#: The Sheen BSDF's albedo under a uniform white world, averaged over view directions with weight cos θ (the lobe's
#: share of the light it receives), at roughness SHEEN_ROUGHNESS, measured from Cycles (Blender 5.2, one bounce)
SHEEN_ROUGHNESS = (0.0, 0.1, 0.3, 0.5, 0.75, 1.0)
SHEEN_ALBEDO = {"MICROFIBER": (0.0, 0.00003, 0.0178, 0.0967, 0.260, 0.434),
                "ASHIKHMIN": (0.0, 0.0006, 0.0499, 0.156, 0.304, 0.434)}


def sheen_row(registry, material, node) -> dict:
    """The row of a Sheen BSDF ``node``: a Lambertian of its Color times the lobe's albedo averaged over the
    hemisphere (cosine-weighted, by roughness: :data:`SHEEN_ALBEDO`; the right amount of light, spread evenly instead
    of toward grazing angles), named in a warning. ``registry``: the MaterialRegistry."""
    registry._warn(material, f"'{node.name}' (Sheen BSDF) is approximated by a diffuse of its average reflectance")
    rough = float(np.clip(registry._float_input(material, node.inputs["Roughness"]), 0, 1))
    table = SHEEN_ALBEDO.get(getattr(node, "distribution", "MICROFIBER"), SHEEN_ALBEDO["MICROFIBER"])
    albedo = float(np.interp(rough, SHEEN_ROUGHNESS, table))
    g, varying = registry._compiler(material), {}
    colour = g.emit("scale", {}, [g.value(node.inputs["Color"], "color"), g.constant(albedo, "float")],
                    ("color",))[0]
    row = {"f0": 0.0, "metallic": 0.0, "base_color": (1.0, 1.0, 1.0)}
    if colour.const is not None:
        row["base_color"] = colour.constant_value()
    else:
        varying["base_color"] = colour
    return registry._with_program(row, g, varying)
