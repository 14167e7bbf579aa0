"""GGX microfacet primitives the BSDFs share: the Smith term's view factor, the exact dielectric Fresnel, the
half-vector terms of a direction pair and sampling of the normal distribution. Directions are (3, n) rows in the
local frame (z = the macro normal), unit length; float32 in place where the functions can."""
from __future__ import annotations

import numpy as np


def smith_view(alpha2: np.ndarray, c: np.ndarray) -> np.ndarray:
    """√(c² (1 - α²) + α²) (n,): c (1 + 2 Λ(c)) of the GGX Smith Λ at cos θ = c > 0 (float32)."""
    v = c * c
    v *= 1.0 - alpha2
    v += alpha2
    np.sqrt(v, out=v)
    return v


def fresnel_exact(c, eta2m1):
    """Unpolarized dielectric Fresnel at cos θ = c (> 0) for η² - 1 = ``eta2m1`` (≥ 0), float32 in place where
    it can."""
    g = c * c
    g += eta2m1
    np.sqrt(g, out=g)
    gpc = g + c
    gmc = np.subtract(g, c, out=g)
    np.maximum(gpc, np.float32(1e-12), out=gpc)     # c = 0 where glass sends its TIR rows here with η² - 1 = 0
    a = gmc / gpc
    b = c * gpc
    b -= 1.0
    den = np.multiply(c, gmc, out=gpc)
    den += 1.0
    b /= den
    b *= b
    b += 1.0
    a *= a
    a *= b
    a *= 0.5
    return a


def half_vector_terms(wdw: np.ndarray, co, ci, alpha2):
    """cos θh, ωo·h and the GGX D(h) of unit directions with ωo·ωi = ``wdw`` (overwritten: it becomes ωo·h),
    cos θo ``co`` and cos θi ``ci`` about the lobe's normal, without forming h: |ωo + ωi|² = 2 + 2 ωo·ωi,
    cos θh = (cos θo + cos θi)/|ωo + ωi|, ωo·h = (1 + ωo·ωi)/|ωo + ωi|. Arrays broadcast (the target's
    candidates x surfaces blocks); float32 in place where it can."""
    hinv = 2.0 + 2.0 * wdw
    np.maximum(hinv, np.float32(1e-24), out=hinv)
    np.sqrt(hinv, out=hinv)
    np.divide(np.float32(1.0), hinv, out=hinv)
    cos_h = (co + ci) * hinv
    np.clip(cos_h, 0.0, 1.0, out=cos_h)
    odh = wdw
    odh += 1.0
    odh *= hinv
    np.clip(odh, 1e-6, 1.0, out=odh)
    den = cos_h * cos_h
    den *= alpha2 - 1.0
    den += 1.0
    d = den * den
    d *= np.float32(np.pi)
    np.divide(alpha2, d, out=d)
    return cos_h, odh, d


def ggx_normals(alpha: np.ndarray, u1: np.ndarray, u2: np.ndarray) -> np.ndarray:
    """GGX microfacet normals (3, k) in the local frame (z = the macro normal) drawn with density D(h) cos θh
    (solid angle) from uniforms u1, u2 (k,): tan² θh = α² u1 / (1 - u1), φ = 2π u2."""
    tan2 = alpha * alpha * u1 / np.maximum(1.0 - u1, 1e-7)
    cos_t = 1.0 / np.sqrt(1.0 + tan2)
    sin_t = np.sqrt(np.maximum(0.0, 1.0 - cos_t * cos_t))
    phi = np.float32(2 * np.pi) * u2
    h = np.empty((3, len(cos_t)), np.float32)
    h[0] = sin_t * np.cos(phi)
    h[1] = sin_t * np.sin(phi)
    h[2] = cos_t
    return h
