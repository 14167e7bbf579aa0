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

Smooth glass is sampled only (a delta closure: its BSDF parameters are black for light samples, and the emission
its rays meet takes MIS weight 1, ``DELTA_PDF``). Rough glass is also evaluated for the path tracer's next-event
estimation (:func:`eval_rough`: f and the pdf with which :func:`sample_glass` draws a direction, on both sides of
the surface), and the emission its sampled rays meet is MIS-weighted by that pdf, as Cycles light-samples it. The
camera's glass chains (integrators/camera_paths.py) sample it only (their emission weight 1) and ReSTIR's targets
never see glass (their surfaces lie past the chains). Shadow rays are blocked by glass, as in Cycles (caustics come
from BSDF paths only).
"""
from __future__ import annotations

import numpy as np

from ..sampling import dot, orthonormal_basis
from .microfacet import fresnel_exact, ggx_normals
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


def _ggx_d(alpha: np.ndarray, cos_h: np.ndarray) -> np.ndarray:
    """GGX D(h) at cos θh (1/sr)."""
    a2 = alpha * alpha
    t = cos_h * cos_h * (a2 - 1.0) + 1.0
    return a2 / (np.float32(np.pi) * t * t)


def _beckmann_d(alpha: np.ndarray, cos_h: np.ndarray) -> np.ndarray:
    """Beckmann D(h) at cos θh (1/sr)."""
    c2 = np.maximum(cos_h * cos_h, 1e-12)
    return np.exp(-(1.0 - c2) / (c2 * alpha * alpha)) / (np.float32(np.pi) * alpha * alpha * c2 * c2)


def eval_glass(wo: np.ndarray, wi: np.ndarray, n: np.ndarray, ng: np.ndarray, front: np.ndarray, ior: np.ndarray,
               reflect_tint: np.ndarray, refract_tint: np.ndarray, alpha: np.ndarray, multiscatter: np.ndarray,
               fresnel_on: np.ndarray, beckmann: np.ndarray):
    """The rough glass of :func:`sample_glass` evaluated for light directions: f (3, k) (the BSDF, per steradian;
    the caller takes |cos θi|) and the solid-angle pdf (k,) with which :func:`sample_glass` draws ``wi`` (3, k),
    for k rough glass hits (arguments as there; ``alpha`` above ROUGH_ALPHA_MIN). f |cos θi| / pdf is the sample's
    weight there, so light samples and BSDF samples estimate the same lobe: reflection
    tint F D G / (4 cos θo E), refraction tint (1 - F) D G η² (ωo·h) |ωi·h| / (cos θo (ωo·h + η ωi·h)² E)
    (η = η_t / η_i; without Fresnel (the Refraction BSDF) no reflection and no 1 - F)."""
    eta = np.where(front, ior, 1.0 / ior).astype(np.float32)
    co = np.clip(dot(wo, n), 0.0, 1.0)
    ci = dot(wi, n)
    reflect = ci > 0
    hr = wo + wi
    ht = -(wo + eta * wi)
    h = np.where(reflect, hr, ht)
    h = h / np.maximum(np.sqrt(dot(h, h)), 1e-12)
    h = h * np.where(dot(h, n) < 0, np.float32(-1.0), np.float32(1.0))
    oh, ih, cos_h = dot(wo, h), dot(wi, h), dot(h, n)
    side = dot(wi, ng)
    valid = (co > 0) & (oh > 0) & (cos_h > 0) & np.where(reflect, (ih > 0) & (side > 0), (ih < 0) & (side < 0))
    d = np.where(beckmann, _beckmann_d(alpha, cos_h), _ggx_d(alpha, cos_h))
    lam_o = np.where(beckmann, beckmann_lambda(alpha, co), smith_lambda(alpha, co))
    lam_i = np.where(beckmann, beckmann_lambda(alpha, np.abs(ci)), smith_lambda(alpha, np.abs(ci)))
    g = 1.0 / (1.0 + lam_o + lam_i)
    c = np.clip(oh, 0.0, 1.0)
    sin2_t = (1.0 - c * c) / (eta * eta)
    tir = sin2_t >= 1.0
    fr = np.where(tir, 1.0, fresnel_exact(c, np.where(tir, 0.0, eta * eta - 1.0).astype(np.float32)))
    p_r = np.where(fresnel_on, fr, 0.0)
    p_t = np.where(fresnel_on, 1.0 - fr, np.where(tir, 0.0, 1.0))
    e = np.where(multiscatter, glass_albedo_at(alpha, co, eta), np.float32(1.0))
    den_t = oh + eta * ih
    jac_t = eta * eta * np.abs(ih) / np.maximum(den_t * den_t, 1e-12)
    pdf = np.where(reflect, p_r * d * cos_h / np.maximum(4.0 * oh, 1e-12), p_t * d * cos_h * jac_t)
    # f |cos θi| = weight x pdf, weight = tint G (ωo·h) / (cos θo cos θh E)
    w = g * c / np.maximum(co * cos_h * e, 1e-12)
    f_cos = w * pdf
    tint = np.where(reflect, reflect_tint, refract_tint)
    f = tint * (f_cos / np.maximum(np.abs(ci), 1e-6))
    ok = valid & np.isfinite(pdf) & (pdf > 0)
    return np.where(ok, f, 0.0).astype(np.float32), np.where(ok, pdf, 0.0).astype(np.float32)


def rough_rows(surf) -> np.ndarray:
    """The hits of ``surf`` (a Surface) on rough glass (indices), which light samples can reach."""
    if surf.glass is None:
        return np.zeros(0, np.intp)
    return np.flatnonzero(surf.glass & (surf.glass_alpha > ROUGH_ALPHA_MIN))


def eval_rough(surf, rows: np.ndarray, wi: np.ndarray):
    """:func:`eval_glass` at the rough glass hits ``rows`` of ``surf`` for world directions ``wi`` (3, k)."""
    def take(a):
        return np.take(a, rows, axis=-1)
    beck = surf.glass_beckmann[rows] if surf.glass_beckmann is not None else np.zeros(rows.size, bool)
    return eval_glass(take(surf.wo), wi, take(surf.ns), take(surf.ng), surf.glass_front[rows], surf.glass_ior[rows],
                      take(surf.glass_reflect), take(surf.glass_refract), surf.glass_alpha[rows],
                      surf.glass_ms[rows], surf.glass_fresnel[rows], beck)
