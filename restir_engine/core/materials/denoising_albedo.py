"""The albedo a denoiser is guided by (Cycles' Denoising Albedo pass): per first hit, the reflectance of the
Principled lobes toward the viewer (bsdf.py's lobes), scene-linear RGB in [0, 1]."""
from __future__ import annotations

import numpy as np


def denoising_albedo(surf) -> np.ndarray:
    """What a denoiser takes as the albedo of surfaces (3, n) (Cycles' Denoising Albedo, first hit): the reflectance
    of each lobe toward the viewer: the diffuse colour under its layer weight, and each specular lobe's
    (E + Fms (1 - E)) times its Fresnel averaged like the layer's (the dielectric's mix(f0, 1, S); a metal's
    Schlick value at the view angle). Clipped to [0, 1]."""
    p, v = surf.params, surf.view
    e = surf.albedo
    one_e = 1.0 - e
    out = v.kd * np.float32(np.pi)
    if v.sheen is not None:  # a sheen's kd holds R(μo)/Ē (sheen.py): its albedo is Color R(μo)
        from .sheen import mean_albedo
        out = np.array(out, np.float32, copy=True)
        out[:, v.sheen.rows] *= mean_albedo(v.sheen.roughness)
    if p.has_subsurface():  # camera hits keep the subsurface share as its own lobe: its weight is its albedo
        from .subsurface_lobe import lobe_weight
        rows = np.flatnonzero(p.sss.max(axis=0) > 0)
        out = np.array(out, np.float32, copy=True)
        out[:, rows] += lobe_weight(surf, rows)
    if p.has("metal"):
        c = np.clip(1.0 - surf.wo_l[2], 0.0, 1.0)
        out = out + (p.a_m + p.b_m * (c * c * c * c * c)) * (e + p.fm * one_e)
    if p.has("diel"):
        out = out + (p.a_d + p.c_d * (1.0 - p.f0r) * surf.layer) * (e + p.fd * one_e)
    return np.clip(out, 0.0, 1.0).astype(np.float32)
