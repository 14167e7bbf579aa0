"""Smooth glass: Cycles' Glass BSDF at roughness 0 (and Principled Transmission), a delta closure.

A hit on glass reflects about the shading normal with the exact dielectric Fresnel F (unpolarized, IOR η
inside over outside; total internal reflection where the refracted direction does not exist) or refracts
with probability 1 - F, so each direction is drawn with its own probability and the path's throughput only
takes the tint: reflection x ``glass_reflect``, refraction x ``glass_refract`` (no 1/η² radiance scaling, as
Cycles). Delta closures are not evaluated for light samples (next-event estimation, ReSTIR targets): a glass
hit's BSDF parameters are black for those, and light through glass arrives by the path's next vertices (its
emission seen along a delta ray takes MIS weight 1, ``DELTA_PDF``). Shadow rays are blocked by glass, as in
Cycles (caustics come from BSDF paths only).
"""
from __future__ import annotations

import numpy as np

from .bsdf import fresnel_exact
from .sampling import dot

DELTA_PDF = np.float32(1e15)  # "pdf" of a delta direction: power_heuristic(DELTA_PDF, any light pdf) = 1
GLASS_SALT = 0x2545F491       # decorrelates the glass pick from the Mix pick (both hash the same hit)


def sample_glass(wo: np.ndarray, n: np.ndarray, ng: np.ndarray, front: np.ndarray, ior: np.ndarray,
                 reflect_tint: np.ndarray, refract_tint: np.ndarray, u: np.ndarray):
    """Directions (3, k), weights (3, k) and validity (k,) of delta samples at k glass hits: ``wo`` (3, k) toward
    the viewer, ``n`` / ``ng`` (3, k) shading / geometric normals facing ``wo``, ``front`` (k,) True where the ray
    arrived from outside (against the outward geometric normal), ``ior`` (k,) the glass's IOR, ``u`` (k,)
    uniforms choosing reflection (u < F) or refraction. A sample is invalid where it would leave on the wrong
    side of the geometric surface (a shading-normal artefact)."""
    eta = np.where(front, ior, 1.0 / ior).astype(np.float32)          # η_t / η_i across the interface
    c = np.clip(dot(wo, n), 0.0, 1.0)
    sin2_t = (1.0 - c * c) / (eta * eta)
    tir = sin2_t >= 1.0
    cos_t = np.sqrt(np.maximum(0.0, 1.0 - sin2_t))
    # the exact dielectric Fresnel (its η² - 1 form holds for η < 1 too, wherever the refraction exists)
    fresnel = np.where(tir, 1.0, fresnel_exact(c, np.where(tir, 0.0, eta * eta - 1.0).astype(np.float32)))
    reflect = u < fresnel
    wr = 2.0 * c * n - wo
    wt = -wo / eta + (c / eta - cos_t) * n
    wi = np.where(reflect, wr, wt).astype(np.float32)
    wi /= np.maximum(np.sqrt(dot(wi, wi)), 1e-12)
    weight = np.where(reflect, reflect_tint, refract_tint).astype(np.float32)
    side = dot(wi, ng)
    valid = np.where(reflect, side > 0, side < 0) & np.isfinite(wi).all(axis=0)
    return wi, weight, valid
