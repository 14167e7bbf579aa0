"""The ReSTIR DI target function p̂ with per-surface terms computed once and reused for every candidate.

For a surface point x (shading normal n_s, geometric normal n_g, view direction ωo in world space) and a
light point y (position, unit normal n_l, radiance Le), in area measure on the lights:
  p̂(y) = luminance(f(ωo, ωi) · Le) · |cos θ_s| |cos θ_l| / d²      (0 below the geometric horizon,
                                                                     at a back face of a one-sided light)
  p_b(y) = p_b,ω(ωi | ωo) · |cos θ_l| / d²                            (the BSDF sampling pdf, area measure)
with f the Lambert + GGX model of bsdf.py. Because luminance is linear, luminance(f · Le) splits into
  Le · k_d  +  S(ωi) · (Le · A + (1 - ωo·h)⁵ · Le · B)
where k_d, A and B are per-surface RGB vectors (luminance weights folded in) and S is the scalar
D·G/(4 cos θ_o cos θ_i) of the GGX lobe; only S and the Fresnel power depend on the candidate.
Agrees with bsdf.eval_bsdf to float32 rounding (tested).
"""
from __future__ import annotations

import dataclasses

import numpy as np

from .bsdf import _smith_lambda, _schlick, view_albedo
from .light_tiles import light_points, unpack
from .lights import spot_factor
from .sampling import to_world

LUM = np.array([0.2126, 0.7152, 0.0722], np.float32)
INV_PI = np.float32(1.0 / np.pi)


def _rowdot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.einsum("ij,ij->i", a, b)


LAYOUT = {"p": slice(0, 3), "ng": slice(3, 6), "ns": slice(6, 9), "wo": slice(9, 12), "kd": slice(12, 15),
          "a": slice(15, 18), "b": slice(18, 21), "co": 21, "alpha2": 22, "alpha": 23, "lam_o": 24, "p_spec": 25,
          "spec_on": 26}
WIDTH = 27  # float32 per surface: 108 bytes


class ShadingTerms:
    """Per-surface terms of p̂, packed as (n, 27) float32 rows (:data:`LAYOUT`) so that the terms of
    other pixels (spatial and temporal neighbours) are one row gather away."""

    def __init__(self, packed: np.ndarray):
        self.packed = packed
        for name, cols in LAYOUT.items():
            setattr(self, name, packed[:, cols])
        self.glossy = bool((self.spec_on > 0).any() or (self.p_spec > 0).any())

    @staticmethod
    def of_surfaces(surf) -> "ShadingTerms":
        """Terms of surfaces ``surf`` (anything with p, ng, ns, t, bt, wo_l, params)."""
        prm = surf.params
        packed = np.empty((len(surf.p), WIDTH), np.float32)
        put = lambda name, v: packed.__setitem__((slice(None), LAYOUT[name]), v)  # noqa: E731
        put("p", surf.p)
        put("ng", surf.ng)
        put("ns", surf.ns)
        put("wo", to_world(surf.wo_l, surf.ns, surf.t, surf.bt))
        co = surf.wo_l[:, 2].astype(np.float32)
        put("co", co)
        fd = np.where(prm.f0_dielectric > 0, 1.0 - _schlick(prm.f0_dielectric, co), 1.0)
        put("kd", prm.diffuse * (fd * INV_PI)[:, None] * LUM)
        put("spec_on", prm.spec_on)
        put("p_spec", prm.p_spec)
        put("alpha", prm.alpha)
        put("alpha2", prm.alpha * prm.alpha)
        e = view_albedo(prm, surf.wo_l)
        comp = 1.0 + prm.f0 * ((1.0 - e) / e)[:, None]
        put("a", prm.f0 * comp * LUM)
        put("b", (1.0 - prm.f0) * comp * LUM)
        put("lam_o", _smith_lambda(prm.alpha, co))
        return ShadingTerms(packed)

    def take(self, rows) -> "ShadingTerms":
        return ShadingTerms(self.packed.take(rows, axis=0))

    def evaluate(self, pts, want_pdf: bool = True):
        """p̂ (n,) and the BSDF pdf in area measure (n,) (None unless ``want_pdf``) of light points ``pts``
        (light_tiles.LightPoints, one per surface; spot cones already applied, see :func:`with_spots`)."""
        d = pts.pos - self.p
        d2 = _rowdot(d, d)
        inv = 1.0 / np.sqrt(np.maximum(d2, 1e-30))
        ci = _rowdot(d, self.ns) * inv
        cos_l = -_rowdot(d, pts.normal) * inv
        ok = (_rowdot(d, self.ng) > 0) & (ci > 0) & (d2 > 0) & (np.abs(cos_l) > 1e-8) & ((cos_l > 0) | pts.two_sided)
        to_area = np.abs(cos_l) / np.maximum(d2, 1e-30)
        le = pts.le
        lum = _rowdot(le, self.kd)
        pdf_s = None
        if self.glossy:
            wi = d * inv[:, None]
            h = self.wo + wi
            hinv = 1.0 / np.maximum(np.sqrt(_rowdot(h, h)), 1e-12)
            cos_h = np.clip(_rowdot(h, self.ns) * hinv, 0.0, 1.0)
            odh = np.clip(_rowdot(h, self.wo) * hinv, 1e-6, 1.0)
            c2 = cos_h * cos_h
            den = c2 * (self.alpha2 - 1.0) + 1.0
            dist_d = self.alpha2 / (np.pi * den * den)
            g = 1.0 / (1.0 + self.lam_o + _smith_lambda(self.alpha, ci))
            s = self.spec_on * dist_d * g / np.maximum(4.0 * self.co * ci, 1e-12)
            c = np.clip(1.0 - odh, 0.0, 1.0)
            c5 = (c * c) * (c * c) * c
            lum = lum + s * (_rowdot(le, self.a) + c5 * _rowdot(le, self.b))
            pdf_s = dist_d * cos_h / (4.0 * odh)
        p_hat = np.where(ok, lum * ci * to_area, 0.0).astype(np.float32)
        if not want_pdf:
            return p_hat, None
        pdf = (1.0 - self.p_spec) * np.maximum(ci, 0.0) * INV_PI
        if pdf_s is not None:
            pdf = pdf + self.p_spec * pdf_s
        return p_hat, np.where(ok, pdf * to_area, 0.0).astype(np.float32)


def with_spots(pts, lamps, p: np.ndarray, spot_tri: np.ndarray | None = None):
    """``pts`` with spot-cone attenuation towards receivers p applied to the radiance (a copy if any).
    ``spot_tri`` (n,) lamp triangle per point, -1 without a cone (default: ``pts.spot_tri``)."""
    spot_tri = pts.spot_tri if spot_tri is None else spot_tri
    spot = np.flatnonzero(spot_tri >= 0)
    if spot.size == 0:
        return pts
    le = pts.le.copy()
    le[spot] *= spot_factor(lamps, spot_tri[spot], p[spot])[:, None]
    return dataclasses.replace(pts, le=le)


class FramePoints:
    """The light points of a frame of reservoirs (light -1 rows hold an arbitrary point), packed for
    row gathers by neighbouring pixels."""

    def __init__(self, lights, light: np.ndarray, b1: np.ndarray, b2: np.ndarray):
        pts = light_points(lights, np.maximum(light, 0), b1, b2)
        self.rows = pts.packed()
        self.spot_tri = pts.spot_tri if pts.has_spots else None
        self.lamps = lights.scene.lamps

    def at(self, q: np.ndarray, receivers: np.ndarray):
        """Points of reservoirs ``q`` as seen from receivers (n, 3) (spot cones applied)."""
        pts = unpack(self.rows.take(q, axis=0))
        if self.spot_tri is not None:
            pts = with_spots(pts, self.lamps, receivers, self.spot_tri[q])
        return pts
