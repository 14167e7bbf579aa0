"""The Principled BSDF's layers as node-program operations: how much of the light reaches the base under a Coat,
as Cycles weighs it (Blender 4.0+), and the Sheen's albedo toward the viewer.

Cycles puts the Coat on top of the base as a dielectric GGX lobe of weight w (Coat Weight) with the exact
dielectric Fresnel of the Coat IOR η, and scales everything under it by
  layer = saturate(1 - w A(α, cos θ, η))                   (A the coat's albedo toward the viewer: its Fresnel
                                                            averaged over the rough coat's reflections, the
                                                            dielectric layer's table: :func:`coat_albedo`)
  tint  = mix(1, Coat Tint^(1 / cos θ_t), w)               (Beer's law through a coat of unit thickness, tint the
                                                            transmittance at normal incidence; cos θ_t the angle
                                                            of the view refracted into the coat)
with θ the angle between the view and the coat normal. Both depend on the view only, not on the light.
The Sheen (Cycles' microfibre lobe) reflects R(μo, roughness) of uniform light toward a view at μo = cos θo
(core/materials/sheen.py): :func:`sheen_albedo`, which dims what lies under a Principled BSDF's sheen.
Floats are (n,) or 0-d, vectors and colours (3, n) or (3, 1).
"""
from __future__ import annotations

import numpy as np

from .. import microfacet_tables as tables
from ..microfacet_tables import ALPHA_MIN, layer_s
from ..params import fss_dielectric, multiscatter_fresnel
from .ops_math import _dot, f32

_F = np.float32


def sheen_albedo(attrs, params, roughness, normal):
    """The Sheen's albedo R(μo, roughness) (n,) toward the viewer, μo about the unit ``normal`` facing the viewer
    (core/materials/sheen.py)."""
    from ..sheen import albedo
    cos = np.clip(_dot(attrs.get("incoming"), f32(normal)), 0, 1)
    return albedo(f32(roughness), cos)


def coat_albedo(roughness, cos, eta):
    """The coat's directional albedo toward the viewer as Cycles estimates it for the layering (n,):
    (E + Fms (1 - E)) · mix(F0(η), 1, S(α, μ, η)), the same form as the Principled dielectric layer's (bsdf.py):
    E(α, μ) the GGX albedo, Fms the multiscatter Fresnel of the fitted average Fss(η), S the dielectric layer's
    table (α = roughness²); 0 for η = 1."""
    n = np.shape(cos)
    alpha = np.broadcast_to(np.maximum(np.clip(f32(roughness), 0, 1) ** 2, ALPHA_MIN), n).astype(np.float32)
    eta = np.broadcast_to(f32(eta), n).astype(np.float32)
    mu = np.clip(cos, 0, 1).astype(np.float32)
    f0 = ((eta - 1) / (eta + 1)) ** 2
    s = layer_s(alpha, mu, f0.astype(np.float32))
    e = tables.albedo(alpha, mu)
    fms = multiscatter_fresnel(fss_dielectric(eta), tables.average_albedo(alpha))
    return np.where(eta > 1, (e + fms * (1 - e)) * (f0 + (1 - f0) * s), _F(0)).astype(np.float32)


def coat_layer(attrs, params, weight, ior, tint, normal, roughness):
    """(layer (n,), tint factor (3, n), the coat's albedo (n,)) under a Coat of ``weight``, ``ior``, ``tint`` and
    ``roughness`` with unit ``normal`` facing the viewer (module docstring)."""
    w = np.maximum(f32(weight), _F(0))
    eta = np.maximum(f32(ior), _F(1))
    cos = np.clip(_dot(attrs.get("incoming"), f32(normal)), 0, 1)
    albedo = coat_albedo(roughness, cos, eta)
    layer = np.clip(1 - w * albedo, 0, 1).astype(np.float32)
    tint = np.maximum(f32(tint), _F(0))
    cos_t = np.sqrt(np.maximum(1 - (1 - cos * cos) / (eta * eta), _F(1e-12)))
    through = np.where(tint > 0, np.power(np.maximum(tint, _F(1e-30)), 1 / cos_t), _F(0))
    factor = (1 - w) + w * through
    return layer, np.broadcast_to(factor, (3, len(attrs))).astype(np.float32), albedo


OPERATIONS = {"coat_layer": coat_layer, "sheen_albedo": sheen_albedo}
#: reads the view: never folded into constants at export
READS_HITS = frozenset({"coat_layer", "sheen_albedo"})
