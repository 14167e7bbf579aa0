"""Precomputed tables of the GGX microfacet lobe, the data behind Cycles-style multiscatter energy compensation
and Principled layering (our own tables: ``scripts/make_ggx_tables.py`` writes ``core/data/ggx_tables.npz``
from :func:`compute_tables`; computed on first use if the file is missing).

Axes (index i of n entries sits at the grid value, lookups interpolate linearly between entries):
  α  = GGX alpha (roughness²), ALPHAS: 32 entries from ALPHA_MIN to 1
  μ  = cos θ of the view direction, MUS: 32 entries from 1/64 to 1 (clamped outside)
  z  = sqrt((η - 1)/(η + 1)) of the dielectric's relative IOR η (so F0 = z⁴), ZS: 16 entries from 0 to 0.99

Tables (all for height-correlated Smith GGX, single scattering, no cosine-weighted Fresnel unless stated):
  E[α, μ]       directional albedo with F = 1
  E_avg[α]      its cosine-weighted hemispherical average ∫ 2μ E(μ) dμ
  S[α, μ, z]    the exact dielectric Fresnel's interpolation factor s = (F(ωo·h, η) - F0)/(1 - F0) averaged over
                the reflected light: ∫ s f_ss cos / ∫ f_ss cos. The specular layer of a Principled BSDF with
                normal-incidence reflectance f0 (tinted) then reflects E · mix(f0, 1, S) (single scattering).
  GLASS_OUT[α, μ, z], GLASS_IN[α, μ, z]
                directional albedo of a rough dielectric interface (GGX glass: reflection weighted by the exact
                Fresnel F(ωo·h), refraction by 1 - F, total internal reflection included), entered from the optically
                thinner side (relative IOR η = η(z) > 1) and from the denser side (1/η); Cycles scales its
                multiscatter glass by 1/E (core/materials/glass.py).
"""
from __future__ import annotations

import os

import numpy as np

ALPHA_MIN = 1e-3
N_ALPHA, N_MU, N_Z = 32, 32, 16
ALPHAS = np.linspace(ALPHA_MIN, 1.0, N_ALPHA)
MUS = np.linspace(1.0 / 64, 1.0, N_MU)
ZS = np.linspace(0.0, 0.99, N_Z)
TABLE_FILE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "ggx_tables.npz")
STRATA = 64  # NDF samples per entry: STRATA² stratified

_TABLES: dict | None = None


def fresnel_dielectric(c, eta):
    """Unpolarized Fresnel reflectance of a dielectric interface of relative IOR ``eta`` (≥ 1) at cos θ = ``c``
    (arrays broadcasting; 1 on total internal reflection)."""
    g2 = eta * eta - 1.0 + c * c
    g = np.sqrt(np.maximum(g2, 0.0))
    a = (g - c) / np.maximum(g + c, 1e-12)
    b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0)
    return np.where(g2 > 0, 0.5 * a * a * (1.0 + b * b), 1.0)


def eta_of_z(z):
    """η from the table's IOR coordinate z (F0 = z⁴)."""
    r = np.minimum(np.asarray(z, np.float64) ** 2, 0.9999)
    return (1.0 + r) / (1.0 - r)


def z_of_f0(f0):
    """The IOR coordinate of a normal-incidence reflectance."""
    return np.sqrt(np.sqrt(np.clip(f0, 0.0, 1.0)))


def smith_lambda(alpha, cos):
    c2 = np.clip(cos * cos, 1e-12, 1.0)
    return 0.5 * (np.sqrt(1.0 + alpha * alpha * (1.0 - c2) / c2) - 1.0)


def compute_tables(strata: int = STRATA) -> dict:
    """E, E_avg and S by stratified sampling of the GGX normal distribution (strata² samples per entry, shared by
    all entries of a row; a few seconds). E_avg integrates E over 64 midpoints in μ."""
    u = (np.arange(strata) + 0.5) / strata
    u1 = np.repeat(u, strata)
    u2 = np.tile(u, strata)
    eta = eta_of_z(ZS)                                    # (nz,)
    f0 = ((eta - 1) / (eta + 1)) ** 2
    mu_avg = (np.arange(64) + 0.5) / 64
    e_tab = np.empty((N_ALPHA, N_MU))
    s_tab = np.empty((N_ALPHA, N_MU, N_Z))
    e_avg = np.empty(N_ALPHA)
    for i, a in enumerate(ALPHAS):  # one table row at a time, vectorized over μ, z and the samples
        tan2 = a * a * u1 / np.maximum(1 - u1, 1e-12)
        ch = 1 / np.sqrt(1 + tan2)
        sh = np.sqrt(np.maximum(0, 1 - ch * ch))
        hx, hz = sh * np.cos(2 * np.pi * u2), ch

        def weights(mus):
            mu = mus[:, None]
            odh = np.sqrt(1 - mu * mu) * hx[None] + mu * hz[None]   # wo in the xz plane
            wi_z = 2 * odh * hz[None] - mu
            g = 1 / (1 + smith_lambda(a, np.broadcast_to(mu, wi_z.shape)) + smith_lambda(a, np.maximum(wi_z, 1e-9)))
            # f_ss cos / pdf_ndf with pdf_ndf = D cos θh / (4 ωo·h): G ωo·h / (μ cos θh)
            return np.where((wi_z > 0) & (odh > 0), g * odh / (mu * hz[None]), 0.0), np.clip(odh, 0, 1)

        w, odh = weights(MUS)
        e_tab[i] = w.mean(axis=1)
        fr = fresnel_dielectric(odh[..., None], eta)                   # (nμ, samples, nz)
        s = np.clip((fr - f0) / np.maximum(1 - f0, 1e-12), 0, 1)
        s_tab[i] = (s * w[..., None]).mean(axis=1) / np.maximum(e_tab[i][:, None], 1e-12)
        wa, _ = weights(mu_avg)
        e_avg[i] = (2 * mu_avg * wa.mean(axis=1)).mean()
    glass = {side: np.empty((N_ALPHA, N_MU, N_Z)) for side in ("GLASS_OUT", "GLASS_IN")}
    for i, a in enumerate(ALPHAS):
        for side, rel in (("GLASS_OUT", eta), ("GLASS_IN", 1.0 / eta)):
            glass[side][i] = glass_albedo(a, MUS, rel, u1, u2)
    return {"E": np.clip(e_tab, 1e-3, 1.0).astype(np.float32), "E_avg": np.clip(e_avg, 1e-3, 1.0).astype(np.float32),
            "S": np.clip(s_tab, 0.0, 1.0).astype(np.float32),
            **{k: np.clip(v, 1e-3, 1.0).astype(np.float32) for k, v in glass.items()}}


def glass_albedo(alpha: float, mus: np.ndarray, eta: np.ndarray, u1: np.ndarray, u2: np.ndarray) -> np.ndarray:
    """(len(mus), len(eta)) directional albedo of a GGX dielectric interface of roughness ``alpha`` and relative IOR
    ``eta`` (transmitted side over incident side) seen at cos θ = ``mus``: the mean over normals h drawn from
    D(h) cos θh (from the uniforms u1, u2) of (F · G(ωo, ωr) + (1 - F) · G(ωo, ωt)) ωo·h / (μ cos θh), a reflection
    or refraction counting only where it leaves on its own side."""
    tan2 = alpha * alpha * u1 / np.maximum(1 - u1, 1e-12)
    hz = 1 / np.sqrt(1 + tan2)
    hx = np.sqrt(np.maximum(0, 1 - hz * hz)) * np.cos(2 * np.pi * u2)
    mu = mus[:, None, None]
    c = np.sqrt(1 - mu * mu) * hx[None, :, None] + mu * hz[None, :, None]          # ωo·h (nμ, samples, 1)
    e = np.asarray(eta, np.float64)[None, None, :]
    fr = fresnel_dielectric(np.clip(c, 0, 1), e)  # its η² - 1 + c² form is 1 on total internal reflection
    hz3 = hz[None, :, None]
    lam_o = smith_lambda(alpha, np.broadcast_to(mu, c.shape))
    r_z = 2 * c * hz3 - mu                                                          # reflected ωr·n
    sin2_t = (1 - c * c) / (e * e)
    cos_t = np.sqrt(np.maximum(0, 1 - sin2_t))
    t_z = -mu / e + (c / e - cos_t) * hz3                                           # refracted ωt·n
    g_r = 1 / (1 + lam_o + smith_lambda(alpha, np.maximum(r_z, 1e-9)))
    g_t = 1 / (1 + lam_o + smith_lambda(alpha, np.maximum(-t_z, 1e-9)))
    w = c / (mu * hz3)
    val = np.where(r_z > 0, fr * g_r, 0.0) + np.where((t_z < 0) & (sin2_t < 1), (1 - fr) * g_t, 0.0)
    return np.where(c > 0, val * w, 0.0).mean(axis=1)



def tables() -> dict:
    """The tables (read from :data:`TABLE_FILE` once)."""
    global _TABLES
    if _TABLES is None:
        try:
            with np.load(TABLE_FILE) as data:
                _TABLES = {k: data[k].astype(np.float32) for k in ("E", "E_avg", "S", "GLASS_OUT", "GLASS_IN")}
        except (OSError, KeyError):
            _TABLES = compute_tables()
    return _TABLES


def _axis(values, grid):
    """Index i0 (clamped so i0 + 1 exists) and weight of ``values`` on a uniform ``grid``."""
    n = len(grid)
    x = np.clip((np.asarray(values, np.float32) - grid[0]) * np.float32((n - 1) / (grid[-1] - grid[0])), 0, n - 1)
    i0 = np.minimum(x.astype(np.intp), n - 2)
    return i0, (x - i0).astype(np.float32)


def albedo(alpha, mu):
    """E(α, μ), bilinear."""
    t = tables()["E"]
    i, fi = _axis(alpha, ALPHAS)
    j, fj = _axis(mu, MUS)
    return (t[i, j] * (1 - fj) + t[i, j + 1] * fj) * (1 - fi) + (t[i + 1, j] * (1 - fj) + t[i + 1, j + 1] * fj) * fi


def average_albedo(alpha):
    """E_avg(α), linear."""
    t = tables()["E_avg"]
    i, fi = _axis(alpha, ALPHAS)
    return t[i] * (1 - fi) + t[i + 1] * fi


def glass_albedo_at(alpha, mu, eta):
    """The rough dielectric's directional albedo (GLASS_OUT where the relative IOR ``eta`` >= 1, else GLASS_IN at
    1/eta), trilinear in (α, μ, z); arrays of one shape."""
    eta = np.asarray(eta, np.float32)
    inside = eta < 1
    e = np.where(inside, 1.0 / np.maximum(eta, 1e-6), eta)
    z = np.sqrt(np.clip((e - 1) / (e + 1), 0.0, 1.0))
    return np.where(inside, _trilinear(tables()["GLASS_IN"], alpha, mu, z),
                    _trilinear(tables()["GLASS_OUT"], alpha, mu, z)).astype(np.float32)


def layer_s(alpha, mu, f0):
    """S(α, μ, z(f0)), trilinear (arrays of one shape)."""
    return _trilinear(tables()["S"], alpha, mu, z_of_f0(f0))


def _trilinear(t: np.ndarray, alpha, mu, z) -> np.ndarray:
    """A (α, μ, z) table at points of one shape, trilinear."""
    i, fi = _axis(alpha, ALPHAS)
    j, fj = _axis(mu, MUS)
    k, fk = _axis(z, ZS)
    out = 0.0
    for di, wi in ((0, 1 - fi), (1, fi)):
        for dj, wj in ((0, 1 - fj), (1, fj)):
            out = out + wi * wj * (t[i + di, j + dj, k] * (1 - fk) + t[i + di, j + dj, k + 1] * fk)
    return np.asarray(out, np.float32)


def albedo_rows(alpha) -> np.ndarray:
    """E interpolated at fixed α (m,) -> (m, N_MU) rows over μ (a material's α is constant, so a hit's E is one
    linear interpolation in μ: :func:`mu_index`, :func:`lerp_rows`)."""
    t = tables()["E"]
    i, fi = _axis(alpha, ALPHAS)
    return (t[i] * (1 - fi[:, None]) + t[i + 1] * fi[:, None]).astype(np.float32)


def layer_rows(alpha, f0) -> np.ndarray:
    """S interpolated at fixed (α, z(f0)) (m,) -> (m, N_MU) rows over μ."""
    t = tables()["S"]
    i, fi = _axis(alpha, ALPHAS)
    k, fk = _axis(z_of_f0(f0), ZS)
    fi, fk = fi[:, None], fk[:, None]
    lo = t[i, :, k] * (1 - fk) + t[i, :, k + 1] * fk
    hi = t[i + 1, :, k] * (1 - fk) + t[i + 1, :, k + 1] * fk
    return (lo * (1 - fi) + hi * fi).astype(np.float32)


def mu_index(index: np.ndarray, mu: np.ndarray):
    """Where hits of rows ``index`` (n,) at ``mu`` (n,) fall in (m, N_MU) per-material rows: flat indices of the
    lower neighbours (n,) and the fractions (n,) float32, for :func:`lerp_rows` (shared by every table)."""
    n = N_MU
    y = mu - np.float32(MUS[0])
    y *= np.float32((n - 1) / (1.0 - MUS[0]))
    np.maximum(y, 0.0, out=y)
    np.minimum(y, n - 1, out=y)
    y0 = y.astype(np.intp)
    np.minimum(y0, n - 2, out=y0)
    fy = y - y0.astype(np.float32)  # float32 (an integer array would promote it, and every term after, to float64)
    k = index * n
    k += y0
    return k, fy


def lerp_rows(rows: np.ndarray, k: np.ndarray, fy: np.ndarray) -> np.ndarray:
    """Linear interpolation in μ of (m, N_MU) ``rows`` at :func:`mu_index`'s ``k``, ``fy``."""
    flat = rows.reshape(-1)
    lo = np.take(flat, k)
    out = np.take(flat, k + 1)
    out -= lo
    out *= fy
    out += lo
    return out
