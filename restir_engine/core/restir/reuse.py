"""Spatial and temporal reuse, generic over the sample type.

Both merge a pixel's own (canonical) reservoir with other reservoirs whose samples are shifted to the pixel:
spatial reuse with up to k similar neighbours of the same frame, temporal reuse with the reservoir its
surface had in the previous frame. The sample type enters through a *space* object:
  space.kind                          the Reservoirs subclass
  space.prepare(res)                  per-frame data for gathers of the samples of ``res``
  space.gather(prepared, idx)         samples ``idx`` of ``prepared``, evaluable at any surfaces
  space.evaluate(terms, gathered)     p̂ (n,) of gathered samples at surfaces ``terms``
  space.evaluate_mis (optional)       p̂ for the MIS weights of the neighbours' techniques (GI: with visibility)
  space.shift_ok (optional)           biased mode only: (n,) bool, whether a sample may move from the neighbour's
                                      surface to the pixel's (GI: Jacobian outlier rejection)
Samples live in area measure (DI: points on lights, GI: secondary surface points), so shifting a sample to
another pixel needs no Jacobian.

Merges (one code path, :func:`merge`):
  NONE      w_i = p̂_c(y_i) W_i M_i,  W = Σw / (p̂_c(y) ΣM)    (1/M: fast, darkens where a neighbour's
                                                              sample is impossible at the pixel)
  UNBIASED  w_i = m_i(y_i) p̂_c(y_i) W_i,  W = Σw / p̂_c(y)  with pairwise MIS weights m_i
            (:func:`pairwise_weights`), which sum to one for every sample: unbiased.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..modes import BiasCorrection, values
from .reservoir import Reservoirs, Stream

DEPTH_TOLERANCE = 0.1    # relative planar-depth difference above which a neighbour is rejected
NORMAL_COS = 0.906       # cos 25°: shading normals further apart are rejected
BIAS_CORRECTIONS = values(BiasCorrection)


def similar(depth_ref: np.ndarray, depth: np.ndarray, ns_ref: np.ndarray, ns: np.ndarray) -> np.ndarray:
    """Whether a neighbour's surface (planar depth, shading normal as (3, n) rows) may share samples with the
    reference: depth within DEPTH_TOLERANCE of the reference's and normals within 25°."""
    ok = np.abs(depth - depth_ref) <= DEPTH_TOLERANCE * np.maximum(depth_ref, 1e-6)
    ok &= ns[0] * ns_ref[0] + ns[1] * ns_ref[1] + ns[2] * ns_ref[2] >= NORMAL_COS
    return ok


def neighbor_offsets(k: int, radius: float, rng: np.random.Generator, n: int) -> np.ndarray:
    """Per-pixel neighbour offsets (k, 2, n) in pixels (neighbour, x/y, pixel): a golden-angle spiral filling
    the disc of ``radius`` (low discrepancy), rotated by a random angle per pixel and pass (no ring
    artefacts)."""
    j = np.arange(k, dtype=np.float32)
    r = np.float32(radius) * np.sqrt((j + 0.5) / k)
    spiral = j * np.float32(2.39996323)
    cs, sn = (r * np.cos(spiral))[:, None], (r * np.sin(spiral))[:, None]  # (k, 1) the spiral before the turn
    turn = rng.random(n, dtype=np.float32) * np.float32(2 * np.pi)
    ct, st = np.cos(turn), np.sin(turn)                                     # (n,) the rotation of each pixel
    out = np.empty((k, 2, n), np.float32)
    out[:, 0] = ct * cs - st * sn                                           # r cos(spiral + turn)
    out[:, 1] = st * cs + ct * sn                                           # r sin(spiral + turn)
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
    arrays (``oks``: the neighbour was accepted); ``p_c`` = p̂_c(y_c), ``p_q`` = p̂_q(y_q) (the targets
    cached in the reservoirs). Returns (m_c (n,), [m_q (n,)])."""
    k = np.sum(oks, axis=0).astype(np.float32) if oks else np.zeros_like(m_c)
    m_total = m_c + (np.sum(m_q, axis=0) if m_q else 0.0)
    share_c = m_c / np.maximum(k, np.float32(1.0)) * (k > 0)
    inv_total = 1.0 / np.maximum(m_total, 1e-30)
    w_c = (k == 0).astype(np.float32)
    w_q = []
    for mq, pq, pcq, pqc, ok in zip(m_q, p_q, pc_at_q, pq_at_c, oks):
        pi = (mq + share_c) * inv_total
        a = mq * pq
        w_q.append(pi * a / np.maximum(a + share_c * pcq, np.float32(1e-30)) * ok)
        b = share_c * p_c
        w_c = w_c + pi * b / np.maximum(mq * pqc + b, np.float32(1e-30)) * ok
    return w_c.astype(np.float32, copy=False), [w.astype(np.float32, copy=False) for w in w_q]


@dataclass
class Neighbour:
    """One reservoir offered to each canonical pixel: ``src[q]`` where ``ok``; M its (capped) confidence,
    pc_at_q = p̂_c(y_q) (target of the canonical pixel at the neighbour's sample), pq_at_c = p̂_q(y_c)
    (the neighbour's target at the canonical sample; UNBIASED only). Arrays (n,), zero where not ok."""

    src: Reservoirs
    q: np.ndarray
    ok: np.ndarray
    M: np.ndarray
    pc_at_q: np.ndarray
    pq_at_c: np.ndarray | None = None


def merge(canonical: Reservoirs, neighbours: list, bias_correction: str, rng: np.random.Generator) -> Reservoirs:
    """Resample the canonical reservoirs (n) and their neighbours into new reservoirs (see module docstring).
    The canonical reservoirs' M, W and p̂ are their own; the result's M is the sum of confidences."""
    kind = type(canonical)
    n = len(canonical)
    stream = Stream(kind, n, rng)
    own = canonical.has_sample()
    p_c = canonical.p_hat * own
    m_total = canonical.M + (np.sum([nb.M for nb in neighbours], axis=0) if neighbours else 0.0)
    if bias_correction == "UNBIASED":
        w_c, w_q = pairwise_weights(canonical.M, p_c, [nb.M for nb in neighbours],
                                    [nb.src.p_hat[nb.q] for nb in neighbours], [nb.pc_at_q for nb in neighbours],
                                    [nb.pq_at_c for nb in neighbours], [nb.ok for nb in neighbours])
        stream.add(w_c * p_c * canonical.W, canonical.p_hat, canonical)
        for nb, w in zip(neighbours, w_q):
            stream.add(w * nb.pc_at_q * nb.src.W[nb.q] * nb.ok, nb.pc_at_q, nb.src, nb.q)
        denom = None
    elif bias_correction == "NONE":
        stream.add(p_c * canonical.W * canonical.M, canonical.p_hat, canonical)
        for nb in neighbours:
            stream.add(nb.pc_at_q * nb.src.W[nb.q] * nb.M * nb.ok, nb.pc_at_q, nb.src, nb.q)
        denom = m_total
    else:
        raise ValueError(f"unknown bias correction {bias_correction!r}; available: {BIAS_CORRECTIONS}")
    return stream.finish(m_total, denom)


@dataclass
class TemporalSettings:
    """confidence_cap: the largest confidence M a reused reservoir keeps (as a multiple of the current M
    when merged; absolute in the history)."""

    confidence_cap: float = 20.0


@dataclass
class SpatialSettings:
    """neighbors per pass, radius in pixels (0 = automatic, :func:`auto_radius`), passes, bias correction."""

    neighbors: int = 5
    radius: float = 0.0
    passes: int = 1
    bias_correction: str = "UNBIASED"


AUTO_RADIUS = 8.0          # pixels at 640 x 360 (the choice: docs/RESULTS.md, "Spatial radius")
AUTO_RADIUS_MIN = 4.0
_REFERENCE_DIAGONAL = float(np.hypot(640, 360))


def auto_radius(width: int, height: int) -> float:
    """The automatic spatial radius (pixels) of a width x height render: AUTO_RADIUS at 640 x 360, scaled with
    the image diagonal (the same surface area at any resolution), at least AUTO_RADIUS_MIN."""
    return float(max(AUTO_RADIUS_MIN, AUTO_RADIUS * np.hypot(width, height) / _REFERENCE_DIAGONAL))


def _indices(rows) -> np.ndarray:
    """``rows`` (index array or slice with start and stop) as an index array."""
    return np.arange(rows.start, rows.stop) if isinstance(rows, slice) else rows


def _columns(a: np.ndarray, rows) -> np.ndarray:
    """Columns ``rows`` of a (k, n) block: a view for a slice, a gather otherwise."""
    return a[:, rows] if isinstance(rows, slice) else np.take(a, rows, axis=1)


def _mis_target(space):
    """The target a neighbour's technique has for the canonical sample in the MIS weights: the space's
    ``evaluate_mis`` (e.g. with visibility, where a technique can only make samples its surface sees) or
    ``evaluate``."""
    return getattr(space, "evaluate_mis", space.evaluate)


def spatial_reuse(space, gb, res: Reservoirs, prepared, rows: np.ndarray, cfg: SpatialSettings,
                  rng: np.random.Generator) -> Reservoirs:
    """One spatial pass for surfaces ``rows`` of the G-buffer ``gb`` (restir.gbuffer.GBuffer): merge up to
    ``cfg.neighbors`` similar neighbours' reservoirs of ``res`` (the whole frame; ``prepared`` =
    ``space.prepare(res)``) into each surface's own. Returns the new reservoirs of ``rows`` (an index array,
    or a slice: then the surface's own data are views, not gathers)."""
    ids = _indices(rows)
    n = len(ids)
    unbiased = cfg.bias_correction == "UNBIASED"
    me = gb.terms.take(rows)
    pix = gb.pix[rows]
    px, py = pix % gb.width, pix // gb.width
    offs = neighbor_offsets(cfg.neighbors, cfg.radius, rng, n)
    canonical = res.take(rows)
    own = space.gather(prepared, rows) if unbiased else None
    depth_c, ns_c = gb.depth[rows], _columns(gb.normals, rows)
    own_ok = canonical.has_sample()
    neighbours, taken = [], []
    for k in range(cfg.neighbors):
        qx = np.round(px + offs[k, 0]).astype(np.int64)
        qy = np.round(py + offs[k, 1]).astype(np.int64)
        inside = (qx >= 0) & (qx < gb.width) & (qy >= 0) & (qy < gb.height)
        q = gb.slot[np.where(inside, qy * gb.width + qx, pix)]
        # a neighbour outside the window or without a surface, the pixel itself or one already merged would
        # be a correlated duplicate (biased): skip it
        ok = inside & (q >= 0) & (q != ids)
        for q_prev in taken:
            ok &= q != q_prev
        q = np.where(ok, q, ids)
        ok &= similar(depth_c, gb.depth[q], ns_c, np.take(gb.normals, q, axis=1))
        q = np.where(ok, q, ids)
        taken.append(q)
        m_q = res.M[q] * ok
        if not ok.any():
            z = np.zeros(n, np.float32)
            neighbours.append(Neighbour(res, q, ok, m_q, z, z))
            continue
        theirs = space.gather(prepared, q)
        pc = space.evaluate(me, theirs) * (ok & (res.key[q] >= 0))
        if not unbiased and hasattr(space, "shift_ok"):  # biased mode: drop shifts with outlying Jacobians
            pc *= space.shift_ok(me.p, np.take(gb.terms.p, q, axis=1), theirs)
        pq = None
        if unbiased:
            pq = _mis_target(space)(gb.terms.take(q), own) * (ok & own_ok)
        neighbours.append(Neighbour(res, q, ok, m_q, pc, pq))
    return merge(canonical, neighbours, cfg.bias_correction, rng)


def temporal_reuse(space, gb, res: Reservoirs, prepared_now, hist, prepared_prev, rows: np.ndarray,
                   confidence_cap: float, bias_correction: str, motion, rng: np.random.Generator,
                   possible_before=None) -> Reservoirs:
    """Merge the reservoirs of surfaces ``rows`` (of ``res``, prepared as ``prepared_now``) with the reservoir
    each surface had in the previous frame (``hist``: restir.history.TemporalHistory, its reservoirs prepared
    as ``prepared_prev``).

    The hit is moved with its object's previous transform (``motion``: scene.Motion, or None when the
    history is not from the previous frame) and projected with the previous camera; the match must pass the
    similarity tests (depth within 10 %, normals within 25°) and have the same material, else it is a
    disocclusion. The previous confidence is capped at ``confidence_cap`` x the current one.
    ``possible_before(rows)`` (optional): (n,) bool, False where the previous frame could not have produced
    the current sample (a light switched on since): its target there is zero for the MIS weights."""
    from ..geometry.camera import project

    n = len(_indices(rows))
    prev_gb = hist.gbuf
    p_now = _columns(gb.terms.p, rows)
    p_then = p_now if motion is None else motion.moved_points(p_now, gb.instance[rows], "prev")
    raster, depth_then = project(hist.camera, p_then)
    x0, y0, w, h = hist.camera.window
    px = np.floor(raster[:, 0]).astype(np.int64) - x0
    py = np.floor(raster[:, 1]).astype(np.int64) - y0
    inside = (px >= 0) & (px < w) & (py >= 0) & (py < h) & (depth_then > 0)
    q = prev_gb.slot[np.where(inside, py * w + px, 0)]
    ok = inside & (q >= 0)
    q = np.where(ok, q, 0)
    ok &= similar(depth_then, prev_gb.depth[q], _columns(gb.normals, rows), np.take(prev_gb.normals, q, axis=1))
    ok &= prev_gb.material[q] == gb.material[rows]
    canonical = res.take(rows)
    prev = hist.res
    m_prev = np.minimum(prev.M[q], np.float32(confidence_cap) * np.maximum(canonical.M, np.float32(1.0))) * ok
    use = ok & (prev.key[q] >= 0)
    pc = np.zeros(n, np.float32)
    if use.any():
        theirs = space.gather(prepared_prev, q)
        pc = space.evaluate(gb.terms.take(rows), theirs) * use
        if bias_correction != "UNBIASED" and hasattr(space, "shift_ok"):
            pc *= space.shift_ok(p_now, np.take(prev_gb.terms.p, q, axis=1), theirs)
    pq = None
    if bias_correction == "UNBIASED":
        pq = np.zeros(n, np.float32)
        both = ok & canonical.has_sample()
        if both.any():
            pq = _mis_target(space)(prev_gb.terms.take(q), space.gather(prepared_now, rows))
            if possible_before is not None:
                pq = pq * possible_before(rows)
            pq = pq * both
    return merge(canonical, [Neighbour(prev, q, ok, m_prev, pc, pq)], bias_correction, rng)
