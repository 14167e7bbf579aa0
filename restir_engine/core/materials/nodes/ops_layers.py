"""The Principled BSDF's layers as node-program operations: how much of the light reaches the base under a Coat,
as Cycles weighs it (Blender 4.0+).

Cycles puts the Coat on top of the base as a dielectric GGX lobe of weight w (Coat Weight) with the exact
dielectric Fresnel of the Coat IOR η, and scales everything under it by
  layer = saturate(1 - w F(cos θ, η))                      (the coat's albedo toward the viewer, the surface taken
                                                            as smooth: F at the angle to the coat normal)
  tint  = mix(1, Coat Tint^(1 / cos θ_t), w)               (Beer's law through a coat of unit thickness, tint the
                                                            transmittance at normal incidence; cos θ_t the angle
                                                            of the view refracted into the coat)
with θ the angle between the view and the coat normal. Both depend on the view only, not on the light.
Floats are (n,) or 0-d, vectors and colours (3, n) or (3, 1).
"""
from __future__ import annotations

import numpy as np

from .ops_math import _dot, f32
from .ops_texture import _fresnel_dielectric

_F = np.float32


def coat_layer(attrs, params, weight, ior, tint, normal):
    """(layer (n,), tint factor (3, n), the coat's reflectance F (n,)) under a Coat of ``weight``, ``ior`` and
    ``tint`` with unit ``normal`` facing the viewer (module docstring)."""
    w = np.maximum(f32(weight), _F(0))
    eta = np.maximum(f32(ior), _F(1))
    cos = np.clip(_dot(attrs.get("incoming"), f32(normal)), 0, 1)
    fresnel = _fresnel_dielectric(cos, eta)
    layer = np.clip(1 - w * fresnel, 0, 1).astype(np.float32)
    tint = np.maximum(f32(tint), _F(0))
    cos_t = np.sqrt(np.maximum(1 - (1 - cos * cos) / (eta * eta), _F(1e-12)))
    through = np.where(tint > 0, np.power(np.maximum(tint, _F(1e-30)), 1 / cos_t), _F(0))
    factor = (1 - w) + w * through
    return layer, np.broadcast_to(factor, (3, len(attrs))).astype(np.float32), fresnel


OPERATIONS = {"coat_layer": coat_layer}
#: reads the view: never folded into constants at export
READS_HITS = frozenset({"coat_layer"})
