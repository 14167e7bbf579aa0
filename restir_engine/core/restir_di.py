"""ReSTIR DI: reservoirs over the light samples of primary hits.

This module provides the reservoir layout and initial resampling (streaming RIS, Talbot et al. 2005;
Bitterli et al. 2020 §3-4), with candidates from two strategies combined by the balance heuristic:
  light candidates: ``light_candidates`` points from the power alias table over triangle lights,
                    pdf p_l (solid angle) = p_select / A · d² / |cos θ_l|
  BSDF candidates:  ``bsdf_candidates`` BSDF-sampled rays; a ray that reaches emitters yields the lamp
                    it crosses and the emissive surface it stops at (each generated with p_b), a ray
                    that reaches none is a null candidate (it still counts in M_b, never re-drawn)
Resampling weight of candidate y:  w = p̂(y) / (M_l p_l(y) + M_b p_b(y)),
target p̂(y) = luminance(f(ωo, ωi) · Le(y) · |cos θ_s|) (unshadowed integrand, solid-angle measure),
unbiased contribution weight W = Σw / p̂(y_selected). The selected sample is shaded with one shadow ray:
L_direct = f · Le · |cos θ_s| · V · W. Suns are not resampled: one light-sampled sun per pixel is added.

Reservoir memory per pixel: light index (int32), barycentrics b1, b2, confidence M, W, cached p̂
(float32 each) = 24 bytes.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .accel import offset_origin, shadow_rays
from .bsdf import eval_bsdf, luminance, sample_bsdf
from .sampling import dot, to_local, to_world, uniform_triangle

DIRECT_METHODS = ("LIGHT_SAMPLING", "RIS")


@dataclass
class DISettings:
    method: str = "RIS"
    light_candidates: int = 32
    bsdf_candidates: int = 1


@dataclass
class Reservoirs:
    """SoA reservoirs (n,): light int32 (-1 = empty), b1, b2, M, W, p_hat float32."""

    light: np.ndarray
    b1: np.ndarray
    b2: np.ndarray
    M: np.ndarray
    W: np.ndarray
    p_hat: np.ndarray

    @staticmethod
    def empty(n: int) -> "Reservoirs":
        z = np.zeros(n, np.float32)
        return Reservoirs(np.full(n, -1, np.int32), z.copy(), z.copy(), z.copy(), z.copy(), z.copy())


def _target(surf, wi: np.ndarray, le: np.ndarray):
    """p̂ (n,), f (n, 3), |cos θ_s| (n,) and BSDF pdf (n,) of directions wi (world) at the surfaces."""
    wi_l = to_local(wi, surf.ns, surf.t, surf.bt)
    f, pdf_b = eval_bsdf(surf.params, surf.wo_l, wi_l)
    cos_s = np.abs(wi_l[:, 2])
    ok = dot(wi, surf.ng) > 0
    p_hat = np.where(ok, luminance(f * le) * cos_s, 0.0).astype(np.float32)
    return p_hat, f, cos_s, np.where(ok, pdf_b, 0.0).astype(np.float32)


class _Stream:
    """Streaming reservoir update, vectorized over pixels."""

    def __init__(self, n: int, rng: np.random.Generator):
        self.res = Reservoirs.empty(n)
        self.w_sum = np.zeros(n, np.float64)
        self.rng = rng

    def add(self, rows: np.ndarray, light, b1, b2, w, p_hat):
        w = np.where(np.isfinite(w) & (w > 0), w, 0.0)
        self.w_sum[rows] += w
        take = self.rng.random(len(rows)) * self.w_sum[rows] < w
        r = rows[take]
        self.res.light[r] = light[take]
        self.res.b1[r] = b1[take]
        self.res.b2[r] = b2[take]
        self.res.p_hat[r] = p_hat[take]

    def finish(self, m: float) -> Reservoirs:
        res = self.res
        ok = (res.light >= 0) & (res.p_hat > 0)
        res.W = np.where(ok, self.w_sum / np.maximum(res.p_hat, 1e-30), 0.0).astype(np.float32)
        res.light = np.where(ok, res.light, -1).astype(np.int32)
        res.M = np.full(len(res.W), m, np.float32)
        return res


def initial_ris(ctx, surf, rng: np.random.Generator, cfg: DISettings) -> Reservoirs:
    """One reservoir per surface point from M_l light and M_b BSDF candidates (see module docstring)."""
    n = len(surf.p)
    lights = ctx.lights
    m_l = cfg.light_candidates if lights.tri_alias is not None else 0
    m_b = cfg.bsdf_candidates if lights.n_tri else 0
    stream = _Stream(n, rng)
    rows = np.arange(n)
    for _ in range(m_l):
        u = rng.random((n, 4), dtype=np.float32)
        li = lights.tri_alias.sample(u[:, 0], u[:, 1]).astype(np.int32)
        b1, b2 = uniform_triangle(u[:, 2], u[:, 3])
        _q, wi, dist, cos_l, le = lights.point_towards(li, b1, b2, surf.p)
        p_l = lights.tri_only_pdf_solid_angle(li, dist, cos_l)
        p_hat, _f, _c, p_b = _target(surf, wi, le)
        stream.add(rows, li, b1, b2, p_hat / np.maximum(m_l * p_l + m_b * p_b, 1e-30), p_hat)
    for _ in range(m_b):
        u = rng.random((n, 3), dtype=np.float32)
        wi_l, _f, p_b = sample_bsdf(surf.params, surf.wo_l, u[:, 0], u[:, 1], u[:, 2])
        wi = to_world(wi_l, surf.ns, surf.t, surf.bt).astype(np.float32)
        wi /= np.maximum(np.sqrt(dot(wi, wi)), 1e-12)[:, None]
        live = np.flatnonzero((p_b > 0) & (dot(wi, surf.ng) > 0))
        if live.size == 0:
            continue
        o = offset_origin(surf.p[live], surf.ng[live], wi[live])
        d = wi[live]
        hits = ctx.geom_accel.intersect(o, d)
        candidates = []
        hp = np.maximum(hits.prim, 0)
        geo_light = np.where(hits.prim >= 0, lights.geom_to_light[hp], -1)
        candidates.append((geo_light, hits.u, hits.v))
        if len(ctx.scene.lamps.tris):
            lh = ctx.lamp_accel.intersect(o, d, hits.t)
            lamp_ok = (lh.prim >= 0) & (lh.t < hits.t)
            lamp_light = np.where(lamp_ok, lights.lamp_to_light[np.maximum(lh.prim, 0)], -1)
            candidates.append((lamp_light, lh.u, lh.v))
        for light, cu, cv in candidates:
            sel = np.flatnonzero(light >= 0)
            if sel.size == 0:
                continue
            r = live[sel]
            li = light[sel].astype(np.int32)
            b1, b2 = cu[sel].astype(np.float32), cv[sel].astype(np.float32)
            _q, wdir, dist, cos_l, le = lights.point_towards(li, b1, b2, surf.p[r])
            p_l = lights.tri_only_pdf_solid_angle(li, dist, cos_l)
            sub = _SurfaceRows(surf, r)
            p_hat, _f2, _c2, pb = _target(sub, wdir, le)
            stream.add(r, li, b1, b2, p_hat / np.maximum(m_l * p_l + m_b * pb, 1e-30), p_hat)
    return stream.finish(1.0)


class _SurfaceRows:
    """A row subset of a Surface, with the fields the target function reads."""

    def __init__(self, surf, rows):
        self.p, self.ng, self.ns = surf.p[rows], surf.ng[rows], surf.ns[rows]
        self.t, self.bt, self.wo_l = surf.t[rows], surf.bt[rows], surf.wo_l[rows]
        self.params = surf.params.take(rows)


def shade(ctx, surf, res: Reservoirs, rng: np.random.Generator) -> np.ndarray:
    """Direct radiance (n, 3) at the surfaces: the reservoir's sample with one shadow ray, plus one
    light-sampled sun."""
    n = len(surf.p)
    out = np.zeros((n, 3), np.float32)
    lights = ctx.lights
    live = np.flatnonzero((res.light >= 0) & (res.W > 0))
    if live.size:
        sub = _SurfaceRows(surf, live)
        q, wi, dist, _cos_l, le = lights.point_towards(res.light[live], res.b1[live], res.b2[live], sub.p)
        _p, f, cos_s, _pb = _target(sub, wi, le)
        contrib = f * le * (cos_s * res.W[live])[:, None] * (dot(wi, sub.ng) > 0)[:, None]
        go = np.flatnonzero(contrib.max(axis=1) > 0)
        if go.size:
            so, sd, far = shadow_rays(sub.p[go], sub.ng[go], q[go], wi[go], dist[go])
            vis = ~ctx.geom_accel.occluded(so, sd, far)
            out[live[go[vis]]] = contrib[go[vis]]
    if lights.sun_alias is not None:
        ls = lights.sample_suns(n, rng.random((n, 4), dtype=np.float32))
        p_hat, f, cos_s, _pb = _target(surf, ls.wi, ls.le)
        contrib = f * ls.le * (cos_s / np.maximum(ls.pdf, 1e-30))[:, None] * (dot(ls.wi, surf.ng) > 0)[:, None]
        go = np.flatnonzero(contrib.max(axis=1) > 0)
        if go.size:
            so, sd, far = shadow_rays(surf.p[go], surf.ng[go], ls.pos[go], ls.wi[go], ls.dist[go])
            vis = ~ctx.geom_accel.occluded(so, sd, far)
            out[go[vis]] += contrib[go[vis]]
    return np.where(np.isfinite(out), out, 0.0).astype(np.float32)
