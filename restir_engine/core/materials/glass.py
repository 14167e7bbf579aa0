"""Glass: Cycles' Glass BSDF (and Principled Transmission) as a dielectric interface, smooth or rough (GGX).

Smooth (roughness² below ROUGH_ALPHA_MIN, where Cycles also switches to a delta closure): a hit reflects about the
shading normal with the exact dielectric Fresnel F (unpolarized, IOR η inside over outside; total internal
reflection where the refracted direction does not exist) or refracts with probability 1 - F, so each direction is
drawn with its own probability and the path's throughput only takes the tint: reflection x ``glass_reflect``,
refraction x ``glass_refract`` (no 1/η² radiance scaling, as Cycles).

Rough (α = roughness², Cycles' multiscatter GGX glass): a microfacet normal h is drawn from D(h) cos θh about the
shading normal, then reflection or refraction about h with probability F(ωo·h) or 1 - F. The Walter et al. BSDF
(Cycles' microfacet eval, height-correlated Smith G) over that pdf leaves the weight
    tint · G(ωo, ωi) · (ωo·h) / (cos θo · cos θh) / E(α, cos θo, η)
where 1/E is Cycles' energy compensation of its multiscatter glass (E: the interface's directional albedo,
microfacet_tables GLASS_OUT / GLASS_IN), for reflection and refraction alike.

Glass is sampled, never evaluated for light samples (next-event estimation, ReSTIR targets): a glass hit's BSDF
parameters are black for those, and light through or off glass arrives by the path's next vertices (its emission
seen along a glass ray takes MIS weight 1, ``DELTA_PDF``). Unbiased for rough glass too, but small lights seen
through rough glass converge slower than in Cycles, which light-samples them. Shadow rays are blocked by glass, as
in Cycles (caustics come from BSDF paths only).
"""
from __future__ import annotations

import numpy as np

from ..sampling import dot, orthonormal_basis
from .bsdf import fresnel_exact, ggx_normals
from .microfacet_tables import glass_albedo_at, smith_lambda

DELTA_PDF = np.float32(1e15)  # "pdf" of a delta direction: power_heuristic(DELTA_PDF, any light pdf) = 1
GLASS_SALT = 0x2545F491       # decorrelates the glass pick from the Mix pick (both hash the same hit)
ROUGH_ALPHA_MIN = np.float32(np.sqrt(1e-7))  # Cycles: α_x α_y <= 1e-7 is a delta closure


def beckmann_normals(alpha: np.ndarray, u1: np.ndarray, u2: np.ndarray) -> np.ndarray:
    """Beckmann microfacet normals (3, k) drawn with density D(h) cos θh (solid angle): tan² θh = -α² ln(1 - u1),
    φ = 2π u2."""
    tan2 = -alpha * alpha * np.log(np.maximum(1.0 - u1, 1e-12))
    cos_t = 1.0 / np.sqrt(1.0 + tan2)
    sin_t = np.sqrt(np.maximum(0.0, 1.0 - cos_t * cos_t))
    phi = np.float32(2 * np.pi) * u2
    return np.stack([sin_t * np.cos(phi), sin_t * np.sin(phi), cos_t]).astype(np.float32)


def beckmann_lambda(alpha: np.ndarray, cos: np.ndarray) -> np.ndarray:
    """The Beckmann Smith Λ at cos θ, by the rational approximation Cycles uses (0 for a = 1/(α tan θ) ≥ 1.6)."""
    c2 = np.clip(cos * cos, 1e-12, 1.0)
    s = alpha * alpha * np.maximum(1.0 / c2 - 1.0, 0.0)         # α² tan² θ
    a = 1.0 / np.sqrt(np.maximum(s, 1e-30))
    lam = ((0.396 * a - 1.259) * a + 1.0) / ((2.181 * a + 3.535) * a)
    return np.where(s < 0.39, 0.0, lam).astype(np.float32)


def sample_glass(wo: np.ndarray, n: np.ndarray, ng: np.ndarray, front: np.ndarray, ior: np.ndarray,
                 reflect_tint: np.ndarray, refract_tint: np.ndarray, u: np.ndarray, alpha: np.ndarray | None = None,
                 u1: np.ndarray | None = None, u2: np.ndarray | None = None, multiscatter: np.ndarray | None = None,
                 fresnel_on: np.ndarray | None = None, beckmann: np.ndarray | None = None):
    """Directions (3, k), weights (3, k) and validity (k,) of samples at k glass hits: ``wo`` (3, k) toward
    the viewer, ``n`` / ``ng`` (3, k) shading / geometric normals facing ``wo``, ``front`` (k,) True where the ray
    arrived from outside (against the outward geometric normal), ``ior`` (k,) the glass's IOR, ``u`` (k,)
    uniforms choosing reflection (u < F) or refraction; ``alpha`` (k,) GGX α (None: all smooth) with ``u1``, ``u2``
    (k,) drawing the microfacet normal, ``multiscatter`` (k,) bool: energy compensated (else single-scattering
    GGX, Cycles' "GGX" distribution); ``fresnel_on`` (k,) bool (None: all True): False where the closure always
    refracts (the Refraction BSDF: no Fresnel weighting, total internal reflection absorbs). A sample is invalid
    where it would leave on the wrong side of the geometric surface (a shading-normal artefact) or, when rough, of
    the shading normal. ``beckmann`` (k,) bool (None: none): rough rows with Beckmann's normal distribution and
    Smith term instead of GGX's (single-scattering)."""
    eta = np.where(front, ior, 1.0 / ior).astype(np.float32)          # η_t / η_i across the interface
    mu = np.clip(dot(wo, n), 0.0, 1.0)
    rough = None if alpha is None else np.flatnonzero(alpha > ROUGH_ALPHA_MIN)
    h = n
    if rough is not None and rough.size:
        hl = ggx_normals(alpha[rough], u1[rough], u2[rough])
        beck = None if beckmann is None else np.flatnonzero(beckmann[rough])
        if beck is not None and beck.size:
            hl[:, beck] = beckmann_normals(alpha[rough][beck], u1[rough][beck], u2[rough][beck])
        hz = hl[2]
        nr = n[:, rough]
        t, b = orthonormal_basis(nr)
        h = n.copy()
        h[:, rough] = hl[0] * t + hl[1] * b + hl[2] * nr
    c = np.clip(dot(wo, h), 0.0, 1.0)
    sin2_t = (1.0 - c * c) / (eta * eta)
    tir = sin2_t >= 1.0
    cos_t = np.sqrt(np.maximum(0.0, 1.0 - sin2_t))
    # the exact dielectric Fresnel (its η² - 1 form holds for η < 1 too, wherever the refraction exists)
    fresnel = np.where(tir, 1.0, fresnel_exact(c, np.where(tir, 0.0, eta * eta - 1.0).astype(np.float32)))
    reflect = u < fresnel
    absorbed = None
    if fresnel_on is not None and not fresnel_on.all():
        off = ~fresnel_on
        absorbed = off & tir
        reflect = reflect & fresnel_on
    wr = 2.0 * c * h - wo
    wt = -wo / eta + (c / eta - cos_t) * h
    wi = np.where(reflect, wr, wt).astype(np.float32)
    wi /= np.maximum(np.sqrt(dot(wi, wi)), 1e-12)
    weight = np.where(reflect, reflect_tint, refract_tint).astype(np.float32)
    side = dot(wi, ng)
    valid = np.where(reflect, side > 0, side < 0) & np.isfinite(wi).all(axis=0)
    if absorbed is not None:
        valid &= ~absorbed
    if rough is not None and rough.size:
        # G(ωo, ωi) (ωo·h) / (cos θo cos θh) / E: the BSDF's value over the pdf of h and of the Fresnel choice
        a, m, ci = alpha[rough], mu[rough], dot(wi[:, rough], n[:, rough])
        lam_o, lam_i = smith_lambda(a, m), smith_lambda(a, np.abs(ci))
        if beck is not None and beck.size:
            lam_o[beck], lam_i[beck] = beckmann_lambda(a[beck], m[beck]), beckmann_lambda(a[beck], np.abs(ci[beck]))
        g = 1.0 / (1.0 + lam_o + lam_i)
        e = glass_albedo_at(a, m, eta[rough])
        if multiscatter is not None:
            e = np.where(multiscatter[rough], e, np.float32(1.0))
        w = g * c[rough] / np.maximum(m * hz * e, 1e-12)
        weight[:, rough] *= w.astype(np.float32)
        valid[rough] &= (np.where(reflect[rough], ci > 0, ci < 0)) & (c[rough] > 0) & (m > 0)
    return wi, weight, valid
