"""Lambert diffuse + GGX specular BSDF, vectorized.

All directions are (3, n) rows (x, y, z) in the local shading frame (z = shading normal), unit length,
``wo`` towards the viewer, ``wi`` towards the light; colours are (3, n) rows (R, G, B). ``eval`` returns
f (3, n) without the cosine; pdfs are in solid-angle measure.

Model (an approximation of the Principled BSDF):
  diffuse  = base·(1-metallic)/π · (1 - F_d(cos_o))      F_d: Schlick with the dielectric f0
  specular = D·G·F / (4 cos_i cos_o)   GGX D, height-correlated Smith G, Schlick F with
             f0 = mix(f0_dielectric, base, metallic), alpha = roughness²
The (1 - F_d) factor keeps reflectance ≤ 1 (energy-sensible). The specular lobe is scaled by
1 + f0 (1 - E(μo, α)) / E(μo, α), E the directional albedo of single-scattering GGX with F = 1
(Turquin 2019 energy compensation), standing in for the energy Cycles' multiscatter GGX keeps at high
roughness: a white metal then reflects all the light it receives. Lobes are sampled by one-sample MIS:
cosine hemisphere for the diffuse lobe, the GGX normal distribution for the specular one.
"""
from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from .sampling import cosine_hemisphere, dot

ALPHA_MIN = 1e-3
INV_PI = np.float32(1.0 / np.pi)


def luminance(rgb: np.ndarray) -> np.ndarray:
    """Rec. 709 luminance of scene-linear RGB in the last axis (..., 3)."""
    return np.float32(0.2126) * rgb[..., 0] + np.float32(0.7152) * rgb[..., 1] + np.float32(0.0722) * rgb[..., 2]


def luminance_rows(rgb: np.ndarray) -> np.ndarray:
    """Rec. 709 luminance of scene-linear RGB as (3, ...) rows."""
    return np.float32(0.2126) * rgb[0] + np.float32(0.7152) * rgb[1] + np.float32(0.0722) * rgb[2]


@dataclass
class SurfaceParams:
    """Per-hit (or per-material) BSDF parameters: diffuse (3, n), f0 (3, n) (RGB rows), f0_dielectric (n,),
    alpha (n,), p_spec (n,) probability of sampling the specular lobe, spec_on (n,) 1 where a specular
    lobe exists (0 for Diffuse BSDF)."""

    diffuse: np.ndarray
    f0: np.ndarray
    f0_dielectric: np.ndarray
    alpha: np.ndarray
    p_spec: np.ndarray
    spec_on: np.ndarray

    def take(self, idx) -> "SurfaceParams":
        """Parameters of entries ``idx`` (index array or slice)."""
        if isinstance(idx, slice):
            return SurfaceParams(self.diffuse[:, idx], self.f0[:, idx], self.f0_dielectric[idx], self.alpha[idx],
                                 self.p_spec[idx], self.spec_on[idx])
        return SurfaceParams(np.take(self.diffuse, idx, axis=1), np.take(self.f0, idx, axis=1),
                             self.f0_dielectric[idx], self.alpha[idx], self.p_spec[idx], self.spec_on[idx])

    def assign(self, idx, other: "SurfaceParams") -> None:
        """self[idx] = other (every field)."""
        self.diffuse[:, idx] = other.diffuse
        self.f0[:, idx] = other.f0
        for name in ("f0_dielectric", "alpha", "p_spec", "spec_on"):
            getattr(self, name)[idx] = getattr(other, name)

    @staticmethod
    def from_material(base: np.ndarray, metallic: np.ndarray, roughness: np.ndarray, f0_d: np.ndarray):
        """From base colours (m, 3) (scene-linear RGB, as the material table stores them), metallic,
        roughness and the dielectric f0 (m,)."""
        base = np.asarray(base, np.float32).T
        m = np.clip(metallic, 0, 1)
        f0 = (f0_d * (1 - m) + base * m).astype(np.float32)
        diffuse = (base * (1 - m)).astype(np.float32)
        alpha = np.maximum(np.clip(roughness, 0, 1) ** 2, ALPHA_MIN).astype(np.float32)
        ws = luminance_rows(f0)
        wd = luminance_rows(diffuse) * (1 - f0_d)
        tot = ws + wd
        p = np.where(tot > 0, ws / np.maximum(tot, 1e-12), 0.0)
        both = (ws > 0) & (wd > 0)
        p = np.where(both, np.clip(p, 0.1, 0.9), p).astype(np.float32)
        spec_on = (f0.max(axis=0) > 0).astype(np.float32)
        return SurfaceParams(diffuse, f0, f0_d.astype(np.float32), alpha, p, spec_on)


def schlick(f0, cos):
    c = np.clip(1.0 - cos, 0.0, 1.0)
    c5 = (c * c) * (c * c) * c
    return f0 + (1.0 - f0) * c5


_ALBEDO_TABLE = None
_TABLE_N = 32


TABLE_FILE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "ggx_albedo.npy")


def ggx_albedo_table() -> np.ndarray:
    """E[α index, μ index]: directional albedo of single-scattering GGX (F = 1, height-correlated Smith)
    on a 32 x 32 grid of α in [ALPHA_MIN, 1] and μo in [1/64, 1]. Read from core/data/ggx_albedo.npy
    (written by scripts/make_ggx_table.py from :func:`compute_ggx_albedo_table`; computed here if missing)."""
    global _ALBEDO_TABLE
    if _ALBEDO_TABLE is None:
        try:
            table = np.load(TABLE_FILE)
        except OSError:
            table = compute_ggx_albedo_table()
        _ALBEDO_TABLE = table.astype(np.float32)
    return _ALBEDO_TABLE


def compute_ggx_albedo_table() -> np.ndarray:
    """The table of :func:`ggx_albedo_table` by stratified NDF sampling (64 x 64 strata per entry; about a
    second)."""
    n = _TABLE_N
    alphas = np.linspace(ALPHA_MIN, 1.0, n)
    mus = np.linspace(1.0 / 64, 1.0, n)
    k = 64
    u1 = ((np.arange(k) + 0.5) / k)[:, None].repeat(k, 1).ravel()
    u2 = ((np.arange(k) + 0.5) / k)[None, :].repeat(k, 0).ravel()
    table = np.empty((n, n))
    for i, a in enumerate(alphas):  # loop over table rows, vectorized over μ and strata
        tan2 = a * a * u1 / np.maximum(1 - u1, 1e-9)
        ch = 1 / np.sqrt(1 + tan2)
        sh = np.sqrt(np.maximum(0, 1 - ch * ch))
        h = np.stack([sh * np.cos(2 * np.pi * u2), sh * np.sin(2 * np.pi * u2), ch], axis=1)
        mu = mus[:, None]
        wo = np.stack([np.sqrt(1 - mu * mu), np.zeros_like(mu), mu], axis=-1)  # (n, 1, 3)
        odh = (wo * h[None]).sum(-1)
        wi_z = 2 * odh * h[None, :, 2] - mu
        g = 1 / (1 + smith_lambda(a, np.broadcast_to(mu, wi_z.shape)) + smith_lambda(a, np.maximum(wi_z, 1e-6)))
        wgt = np.where((wi_z > 0) & (odh > 0), g * odh / (mu * h[None, :, 2]), 0.0)
        table[i] = wgt.mean(axis=1)
    return np.clip(table, 1e-3, 1.0).astype(np.float32)


def ggx_albedo(alpha: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """Bilinear lookup of :func:`ggx_albedo_table` at (α, μo)."""
    t = ggx_albedo_table()
    n = _TABLE_N
    x = np.clip((alpha - ALPHA_MIN) / (1.0 - ALPHA_MIN) * (n - 1), 0, n - 1)
    y = np.clip((mu - 1.0 / 64) / (1.0 - 1.0 / 64) * (n - 1), 0, n - 1)
    x0 = np.minimum(x.astype(np.int64), n - 2)
    y0 = np.minimum(y.astype(np.int64), n - 2)
    fx, fy = (x - x0).astype(np.float32), (y - y0).astype(np.float32)
    return ((t[x0, y0] * (1 - fy) + t[x0, y0 + 1] * fy) * (1 - fx)
            + (t[x0 + 1, y0] * (1 - fy) + t[x0 + 1, y0 + 1] * fy) * fx)


def ggx_albedo_rows(alpha: np.ndarray) -> np.ndarray:
    """The table interpolated at fixed roughnesses α (m,) -> (m, 32) rows over μo (materials' α is constant,
    so a hit's albedo is then one linear interpolation in μo: :func:`ggx_albedo_at`)."""
    t = ggx_albedo_table()
    n = _TABLE_N
    x = np.clip((np.asarray(alpha, np.float32) - ALPHA_MIN) / (1.0 - ALPHA_MIN) * (n - 1), 0, n - 1)
    x0 = np.minimum(x.astype(np.int64), n - 2)
    fx = (x - x0).astype(np.float32)[:, None]
    return (t[x0] * (1 - fx) + t[x0 + 1] * fx).astype(np.float32)


def ggx_albedo_at(rows: np.ndarray, index: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """E(μo) (n,) from rows of :func:`ggx_albedo_rows` (row ``index`` per point): equals :func:`ggx_albedo`
    at that row's α to float32 rounding."""
    n = _TABLE_N
    y = np.clip((mu - np.float32(1.0 / 64)) * np.float32((n - 1) / (1.0 - 1.0 / 64)), 0, n - 1)
    y0 = np.minimum(y.astype(np.intp), n - 2)
    fy = y - y0
    k = index * n + y0
    flat = rows.reshape(-1)
    return flat[k] * (1 - fy) + flat[k + 1] * fy


def smith_lambda(alpha, cos):
    c2 = np.clip(cos * cos, 1e-12, 1.0)
    tan2 = (1.0 - c2) / c2
    return 0.5 * (np.sqrt(1.0 + alpha * alpha * tan2) - 1.0)


def view_albedo(p: SurfaceParams, wo: np.ndarray) -> np.ndarray:
    """GGX directional albedo E(μo, α) (n,) of the view directions: depends on wo only, so callers that
    evaluate many wi for the same wo compute it once and pass it to :func:`eval_bsdf`."""
    return ggx_albedo(p.alpha, np.clip(wo[2], 0, 1))


@dataclass
class ViewTerms:
    """The factors of f and its pdf that depend on the view direction only, per surface (n): computed once
    and reused by every wi evaluated there (next-event estimation, BSDF sampling, shading).
    kd (3, n) = diffuse (1 - F_d(cos θ_o)) / π; spec_a, spec_b (3, n) = f0 · c, (1 - f0) · c with c the
    energy compensation 1 + f0 (1 - E)/E (so the specular lobe is D G / (4 cos θ_o cos θ_i) · (spec_a + c⁵
    spec_b), c⁵ = (1 - ωo·h)⁵); alpha, alpha2, lam_o = Λ(ωo), co = cos θ_o, spec_on, p_spec (n,)."""

    kd: np.ndarray
    spec_a: np.ndarray
    spec_b: np.ndarray
    alpha: np.ndarray
    alpha2: np.ndarray
    lam_o: np.ndarray
    co: np.ndarray
    spec_on: np.ndarray
    p_spec: np.ndarray
    glossy: bool = True  # False: no surface has a specular lobe (Diffuse BSDFs only): Lambert alone

    @staticmethod
    def of(p: SurfaceParams, wo: np.ndarray, albedo: np.ndarray | None = None) -> "ViewTerms":
        co = wo[2]
        # a lobe with f0 = 0 does not exist (Diffuse BSDF): no Fresnel split, no grazing specular
        fd = np.where(p.f0_dielectric > 0, 1.0 - schlick(p.f0_dielectric, co), np.float32(1.0))
        e = view_albedo(p, wo) if albedo is None else albedo
        comp = 1.0 + p.f0 * ((1.0 - e) / e)
        return ViewTerms(p.diffuse * (fd * INV_PI), p.f0 * comp, (1.0 - p.f0) * comp, p.alpha,
                         p.alpha * p.alpha, smith_lambda(p.alpha, co), co, p.spec_on, p.p_spec,
                         bool((p.spec_on > 0).any() or (p.p_spec > 0).any()))


def view_terms(surf) -> ViewTerms:
    """The view terms of surfaces: ``surf.view`` when they carry them (surface.Surface computes them once),
    else computed from ``params``, ``wo_l`` and ``albedo`` (if given)."""
    v = getattr(surf, "view", None)
    return v if v is not None else ViewTerms.of(surf.params, surf.wo_l, getattr(surf, "albedo", None))


def eval_view(v: ViewTerms, wo: np.ndarray, wi: np.ndarray):
    """f (3, n) and pdf (n,) (solid angle) of unit directions wi (3, n) at surfaces with view terms ``v``. The half
    vector h = (wo + wi)/|wo + wi| enters only through cos θ_h = (cos θ_o + cos θ_i)/|wo + wi| and
    wo·h = (1 + wo·wi)/|wo + wi|, with |wo + wi|² = 2 + 2 wo·wi."""
    co = v.co
    ci = wi[2]
    valid = (co > 0) & (ci > 0)
    if not v.glossy:
        pdf = np.maximum(ci, np.float32(0.0)) * INV_PI * valid
        return (v.kd * valid).astype(np.float32, copy=False), pdf.astype(np.float32, copy=False)
    wdw = dot(wo, wi)
    hinv = 1.0 / np.sqrt(np.maximum(2.0 + 2.0 * wdw, np.float32(1e-24)))
    cos_h = np.clip((co + ci) * hinv, 0, 1)
    odh = np.clip((1.0 + wdw) * hinv, 1e-6, 1.0)
    den = cos_h * cos_h * (v.alpha2 - 1.0) + 1.0
    d = v.alpha2 / (np.float32(np.pi) * den * den)
    g = 1.0 / (1.0 + v.lam_o + smith_lambda(v.alpha, ci))
    c = np.clip(1.0 - odh, 0.0, 1.0)
    c5 = (c * c) * (c * c) * c
    s = v.spec_on * d * g / np.maximum(4.0 * co * ci, np.float32(1e-12))
    f = v.kd + s * v.spec_a + (s * c5) * v.spec_b
    f *= valid
    pdf = (1 - v.p_spec) * np.maximum(ci, 0) * INV_PI + v.p_spec * (d * cos_h / (4.0 * odh))
    pdf *= valid
    return f.astype(np.float32, copy=False), pdf.astype(np.float32, copy=False)


def eval_bsdf(p: SurfaceParams, wo: np.ndarray, wi: np.ndarray, albedo: np.ndarray | None = None):
    """f (3, n) and pdf (n,) of sampling wi given wo, both unit (3, n) vectors (``albedo``: :func:`view_albedo`, if
    known). For many wi at the same surfaces build :class:`ViewTerms` once and call :func:`eval_view`."""
    return eval_view(ViewTerms.of(p, wo, albedo), wo, wi)


def sample_bsdf(p: SurfaceParams, wo: np.ndarray, u_lobe: np.ndarray, u1: np.ndarray, u2: np.ndarray,
                albedo: np.ndarray | None = None, view: ViewTerms | None = None):
    """Sample wi; returns wi (3, n), f (3, n), pdf (n,) (the mixture pdf, so MIS-ready). ``albedo``: see
    :func:`eval_bsdf`; ``view``: the surfaces' :class:`ViewTerms` if known."""
    spec = np.flatnonzero(u_lobe < p.p_spec)
    wi = cosine_hemisphere(u1, u2)
    if spec.size:
        a = p.alpha[spec]
        uu1, uu2 = u1[spec], u2[spec]
        tan2 = a * a * uu1 / np.maximum(1.0 - uu1, 1e-7)
        cos_t = 1.0 / np.sqrt(1.0 + tan2)
        sin_t = np.sqrt(np.maximum(0.0, 1.0 - cos_t * cos_t))
        phi = 2 * np.pi * uu2
        h = np.empty((3, spec.size), np.float32)
        h[0] = sin_t * np.cos(phi)
        h[1] = sin_t * np.sin(phi)
        h[2] = cos_t
        o = np.take(wo, spec, axis=1)
        wi[:, spec] = 2.0 * dot(o, h) * h - o
    f, pdf = eval_view(ViewTerms.of(p, wo, albedo) if view is None else view, wo, wi)
    ok = (pdf > 0) & (wi[2] > 0)
    f *= ok
    pdf *= ok
    return wi, f, pdf
