"""The Principled BSDF as Cycles builds it (Blender 4.x/5.x), without transmission (a Coat or a Sheen is a Mix of a
coat or sheen row and a base row: export/coat.py, export/sheen.py; a sheen row's diffuse lobe is sheen.py's lobe);
vectorized. Anisotropic hits replace the specular lobes' D and Smith terms
with anisotropic GGX (anisotropy.py) at the same α = √(αx αy), so the lobes' weights and compensation stay these.

All directions are (3, n) rows (x, y, z) in the local shading frame (z = shading normal), unit length,
``wo`` towards the viewer, ``wi`` towards the light; colours are (3, n) rows (R, G, B), scene-linear.
``eval`` returns f (3, n) without the cosine; pdfs are in solid-angle measure.

Lobes (α = roughness², all GGX lobes share it: D, height-correlated Smith G2 = 1/(1 + Λo + Λi)):
  metal       metallic · F_m(ωo·h) · D G2/(4 cos θo cos θi) · (1 + Fms_m (1 - E)/E)
              F_m = F0 + (1 - F0)(1 - ωo·h)⁵ - b ωo·h (1 - ωo·h)⁶  (F82-tint; b = 0 for a white Specular Tint;
              a Glossy BSDF has the constant F_m = its colour)
  dielectric  (1 - metallic) · F_d(ωo·h) · D G2/(4 cos θo cos θi) · (1 + Fms_d (1 - E)/E)
              F_d = mix(f0·tint, 1, s), s = (F_exact(ωo·h, η) - f0)/(1 - f0): the exact Fresnel of
              η = (1 + √f0)/(1 - √f0), rescaled to start at the tinted f0
  diffuse     base (1 - metallic)/π · saturate(1 - max_rgb[(E + Fms_d (1 - E)) · mix(f0·tint, 1, S(α, μo, η))])
              (Lambert under the dielectric layer, weighted by one minus that layer's albedo toward the viewer)
E(α, μo) is the single-scattering albedo, Fms = Fss E_avg/(1 - Fss (1 - E_avg)) the multiscatter Fresnel with Fss
the lobe's average Fresnel (metal: mix(F0, 1, 1/21) - b/126; dielectric: mix(f0·tint, 1, s_ss), s_ss from the
fitted average (η - 1)/(4.08567 + 1.00071 η); Glossy: its colour). Tables: :mod:`.microfacet_tables`. A lobe
with the "GGX" (single-scatter) distribution has no compensation and layers with mix(f0·tint, 1, S) alone.
Lobes are sampled by one-sample MIS: cosine hemisphere for the diffuse lobe, the GGX normal distribution for
the specular ones.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..sampling import cosine_hemisphere, dot, orthonormal_basis
from . import microfacet_tables as tables
from .microfacet import fresnel_exact, ggx_normals, smith_view
from .anisotropy import AnisoFrame
from .params import SurfaceParams
from .sheen import SheenRows

INV_PI = np.float32(1.0 / np.pi)


def view_albedo(p: SurfaceParams, wo: np.ndarray) -> np.ndarray:
    """GGX single-scattering albedo E(μo, α) (n,) of the view directions."""
    return tables.albedo(p.alpha, np.clip(wo[2], 0, 1))


def view_layer(p: SurfaceParams, wo: np.ndarray) -> np.ndarray:
    """The dielectric layer's Fresnel interpolation factor S(α, μo, η) (n,) toward the viewer."""
    return tables.layer_s(p.alpha, np.clip(wo[2], 0, 1), p.f0r)


@dataclass
class ViewTerms:
    """The factors of f and its pdf that depend on the view direction only, per surface (n): computed once
    and reused by every wi evaluated there (next-event estimation, BSDF sampling, shading).
    kd (3, n) the diffuse lobe (layering weight applied, over π); the specular lobes are
    D G2/(4 cos θo cos θi) · (spec_a + c⁵ spec_b + max(F(ωo·h) - f0r, 0) spec_c - ωo·h c⁶ spec_d) with
    c = 1 - ωo·h and F the exact dielectric Fresnel of η (eta2m1 = η² - 1): spec_a (3, n); spec_b only where some
    surface has a metal lobe, spec_c, eta2m1, f0r only where some has a dielectric lobe, spec_d only where some
    metal has a Specular Tint (else None);
    alpha, alpha2 = α², co = cos θo, vo = √(cos² θo (1 - α²) + α²) (the view's half of the height-correlated
    Smith term: G2/(4 cos θo cos θi) = 1/(2 (vo cos θi + vi cos θo)); Λ(ωo) = (vo/cos θo - 1)/2), p_spec (n,)."""

    kd: np.ndarray
    spec_a: np.ndarray
    spec_b: np.ndarray
    spec_c: np.ndarray | None
    spec_d: np.ndarray | None
    eta2m1: np.ndarray | None
    alpha: np.ndarray
    alpha2: np.ndarray
    vo: np.ndarray
    co: np.ndarray
    p_spec: np.ndarray
    glossy: bool = True  # False: no surface has a specular lobe (Diffuse BSDFs only): Lambert alone
    om_a2: np.ndarray | None = None    # (n,) 1 - α² (glossy)
    pd: np.ndarray | None = None       # (n,) (1 - p_spec)/π: the diffuse sample's pdf over cos θi (glossy)
    f0r: np.ndarray | None = None  # (n,) untinted dielectric f0 (with spec_c)
    bump_n: np.ndarray | None = None   # (3, n) normal-mapped surfaces: the unmapped normal in the local frame
    bump_a2: np.ndarray | None = None  # (n,) and its bump-shadowing roughness (:func:`bump_factor`)
    on_a: np.ndarray | None = None     # (n,) Oren–Nayar where some surface has a diffuse roughness (else None):
    on_b: np.ndarray | None = None     # a, b and the multiple-scattering colour Ems (1 - E(cos θo)) (3, n)
    on_ms: np.ndarray | None = None
    spec_n: np.ndarray | None = None   # (3, n) the specular lobes' normal in the local frame (surface.py), or None
    co_s: np.ndarray | None = None     # (n,) cos θo about spec_n
    spec_rows: np.ndarray | None = None  # (k,) the surfaces whose spec_n is not the shading normal (z), and
    spec_nr: np.ndarray | None = None    # (3, k) their spec_n; spec_bent (n,) bool: those surfaces
    spec_bent: np.ndarray | None = None
    # metals on their own columns (a chunk whose other lobes are grey and where at most half the surfaces are
    # metal): spec_a and spec_b hold no metal part; metal_a, metal_b, metal_d (3, k) are the metal lobe's
    # spec_a, spec_b, spec_d terms of surfaces metal_rows (k,)
    metal_rows: np.ndarray | None = None
    metal_a: np.ndarray | None = None
    metal_b: np.ndarray | None = None
    metal_d: np.ndarray | None = None
    aniso: AnisoFrame | None = None  # the anisotropic surfaces (their vo is the anisotropic view term)
    sheen: SheenRows | None = None   # the sheen surfaces (their kd holds R(μo)/Ē; f takes R(μi) too: sheen.py)

    def spec_full(self):
        """spec_a ((3, n) or grey (n,)) and spec_b ((3, n) or None) of every surface, metal columns included."""
        if self.metal_rows is None:
            return self.spec_a, self.spec_b
        r, n = self.metal_rows, len(self.co)
        a = np.empty((3, n), np.float32)
        a[:] = self.spec_a
        a[:, r] += self.metal_a
        b = np.zeros((3, n), np.float32)
        b[:, r] = self.metal_b
        return a, b

    @property
    def lam_o(self) -> np.ndarray:
        """Smith Λ(ωo) (n,) about the specular lobes' normal."""
        co = self.co if self.co_s is None else self.co_s
        lam = self.vo / np.maximum(co, np.float32(1e-12))
        lam -= 1.0
        lam *= 0.5
        return lam

    def with_spec_normal(self, spec_n: np.ndarray, wo: np.ndarray) -> None:
        """Give the specular lobes their own normal ``spec_n`` (local, unit (3, n)): their cos θo and vo. Only the
        surfaces where it differs from the shading normal (few: 0.04 % of the demo's hits) pay for it."""
        bent = (spec_n[0] != 0) | (spec_n[1] != 0) | (spec_n[2] != 1)
        rows = np.flatnonzero(bent)
        if rows.size == 0:
            return
        self.spec_n, self.spec_rows, self.spec_bent = spec_n, rows, bent
        self.spec_nr = np.take(spec_n, rows, axis=1)
        self.co_s = self.co.copy()
        self.co_s[rows] = np.clip(dot(np.take(wo, rows, axis=1), self.spec_nr), np.float32(1e-4), 1.0)
        vo = self.vo.copy()
        vo[rows] = smith_view(self.alpha2[rows], self.co_s[rows])
        self.vo = vo

    def with_anisotropy(self, frame: AnisoFrame, wo: np.ndarray) -> None:
        """Make the surfaces ``frame.rows`` anisotropic (their specular D and Smith terms; the view's vo)."""
        rows = frame.rows
        if rows.size == 0 or not self.glossy:
            return
        self.aniso = frame
        vo = self.vo.copy()
        vo[rows] = frame.smith_v(np.take(wo, rows, axis=1))
        self.vo = vo

    def with_sheen(self, rows: SheenRows, wo: np.ndarray) -> None:
        """Make the surfaces ``rows.rows`` sheen lobes (core/materials/sheen.py): kd scaled by R(μo)/Ē."""
        self.sheen = rows
        kd = np.array(self.kd, np.float32, copy=True)
        kd[:, rows.rows] *= rows.view_factor(np.clip(wo[2, rows.rows], 0.0, 1.0))
        self.kd = kd

    @staticmethod
    def of(p: SurfaceParams, wo: np.ndarray, albedo: np.ndarray | None = None,
           layer: np.ndarray | None = None, mu_at=None) -> "ViewTerms":
        """``albedo``, ``layer``: :func:`view_albedo`, :func:`view_layer` (n,) if known, or functions returning
        them (called only where a lobe needs them: a chunk of Diffuse BSDFs looks up neither). ``mu_at``: where
        the surfaces' μo falls in per-material μ rows (:func:`microfacet_tables.mu_index`), with which a table's
        per-hit view under a grey dielectric layer reads its view terms from :meth:`SurfaceParams.mu_rows`."""
        co = wo[2]
        alpha = p.alpha
        alpha2 = alpha * alpha
        vo = smith_view(alpha2, co)
        # per block: a chunk may hold none of a lobe the scene has (a flag absent skips the scan)
        is_metal = p.metal > 0 if p.has("metal") else None
        has_metal = is_metal is not None and bool(is_metal.any())
        has_diel = p.has("diel") and bool(p.diel.any())
        if not (has_metal or has_diel):
            kd = p.diffuse * INV_PI
            return ViewTerms(kd, np.zeros_like(kd), None, None, None, None, alpha, alpha2, vo, co, p.p_spec,
                             False)._oren_nayar(p, co)
        fast = p.view_mu_rows() if mu_at is not None and has_diel else None
        kd = p.diffuse * lerp_at(fast["W"], *mu_at) if fast is not None else p.diffuse * INV_PI
        one_e = miss = None
        if fast is None:
            e = view_albedo(p, wo) if albedo is None else albedo() if callable(albedo) else albedo
            one_e = 1.0 - e
            miss = one_e / e
        spec_a = spec_b = spec_c = spec_d = None
        eta2m1, f0r = (p.eta2m1, p.f0r) if has_diel else (None, None)
        mrows = metal = None
        if has_metal:
            if not p.has("coloured_layer"):  # the other lobes grey: metals on their own columns when few
                mrows = np.flatnonzero(is_metal)
                if 2 * mrows.size > len(co):
                    mrows = None
            pm = p if mrows is None else p.take(mrows)
            if fast is None:
                mm = miss if mrows is None else miss[mrows]
            else:
                k, fy = mu_at if mrows is None else (mu_at[0][mrows], mu_at[1][mrows])
                mm = lerp_at(fast["E"], k, fy)
                np.divide(1.0, mm, out=mm)
                mm -= 1.0                               # (1 - E)/E
            cm = pm.fm * mm
            cm += 1.0
            metal = [cm * pm.a_m, cm * pm.b_m, None]
            if p.has("tint") and pm.d_m.any():
                metal[2] = cm * pm.d_m
            if mrows is None:
                spec_a, spec_b, spec_d = metal
        if has_diel and fast is not None:               # grey layer, a table's view: per-material rows in μo
            k, fy = mu_at
            cd = lerp_at(fast["A"], k, fy)
            spec_a = cd if spec_a is None else np.add(spec_a, cd, out=spec_a)
            spec_c = lerp_at(fast["C"], k, fy)
        elif has_diel:
            # without a tinted dielectric its rows are grey: one channel serves (spec_c (n,), and spec_a too
            # where no metal adds to it)
            row = p.grey if not p.has("coloured_layer") else p.__getattr__
            cd = row("fd") * miss
            cd += 1.0
            spec_c = cd * row("c_d")
            cd *= row("a_d")
            spec_a = cd if spec_a is None else np.add(spec_a, cd, out=spec_a)
            s = view_layer(p, wo) if layer is None else layer() if callable(layer) else layer
            f0t, msd = row("diel_f0"), row("msd")
            la = f0t * (1.0 - s)                        # mix(f0t, 1, S)
            la += s
            dark = one_e * msd
            np.subtract(1.0, dark, out=dark)
            la *= dark                                  # the dielectric layer's albedo toward the viewer
            w = la.max(axis=0) if la.ndim == 2 else la
            np.subtract(1.0, w, out=w)                  # ≤ 1: 1 where there is no dielectric layer (f0t = 0, S = 0)
            np.maximum(w, 0.0, out=w)
            kd *= w
        if mrows is not None and spec_a is None:
            spec_a = np.zeros(len(co), np.float32)
        p_spec = p.p_spec
        pd = 1.0 - p_spec
        pd *= INV_PI
        v = ViewTerms(kd, spec_a, spec_b, spec_c, spec_d, eta2m1, alpha, alpha2, vo, co, p_spec, True,
                      1.0 - alpha2, pd, f0r)
        if mrows is not None:
            v.metal_rows = mrows
            v.metal_a, v.metal_b, v.metal_d = metal
        return v._oren_nayar(p, co)

    def _oren_nayar(self, p: SurfaceParams, co: np.ndarray) -> "ViewTerms":
        """Attach the Oren–Nayar terms where some surface has a diffuse roughness: f_d = kd π (a + b t + ms (1 - E_i))
        (kd stays the Lambert lobe, which the ReSTIR targets and the GI diffuse split use as its approximation)."""
        on_b = p.on_b
        if not (p.has("rough_diffuse") and on_b.any()):
            return self
        self.on_a, self.on_b = p.on_a * np.float32(np.pi), on_b * np.float32(np.pi)
        self.on_ms = p.on_ems * (1.0 - oren_nayar_E(p.on_a, on_b, np.maximum(co, 0))) * np.float32(np.pi)
        return self


def oren_nayar_G(c: np.ndarray) -> np.ndarray:
    """The Oren–Nayar albedo integral's angular part at cos θ = c (Cycles' closed form, Taylor near 0)."""
    c = np.clip(c, 0.0, 1.0)
    s = np.sqrt(np.maximum(1.0 - c * c, 0.0))
    theta = np.arccos(c)
    g = s * (theta - 2.0 / 3.0 - s * c) + (2.0 / 3.0) * (s / np.maximum(c, 1e-6)) * (1.0 - s * s * s)
    return np.where(c < 1e-6, (np.pi / 2 - 2.0 / 3.0) - c, g).astype(np.float32)


def oren_nayar_E(a, b, c):
    """Directional albedo a π + b G(c) of the single-scattering Oren–Nayar lobe (a white surface)."""
    return a * np.float32(np.pi) + b * oren_nayar_G(c)


def view_terms(surf) -> ViewTerms:
    """The view terms of surfaces: ``surf.view`` when they carry them (surface.Surface computes them once),
    else computed from ``params``, ``wo_l`` and ``albedo``/``layer`` (if given)."""
    v = getattr(surf, "view", None)
    return v if v is not None else ViewTerms.of(surf.params, surf.wo_l, getattr(surf, "albedo", None),
                                                getattr(surf, "layer", None))


def lerp_at(rows, k: np.ndarray, fy: np.ndarray) -> np.ndarray:
    """Per-material rows (values, steps) (:meth:`SurfaceParams.mu_rows`) at flat node ``k`` + fraction ``fy`` (n,)."""
    out = np.take(rows[1], k, mode="wrap")
    out *= fy
    out += np.take(rows[0], k, mode="wrap")
    return out


def _diffuse_term(v: ViewTerms, wo: np.ndarray, wi: np.ndarray):
    """(The diffuse lobe's f (3, n) toward unit directions wi: Lambert, Oren–Nayar, the bump-map correction and
    the sheen rows' R(μi); validity (n,) bool: both directions above the shading normal and the unmapped one)."""
    co, ci = v.co, wi[2]
    valid = (co > 0) & (ci > 0)
    kd = v.kd
    if v.on_b is not None:  # Oren–Nayar relative to Lambert (on_a, on_b, on_ms carry the factor π)
        nl = np.maximum(ci, 0)
        nv = np.maximum(co, 0)
        t = dot(wo, wi) - nl * nv
        t = np.where(t > 0, t / (np.maximum(nl, nv) + np.float32(1e-30)), t)
        e_l = oren_nayar_E(v.on_a, v.on_b, nl) * np.float32(1.0 / np.pi)
        kd = kd * (v.on_a + v.on_b * t) + kd * v.on_ms * (1.0 - e_l)
    if v.bump_n is not None:
        ok, g = bump_factor(v, wi)
        valid = valid & (ok > 0)
        kd = kd * g
    if v.sheen is not None:  # the sheen rows' R(μi)
        kd = np.array(kd, np.float32, copy=True)
        kd[:, v.sheen.rows] *= v.sheen.light_factor(wi[2, v.sheen.rows])
    return kd, valid


def eval_view(v: ViewTerms, wo: np.ndarray, wi: np.ndarray):
    """f (3, n) and pdf (n,) (solid angle) of unit directions wi (3, n) at surfaces with view terms ``v``. The half
    vector h = (wo + wi)/|wo + wi| enters only through |wo + wi|² = t = 2 + 2 wo·wi: cos θ_h = (cos θ_o +
    cos θ_i)/√t and wo·h = √t/2, so the specular pdf D cos θ_h/(4 wo·h) is D (cos θ_o + cos θ_i)/(2t)."""
    co = v.co
    ci = wi[2]
    kd, valid = _diffuse_term(v, wo, wi)
    if not v.glossy:
        pdf = np.maximum(ci, np.float32(0.0)) * INV_PI * valid
        return (kd * valid).astype(np.float32, copy=False), pdf.astype(np.float32, copy=False)
    valid = valid.astype(np.float32)                # (masks multiply as float32: a bool operand is cast per element)
    if v.spec_n is not None:  # the specular lobes about their own normal (where it differs: rows rs)
        rs = v.spec_rows
        co = v.co_s
        ci_r = dot(np.take(wi, rs, axis=1), v.spec_nr)
        ci = ci.copy()
        ci[rs] = ci_r
        valid_r = valid[rs] * (ci_r > 0)
    a2 = v.alpha2
    t = dot(wo, wi)
    t *= 2.0
    t += 2.0
    np.maximum(t, np.float32(1e-12), out=t)         # |wo + wi|²
    q = co + ci
    c2 = q * q
    c2 /= t
    np.minimum(c2, 1.0, out=c2)                     # cos² θh
    c2 *= v.om_a2
    np.subtract(1.0, c2, out=c2)                    # 1 + cos² θh (α² - 1)
    c2 *= c2
    c2 *= np.float32(2.0 * np.pi)
    dh = np.divide(a2, c2, out=c2)                  # D/2
    # height-correlated Smith: G2/(4 cos θo cos θi) = 1/(2 (vo cos θi + vi cos θo))
    vi = ci * ci
    vi *= v.om_a2
    vi += a2
    np.sqrt(vi, out=vi)
    vi *= co
    vo_ci = v.vo * ci
    vi += vo_ci
    np.maximum(vi, np.float32(1e-12), out=vi)
    s = np.divide(dh, vi, out=vi)                   # D G2 / (4 cos θo cos θi)
    if v.aniso is not None:  # anisotropic surfaces: their own D and Smith terms (rows ra)
        ra = v.aniso.rows
        s_a, q_a = v.aniso.spec_terms(np.take(wo, ra, axis=1), np.take(wi, ra, axis=1), v.vo[ra])
        s[ra] = s_a
    if v.spec_n is not None:
        s[rs] *= valid_r
    spec = v.spec_a * s                             # (n,) where every lobe is grey, else (3, n)
    odh = np.sqrt(t)
    odh *= 0.5
    np.minimum(odh, 1.0, out=odh)                   # ωo·h
    if v.spec_b is not None or v.spec_d is not None:
        _add_metal_fresnel(spec, s, odh, v.spec_b, v.spec_d)
    if v.spec_c is not None:
        fr = fresnel_exact(odh, v.eta2m1)
        fr -= v.f0r
        np.maximum(fr, 0.0, out=fr)
        fr *= s
        fr = np.multiply(fr, v.spec_c, out=fr) if v.spec_c.ndim == 1 else fr * v.spec_c
        spec = np.add(spec, fr, out=spec) if spec.ndim >= fr.ndim else spec + fr
    if spec.ndim == 1:
        spec *= valid
        f = kd * valid
        f += spec
    else:
        spec += kd
        spec *= valid
        f = spec
    if v.metal_rows is not None:  # the metal lobe on its own columns
        r = v.metal_rows
        sk = s[r]
        m = v.metal_a * sk
        _add_metal_fresnel(m, sk, odh[r], v.metal_b, v.metal_d)
        m *= valid[r]
        n = f.shape[1]
        np.add.at(f.reshape(-1), (r + np.arange(0, 3 * n, n)[:, None]).ravel(), m.ravel())  # f[:, r] += m
    q /= t
    q *= dh                                         # the specular pdf D cos θh/(4 ωo·h)
    if v.aniso is not None:
        q[ra] = q_a
    if v.spec_n is not None:
        ci = wi[2]
        q[rs] *= valid_r
    pdf = np.maximum(ci, np.float32(0.0))
    pdf *= v.pd
    q *= v.p_spec
    pdf += q
    pdf *= valid
    return f.astype(np.float32, copy=False), pdf.astype(np.float32, copy=False)


def _add_metal_fresnel(spec: np.ndarray, s: np.ndarray, odh: np.ndarray, b, d) -> None:
    """spec (3, k) += s · (c⁵ b - ωo·h c⁶ d) in place, c = 1 - ωo·h (the angular part of the metal's F82-tint
    Fresnel; b or d None: absent), clamped at 0 where d is given (the F82-tint clamp)."""
    c = 1.0 - odh
    c5 = c * c
    c5 *= c5
    c5 *= c
    c5 *= s
    if b is not None:
        spec += c5 * b
    if d is not None:
        c5 *= odh * c
        spec -= c5 * d
        np.maximum(spec, 0.0, out=spec)


def bump_factor(v: ViewTerms, wi: np.ndarray):
    """Cycles' bump-map correction at normal-mapped surfaces (1 elsewhere): (valid (n,) 0/1: directions on the
    wrong side of the unmapped normal N_s are rejected for every lobe, the diffuse factor (n,): the Smith G1 of a
    GGX of α² = min(1, tan²θ_d / 8) at |N_s·ωi|, θ_d the angle between the mapped and unmapped normals)."""
    bn = v.bump_n
    cos_si = bn[0] * wi[0] + bn[1] * wi[1] + bn[2] * wi[2]
    ok = (cos_si * bn[2] * wi[2]) >= 0
    c2 = np.clip(cos_si * cos_si, 1e-12, 1.0)
    g = 2.0 / (1.0 + np.sqrt(1.0 + v.bump_a2 * (1.0 - c2) / c2))
    return ok.astype(np.float32), np.where(np.abs(cos_si) < 1e-6, np.float32(0.0), g).astype(np.float32)


def diffuse_f(v: ViewTerms, wi: np.ndarray, rows=None) -> np.ndarray:
    """The diffuse lobe alone (3, k) toward local directions wi (3, k) at surfaces ``rows`` (all when None) of view
    terms ``v``, with the bump-map correction where there is one."""
    kd = v.kd if rows is None else np.take(v.kd, rows, axis=1)
    co = v.co if rows is None else v.co[rows]
    valid = ((wi[2] > 0) & (co > 0)).astype(np.float32)
    if v.sheen is not None:  # the sheen rows' R(μi)
        sub = v.sheen if rows is None else v.sheen.take(rows, len(v.co))
        if sub is not None:
            kd = np.array(kd, np.float32, copy=True)
            kd[:, sub.rows] *= sub.light_factor(wi[2, sub.rows])
    if v.bump_n is not None:
        sub = v if rows is None else ViewTerms(None, None, None, None, None, None, None, None, None, None, None,
                                               bump_n=np.take(v.bump_n, rows, axis=1), bump_a2=v.bump_a2[rows])
        ok, g = bump_factor(sub, wi)
        valid *= ok * g
    return kd * valid


def eval_bsdf(p: SurfaceParams, wo: np.ndarray, wi: np.ndarray):
    """f (3, n) and pdf (n,) of sampling wi given wo, both unit (3, n) vectors. For many wi at the same surfaces
    build :class:`ViewTerms` once and call :func:`eval_view`."""
    return eval_view(ViewTerms.of(p, wo), wo, wi)


def sample_bsdf(p: SurfaceParams, wo: np.ndarray, u_lobe: np.ndarray, u1: np.ndarray, u2: np.ndarray,
                view: ViewTerms | None = None):
    """Sample wi; returns wi (3, n), f (3, n), pdf (n,) (the mixture pdf, so MIS-ready). ``view``: the surfaces'
    :class:`ViewTerms` if known."""
    spec = np.flatnonzero(u_lobe < p.p_spec)
    wi = cosine_hemisphere(u1, u2)
    if spec.size:
        h = ggx_normals(p.alpha[spec], u1[spec], u2[spec])
        if view is not None and view.spec_n is not None:  # about the specular normal: rotate h into its frame
            sel = np.flatnonzero(view.spec_bent[spec])
            if sel.size:
                sn = np.take(view.spec_n, spec[sel], axis=1)
                t2, b2 = orthonormal_basis(sn)
                hs = np.take(h, sel, axis=1)
                h[:, sel] = hs[0] * t2 + hs[1] * b2 + hs[2] * sn
        if view is not None and view.aniso is not None:  # anisotropic rows: their own normals, in their frame
            at = np.full(len(u_lobe), -1, np.intp)
            at[view.aniso.rows] = np.arange(len(view.aniso.rows))
            k = at[spec]
            sel = np.flatnonzero(k >= 0)
            if sel.size:
                h[:, sel] = view.aniso.sample_normals(k[sel], np.take(wo, spec[sel], axis=1), u1[spec[sel]],
                                                      u2[spec[sel]])
        o = np.take(wo, spec, axis=1)
        wi[:, spec] = 2.0 * dot(o, h) * h - o
    # eval_view is 0 (f and pdf) below the surface, and its pdf positive wherever f may be
    f, pdf = eval_view(ViewTerms.of(p, wo) if view is None else view, wo, wi)
    return wi, f, pdf
