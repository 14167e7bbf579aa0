"""ReSTIR DI: reservoirs over the light samples of primary hits.

This module provides the reservoir layout and initial resampling (streaming RIS, Talbot et al. 2005;
Bitterli et al. 2020 §3-4), with candidates from two strategies combined by the balance heuristic:
  light candidates: ``light_candidates`` points from the power alias table over triangle lights,
                    pdf p_l (solid angle) = p_select / A · d² / |cos θ_l|
  BSDF candidates:  ``bsdf_candidates`` BSDF-sampled rays; a ray that reaches emitters yields the lamp
                    it crosses and the emissive surface it stops at (each generated with p_b), a ray
                    that reaches none is a null candidate (it still counts in M_b, never re-drawn)
Everything is in AREA measure on the lights, so a sample (a point on a light) and its weight W mean the
same at every pixel and can be reused across pixels without a Jacobian:
  geometry term G(x, y) = |cos θ_s| |cos θ_l| / d²
  target p̂(y) = luminance(f(ωo, ωi) · Le(y)) · G  (the unshadowed integrand)
  light pdf p_l(y) = p_select / A, BSDF pdf p_b(y) = p_b,ω · |cos θ_l| / d²
Resampling weight of candidate y:  w = p̂(y) / (M_l p_l(y) + M_b p_b(y)); unbiased contribution weight
W = Σw / p̂(y_selected) (units m²). The selected sample is shaded with one shadow ray:
L_direct = f · Le · G · V · W. Suns are not resampled: one light-sampled sun per pixel is added.

Reservoir memory per pixel: light index (int32), barycentrics b1, b2, confidence M, W, cached p̂
(float32 each) = 24 bytes.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from .accel import offset_origin, shadow_rays
from .bsdf import eval_bsdf, luminance, sample_bsdf, view_albedo
from .light_tiles import TileSettings, light_points, sample_points, unpack
from .sampling import dot, to_local, to_world
from .target import WIDTH as TERMS_WIDTH
from .target import FramePoints, ShadingTerms, with_spots

DIRECT_METHODS = ("LIGHT_SAMPLING", "RIS", "RESTIR")


@dataclass
class DISettings:
    """tiles: the sample pass's light_tiles.LightTiles (None = candidates straight from the power table)."""

    method: str = "RIS"
    light_candidates: int = 32
    bsdf_candidates: int = 1
    tile_settings: TileSettings = None
    tiles: object = None


@dataclass
class Reservoirs:
    """SoA reservoirs (n,): light int32 (-1 = empty), b1, b2, M, W, p_hat float32."""

    light: np.ndarray
    b1: np.ndarray
    b2: np.ndarray
    M: np.ndarray
    W: np.ndarray
    p_hat: np.ndarray

    FIELDS = ("light", "b1", "b2", "M", "W", "p_hat")

    @staticmethod
    def empty(n: int) -> "Reservoirs":
        z = np.zeros(n, np.float32)
        return Reservoirs(np.full(n, -1, np.int32), z.copy(), z.copy(), z.copy(), z.copy(), z.copy())

    def assign(self, rows: np.ndarray, other: "Reservoirs") -> None:
        """self[rows] = other (all fields)."""
        for name in Reservoirs.FIELDS:
            getattr(self, name)[rows] = getattr(other, name)

    @staticmethod
    def gather(parts, n: int) -> "Reservoirs":
        """A frame of n reservoirs from (rows, Reservoirs) parts."""
        out = Reservoirs.empty(n)
        for rows, part in parts:
            out.assign(rows, part)
        return out


def _target(surf, wi: np.ndarray, le: np.ndarray, dist: np.ndarray, cos_l: np.ndarray):
    """Area-measure target p̂ (n,), f (n, 3), geometry term G (n,) and the BSDF's pdf converted to area
    measure (n,) for light points in directions wi (world) at distances dist from the surfaces."""
    wi_l = to_local(wi, surf.ns, surf.t, surf.bt)
    if getattr(surf, "albedo", None) is None:  # one lookup per surface, not per candidate
        surf.albedo = view_albedo(surf.params, surf.wo_l)
    f, pdf_b = eval_bsdf(surf.params, surf.wo_l, wi_l, surf.albedo)
    ok = (dot(wi, surf.ng) > 0) & (dist > 0)
    to_area = np.abs(cos_l) / np.maximum(dist * dist, 1e-30)
    g = np.abs(wi_l[:, 2]) * to_area
    p_hat = np.where(ok, luminance(f * le) * g, 0.0).astype(np.float32)
    return p_hat, f, np.where(ok, g, 0.0).astype(np.float32), np.where(ok, pdf_b * to_area, 0.0).astype(np.float32)


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


def initial_ris(ctx, surf, rng: np.random.Generator, cfg: DISettings, px=None, py=None) -> Reservoirs:
    """One reservoir per surface point from M_l light and M_b BSDF candidates (see module docstring).

    Light candidates come from ``cfg.tiles`` (light_tiles.LightTiles; ``px``, ``py``: the surfaces' window
    pixels pick the tile) or straight from the power table. All M_l candidates are weighed first and one is
    selected per pixel in proportion to its weight (the same distribution as streaming one at a time)."""
    n = len(surf.p)
    lights = ctx.lights
    m_l = cfg.light_candidates if lights.tri_alias is not None else 0
    m_b = cfg.bsdf_candidates if lights.n_tri else 0
    stream = _Stream(n, rng)
    terms = ShadingTerms.of_surfaces(surf)
    surf.terms = terms  # the G-buffer keeps them for reuse
    lamps = ctx.scene.lamps
    if m_l and n:
        tiles = cfg.tiles if px is not None else None
        if tiles is not None:
            source, rows = tiles.points, tiles.rows
            pick = np.minimum((rng.random((m_l, n), dtype=np.float32) * tiles.size).astype(np.int64), tiles.size - 1)
            pick += tiles.tile_base(px, py)[None, :]
        else:
            source = sample_points(lights, rng.random((m_l * n, 4), dtype=np.float32))
            rows, pick = None, None
        spots = source.has_spots
        w = np.empty((m_l, n), np.float32)
        p_hats = np.empty((m_l, n), np.float32)
        for k in range(m_l):
            if spots:  # spot cones need the lamp of each candidate
                pts = source.take(pick[k] if pick is not None else slice(k * n, (k + 1) * n))
                pts = with_spots(pts, lamps, surf.p)
            elif pick is not None:
                pts = unpack(rows.take(pick[k], axis=0))
            else:
                pts = source.take(slice(k * n, (k + 1) * n))
            p_hat, p_b = terms.evaluate(pts, want_pdf=m_b > 0)
            den = m_l * pts.pdf if p_b is None else m_l * pts.pdf + m_b * p_b
            wk = p_hat / np.maximum(den, 1e-30)
            w[k] = np.where(np.isfinite(wk) & (wk > 0), wk, 0.0)
            p_hats[k] = p_hat
        cum = np.cumsum(w, axis=0, dtype=np.float64)
        total = cum[-1]
        k_sel = np.minimum((cum <= (rng.random(n) * total)[None, :]).sum(axis=0), m_l - 1)
        cols = np.arange(n)
        flat = pick[k_sel, cols] if pick is not None else k_sel * n + cols
        take = total > 0
        res = stream.res
        res.light[take] = source.light[flat[take]]
        res.b1[take] = source.b1[flat[take]]
        res.b2[take] = source.b2[flat[take]]
        res.p_hat[take] = p_hats[k_sel, cols][take]
        stream.w_sum[:] = total
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
        if len(lamps.tris):
            lh = ctx.lamp_accel.intersect(o, d, hits.t)
            lamp_ok = (lh.prim >= 0) & (lh.t < hits.t)
            lamp_light = np.where(lamp_ok, lights.lamp_to_light[np.maximum(lh.prim, 0)], -1)
            candidates.append((lamp_light, lh.u, lh.v))
        for light, cu, cv in candidates:
            sel = np.flatnonzero(light >= 0)
            if sel.size == 0:
                continue
            r = live[sel]
            pts = with_spots(light_points(lights, light[sel], cu[sel], cv[sel]), lamps, surf.p[r])
            p_hat, pb = terms.take(r).evaluate(pts)
            stream.add(r, pts.light, pts.b1, pts.b2, p_hat / np.maximum(m_l * pts.pdf + m_b * pb, 1e-30), p_hat)
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
        q, wi, dist, cos_l, le = lights.point_towards(res.light[live], res.b1[live], res.b2[live], sub.p)
        _p, f, g, _pb = _target(sub, wi, le, dist, cos_l)
        contrib = f * le * (g * res.W[live])[:, None]
        go = np.flatnonzero(contrib.max(axis=1) > 0)
        if go.size:
            so, sd, far = shadow_rays(sub.p[go], sub.ng[go], q[go], wi[go], dist[go])
            vis = ~ctx.geom_accel.occluded(so, sd, far)
            out[live[go[vis]]] = contrib[go[vis]]
    if lights.sun_alias is not None:
        ls = lights.sample_suns(n, rng.random((n, 4), dtype=np.float32))
        wi_l = to_local(ls.wi, surf.ns, surf.t, surf.bt)
        f, _pb = eval_bsdf(surf.params, surf.wo_l, wi_l)
        ok = (dot(ls.wi, surf.ng) > 0) & (ls.pdf > 0)
        contrib = f * ls.le * (np.abs(wi_l[:, 2]) / np.maximum(ls.pdf, 1e-30) * ok)[:, None]
        go = np.flatnonzero(contrib.max(axis=1) > 0)
        if go.size:
            so, sd, far = shadow_rays(surf.p[go], surf.ng[go], ls.pos[go], ls.wi[go], ls.dist[go])
            vis = ~ctx.geom_accel.occluded(so, sd, far)
            out[go[vis]] += contrib[go[vis]]
    return np.where(np.isfinite(out), out, 0.0).astype(np.float32)


# -- frame-level stages: G-buffer, spatial reuse, shading ------------------------------------------
SPATIAL_DEPTH_TOLERANCE = 0.1    # relative depth difference above which a neighbour is rejected
SPATIAL_NORMAL_COS = 0.906       # cos 25°: normals further apart are rejected
BIAS_CORRECTIONS = ("NONE", "UNBIASED")


@dataclass
class SpatialSettings:
    neighbors: int = 5
    radius: float = 30.0
    passes: int = 1
    bias_correction: str = "UNBIASED"


class GBuffer:
    """Primary-hit surfaces of one sample pass over the whole window (SoA, row-major pixel index).

    Fields mirror the path tracer's Surface (p, ng, ns, t, bt, wo_l, params) plus depth (planar, for
    neighbour similarity), material (int32) and valid (bool, a surface was hit)."""

    def __init__(self, n: int, material_params):
        f3 = lambda: np.zeros((n, 3), np.float32)  # noqa: E731
        self.p, self.ng, self.ns, self.t, self.bt, self.wo_l = f3(), f3(), f3(), f3(), f3(), f3()
        self.depth = np.zeros(n, np.float32)
        self.material = np.zeros(n, np.int32)
        self.instance = np.zeros(n, np.int32)
        self.valid = np.zeros(n, bool)
        self.params = material_params.take(np.zeros(n, np.int64))  # placeholder rows, overwritten per hit
        self.terms = np.zeros((n, TERMS_WIDTH), np.float32)  # target.ShadingTerms rows

    def shading_terms(self, rows=None) -> ShadingTerms:
        """The target function's per-surface terms of all pixels, or of pixels ``rows``."""
        return ShadingTerms(self.terms if rows is None else self.terms.take(rows, axis=0))

    def store(self, rows: np.ndarray, surf, depth: np.ndarray, instance: np.ndarray | None = None):
        for name in ("p", "ng", "ns", "t", "bt", "wo_l"):
            getattr(self, name)[rows] = getattr(surf, name)
        for name in ("diffuse", "f0", "f0_dielectric", "alpha", "p_spec", "spec_on"):
            getattr(self.params, name)[rows] = getattr(surf.params, name)
        self.terms[rows] = surf.terms.packed if getattr(surf, "terms", None) is not None else \
            ShadingTerms.of_surfaces(surf).packed
        self.depth[rows] = depth
        self.material[rows] = surf.mat
        if instance is not None:
            self.instance[rows] = instance
        self.valid[rows] = True


def neighbor_offsets(k: int, radius: float, rng: np.random.Generator, n: int):
    """Per-pixel neighbour offsets (n, k, 2) in pixels: a golden-angle spiral filling the disc of
    ``radius`` (low discrepancy), rotated by a random angle per pixel and pass (no ring artefacts)."""
    j = np.arange(k, dtype=np.float32)
    r = radius * np.sqrt((j + 0.5) / k)
    phi = j * 2.39996323 + rng.random((n, 1), dtype=np.float32) * 2 * np.pi
    return np.stack([r * np.cos(phi), r * np.sin(phi)], axis=-1)


def spatial_reuse(ctx, gb: GBuffer, res: Reservoirs, width: int, height: int, rows: np.ndarray,
                  cfg: SpatialSettings, rng: np.random.Generator, points: FramePoints | None = None) -> Reservoirs:
    """One spatial pass for pixels ``rows``: merge up to ``cfg.neighbors`` similar neighbours' reservoirs
    into the pixel's own (the canonical one).

    NONE: weights p̂_c(y_q)·W_q·M_q, W = Σw / (p̂ ΣM) (fast; darkens where neighbours cannot produce the
    sample). UNBIASED: pairwise MIS with confidence weights (see :func:`pairwise_weights`): two target
    evaluations per neighbour, robust where a neighbour's target is far below the pixel's.
    ``points``: the light points of ``res`` (target.FramePoints), computed here when not given."""
    n = len(rows)
    lights = ctx.lights
    if points is None:
        points = FramePoints(lights, res.light, res.b1, res.b2)
    me = gb.shading_terms(rows)
    stream = _Stream(n, rng)
    local = np.arange(n)
    valid = gb.valid[rows]
    m_c = np.where(valid, res.M[rows], 0.0).astype(np.float32)
    own = res.light[rows] >= 0
    offs = neighbor_offsets(cfg.neighbors, cfg.radius, rng, n)
    px, py = rows % width, rows // width
    unbiased = cfg.bias_correction == "UNBIASED"
    # per accepted neighbour: its pixel, mask, M, p̂_c(y_q), and (unbiased) p̂_q(y_c)
    qs, oks, m_q, pc_at_q, pq_at_c = [], [], [], [], []
    own_pts = points.at(rows, me.p) if unbiased else None
    for k in range(cfg.neighbors):
        qx = np.round(px + offs[:, k, 0]).astype(np.int64)
        qy = np.round(py + offs[:, k, 1]).astype(np.int64)
        inside = (qx >= 0) & (qx < width) & (qy >= 0) & (qy < height)
        q = np.where(inside, qy * width + qx, rows)
        # a neighbour outside the window, the pixel itself or one already merged would be a correlated
        # duplicate (biased): skip it
        ok = inside & gb.valid[q] & (q != rows) & valid
        for q_prev in qs:
            ok &= q != q_prev
        ok &= np.abs(gb.depth[q] - gb.depth[rows]) <= SPATIAL_DEPTH_TOLERANCE * np.maximum(gb.depth[rows], 1e-6)
        ok &= dot(gb.ns[q], gb.ns[rows]) >= SPATIAL_NORMAL_COS
        qs.append(q)
        oks.append(ok)
        m_q.append(np.where(ok, res.M[q], 0.0).astype(np.float32))
        if not ok.any():
            pc_at_q.append(np.zeros(n, np.float32))
            pq_at_c.append(np.zeros(n, np.float32))
            continue
        p_hat, _pb = me.evaluate(points.at(q, me.p), want_pdf=False)
        pc_at_q.append(np.where(ok & (res.light[q] >= 0), p_hat, 0.0).astype(np.float32))
        if unbiased:
            there = gb.shading_terms(q)
            pts = own_pts if points.spot_tri is None else points.at(rows, there.p)  # spot cones: per receiver
            p_there, _pb = there.evaluate(pts, want_pdf=False)
            pq_at_c.append(np.where(ok & own, p_there, 0.0).astype(np.float32))
    m_total = m_c + (np.sum(m_q, axis=0) if m_q else 0.0)
    if unbiased:
        p_own = np.where(own & valid, res.p_hat[rows], 0.0)
        m_c_w, m_q_w = pairwise_weights(m_c, p_own, m_q, [res.p_hat[q] for q in qs], pc_at_q, pq_at_c, oks)
        stream.add(local, res.light[rows], res.b1[rows], res.b2[rows], m_c_w * p_own * res.W[rows], res.p_hat[rows])
        for q, ok, w_mis, pc in zip(qs, oks, m_q_w, pc_at_q):
            stream.add(local, res.light[q], res.b1[q], res.b2[q], np.where(ok, w_mis * pc * res.W[q], 0.0), pc)
        denom = np.ones(n, np.float32)
    else:
        stream.add(local, res.light[rows], res.b1[rows], res.b2[rows],
                   np.where(own, res.p_hat[rows] * res.W[rows] * res.M[rows], 0.0), res.p_hat[rows])
        for q, mq, pc in zip(qs, m_q, pc_at_q):
            stream.add(local, res.light[q], res.b1[q], res.b2[q], pc * res.W[q] * mq, pc)
        denom = m_total
    out = stream.res
    ok = (out.light >= 0) & (out.p_hat > 0) & (denom > 0)
    out.W = np.where(ok, stream.w_sum / np.maximum(out.p_hat * denom, 1e-30), 0.0).astype(np.float32)
    out.light = np.where(ok, out.light, -1).astype(np.int32)
    out.M = m_total.astype(np.float32)
    return out


def pairwise_weights(m_c, p_c, m_q, p_q, pc_at_q, pq_at_c, oks):
    """Pairwise MIS weights with confidences for one canonical reservoir c and neighbours q = 1..k.

    Each neighbour forms a pair with c, in which c takes a 1/k share of its confidence; pair q holds the
    share π_q = (M_q + M_c/k) / M_total of the estimate and splits it by the balance heuristic:
      m_q(y_q) = π_q · M_q p̂_q(y_q) / (M_q p̂_q(y_q) + M_c/k · p̂_c(y_q))
      m_c(y_c) = Σ_q π_q · M_c/k · p̂_c(y_c) / (M_q p̂_q(y_c) + M_c/k · p̂_c(y_c))      (1 when k = 0)
    For every sample the weights of all techniques sum to one, and a technique whose target is zero gets
    weight zero, so the merged reservoir stays unbiased; where all targets agree the weights are the
    confidence shares M/M_total (the generalized balance heuristic). Arguments are per-slot lists of (n,)
    arrays; ``p_c`` = p̂_c(y_c), ``p_q`` = p̂_q(y_q) (the targets cached in the reservoirs).
    Returns (m_c (n,), [m_q (n,)])."""
    k = np.sum(oks, axis=0).astype(np.float32) if oks else np.zeros_like(m_c)
    m_total = m_c + (np.sum(m_q, axis=0) if m_q else 0.0)
    share_c = np.where(k > 0, m_c / np.maximum(k, 1.0), 0.0)
    inv_total = 1.0 / np.maximum(m_total, 1e-30)
    w_c = np.where(k > 0, 0.0, 1.0)
    w_q = []
    for mq, pq, pcq, pqc, ok in zip(m_q, p_q, pc_at_q, pq_at_c, oks):
        pi = (mq + share_c) * inv_total
        a = mq * pq
        w_q.append(np.where(ok, pi * a / np.maximum(a + share_c * pcq, 1e-30), 0.0))
        b = share_c * p_c
        w_c = w_c + np.where(ok, pi * b / np.maximum(mq * pqc + b, 1e-30), 0.0)
    return w_c.astype(np.float32), [w.astype(np.float32) for w in w_q]


# -- temporal reuse ------------------------------------------------------------------------------
@dataclass
class TemporalHistory:
    """What the next sample pass (or frame) reuses: the previous G-buffer, its final reservoirs, its
    camera and the light-table signature they index into."""

    gbuf: GBuffer
    res: Reservoirs
    camera: object
    light_signature: tuple
    frame: int = 0
    light_uid: np.ndarray | None = None  # (n_tri,) stable id of each light (lights.LightTable.light_uid)
    uid_space: tuple = ()                # (scene triangles, lamp triangles) the ids index into
    had_light: np.ndarray | None = None  # after remapping to a new light table: (n_tri,) bool, lights of the
    #                                      current table that were lights in this history's frame

    def remapped(self, lights) -> "TemporalHistory | None":
        """This history for the light table ``lights`` of the next frame: identical tables keep it as it is;
        tables over the same triangles (lights switched on/off or re-powered) get the reservoirs' light
        indices remapped through the stable ids (a light that went out leaves an empty reservoir) and
        ``had_light`` set; anything else cannot be mapped (None)."""
        if self.light_signature == lights.signature:
            return self
        if self.light_uid is None or self.uid_space != lights.uid_space:
            return None
        uid_to_light = np.full(int(sum(self.uid_space)), -1, np.int64)
        uid_to_light[lights.light_uid] = np.arange(lights.n_tri)
        old = self.res.light
        light = np.where(old >= 0, uid_to_light[self.light_uid[np.maximum(old, 0)]], -1).astype(np.int32)
        gone = (old >= 0) & (light < 0)
        res = Reservoirs(light, self.res.b1, self.res.b2, self.res.M, np.where(gone, 0.0, self.res.W).astype(np.float32),
                         np.where(gone, 0.0, self.res.p_hat).astype(np.float32))
        had = np.zeros(int(sum(self.uid_space)), bool)
        had[self.light_uid] = True
        return dataclasses.replace(self, res=res, light_signature=lights.signature, light_uid=lights.light_uid,
                                   had_light=had[lights.light_uid])


def temporal_reuse(ctx, gb: GBuffer, res: Reservoirs, hist: TemporalHistory, width: int, rows: np.ndarray,
                   confidence_cap: float, bias_correction: str, motion, rng: np.random.Generator) -> Reservoirs:
    """Merge each pixel's reservoir with the reservoir its primary hit had in the previous frame.

    The hit is moved with its object's previous transform (``motion``: scene.Motion, or None when the
    history is not from the previous frame) and projected with the previous camera; the match must pass the G-buffer
    tests (depth within 10 %, normals within 25°, same material), else it is a disocclusion. The previous
    confidence is
    capped at ``confidence_cap`` x the current one. NONE: W = Σw / (p̂ ΣM); UNBIASED: pairwise MIS with
    the previous reservoir as the one neighbour (:func:`pairwise_weights`; its target evaluated at its
    stored surface)."""
    from .camera import project
    n = len(rows)
    me = gb.shading_terms(rows)
    x0, y0, w, h = hist.camera.window
    p_then = gb.p[rows]
    if motion is not None:
        p_then = motion.moved_points(p_then, gb.instance[rows], "prev")
    raster, depth_prev_cam = project(hist.camera, p_then)
    px = np.floor(raster[:, 0]).astype(np.int64) - x0
    py = np.floor(raster[:, 1]).astype(np.int64) - y0
    inside = (px >= 0) & (px < w) & (py >= 0) & (py < h) & (depth_prev_cam > 0) & gb.valid[rows]
    q = np.where(inside, py * w + px, 0)
    ok = inside & hist.gbuf.valid[q]
    ok &= np.abs(hist.gbuf.depth[q] - depth_prev_cam) <= SPATIAL_DEPTH_TOLERANCE * np.maximum(depth_prev_cam, 1e-6)
    ok &= dot(hist.gbuf.ns[q], gb.ns[rows]) >= SPATIAL_NORMAL_COS
    ok &= hist.gbuf.material[q] == gb.material[rows]
    stream = _Stream(n, rng)
    local = np.arange(n)
    m_own = np.where(gb.valid[rows], res.M[rows], 0.0).astype(np.float32)
    own = (res.light[rows] >= 0) & gb.valid[rows]
    prev = hist.res
    m_prev = np.where(ok, np.minimum(prev.M[q], confidence_cap * np.maximum(m_own, 1.0)), 0.0).astype(np.float32)
    use = ok & (prev.light[q] >= 0)
    p_hat = np.zeros(n, np.float32)  # p̂ here of the previous sample
    pts = None
    if use.any():
        pts = light_points(ctx.lights, np.maximum(prev.light[q], 0), prev.b1[q], prev.b2[q])
        p_hat, _pb = me.evaluate(with_spots(pts, ctx.scene.lamps, me.p) if pts.has_spots else pts, want_pdf=False)
        p_hat = np.where(use, p_hat, 0.0).astype(np.float32)
    if bias_correction == "UNBIASED":
        # pairwise MIS with one neighbour (the previous reservoir): the balance heuristic with confidences
        p_prev_at_own = np.zeros(n, np.float32)  # p̂ at the previous surface of the current sample
        both = ok & own
        if both.any():
            then = hist.gbuf.shading_terms(q)
            cur = light_points(ctx.lights, np.maximum(res.light[rows], 0), res.b1[rows], res.b2[rows])
            p_then, _pb = then.evaluate(with_spots(cur, ctx.scene.lamps, then.p) if cur.has_spots else cur,
                                        want_pdf=False)
            if hist.had_light is not None:  # the previous frame could not have produced lights that were off
                p_then = np.where(hist.had_light[np.maximum(res.light[rows], 0)], p_then, 0.0)
            p_prev_at_own = np.where(both, p_then, 0.0).astype(np.float32)
        p_own = np.where(own, res.p_hat[rows], 0.0)
        w_c, (w_p,) = pairwise_weights(m_own, p_own, [m_prev], [np.where(use, prev.p_hat[q], 0.0)], [p_hat],
                                       [p_prev_at_own], [ok])
        stream.add(local, res.light[rows], res.b1[rows], res.b2[rows], w_c * p_own * res.W[rows], res.p_hat[rows])
        if pts is not None:
            stream.add(local, pts.light, pts.b1, pts.b2, np.where(use, w_p * p_hat * prev.W[q], 0.0), p_hat)
        denom = np.ones(n, np.float32)
    else:
        stream.add(local, res.light[rows], res.b1[rows], res.b2[rows],
                   np.where(own, res.p_hat[rows] * res.W[rows] * res.M[rows], 0.0), res.p_hat[rows])
        if pts is not None:
            stream.add(local, pts.light, pts.b1, pts.b2, np.where(use, p_hat * prev.W[q] * m_prev, 0.0), p_hat)
        denom = m_own + m_prev
    out = stream.res
    good = (out.light >= 0) & (out.p_hat > 0) & (denom > 0)
    out.W = np.where(good, stream.w_sum / np.maximum(out.p_hat * denom, 1e-30), 0.0).astype(np.float32)
    out.light = np.where(good, out.light, -1).astype(np.int32)
    out.M = (m_own + m_prev).astype(np.float32)
    return out
