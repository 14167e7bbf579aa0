"""Reuse building blocks on known small inputs with exact expected outputs: pairwise MIS weights, the merge
of reservoirs, spatial and temporal reuse over a 3-pixel G-buffer (a table-driven sample space, fixed
neighbour offsets) and the history remap when lights switch on or off."""
import dataclasses

import numpy as np
import pytest
from scenes_core import top_down_camera

from restir_engine.core.restir import reuse
from restir_engine.core.restir.di import DIReservoirs
from restir_engine.core.restir.gbuffer import GBuffer
from restir_engine.core.restir.history import TemporalHistory
from restir_engine.core.restir.reservoir import Reservoirs

F = np.float32


class IdSamples(Reservoirs):
    """Samples named by an integer id."""

    SAMPLE = {"sid": np.int32}


class Terms:
    """Surfaces named by an id, with positions (3, n) (what temporal reuse projects)."""

    def __init__(self, ids, p):
        self.ids, self.p = np.asarray(ids), np.asarray(p, F)

    def take(self, rows):
        return Terms(self.ids[rows], self.p[:, rows])


class TableSpace:
    """p̂ of sample j at surface i = table[i, j]."""

    kind = IdSamples

    def __init__(self, table):
        self.table = np.asarray(table, F)

    def prepare(self, res):
        return res.sid

    def gather(self, prepared, idx):
        return prepared[idx]

    def evaluate(self, terms, gathered):
        return self.table[terms.ids, gathered]


def reservoirs(sid, M, W, p_hat):
    return IdSamples(sid=np.array(sid, np.int32), M=np.array(M, F), W=np.array(W, F), p_hat=np.array(p_hat, F))


def test_pairwise_weights_exact_values():
    one = lambda v: np.array([v], F)  # noqa: E731
    # no neighbour accepted: the canonical sample keeps weight 1
    w_c, (w_q,) = reuse.pairwise_weights(one(1), one(2), [one(1)], [one(3)], [one(1)], [one(4)], [np.array([False])])
    assert w_c[0] == 1.0 and w_q[0] == 0.0
    # one neighbour, M_c = M_q = 1: π = 1, m_q(y_q) = 3 / (3 + 1), m_c(y_c) = 2 / (4 + 2)
    w_c, (w_q,) = reuse.pairwise_weights(one(1), one(2), [one(1)], [one(3)], [one(1)], [one(4)], [np.array([True])])
    np.testing.assert_allclose([w_c[0], w_q[0]], [1 / 3, 0.75], rtol=1e-6)
    # a rejected second neighbour changes nothing
    w_c2, (w_q2, w_r) = reuse.pairwise_weights(one(1), one(2), [one(1), one(0)], [one(3), one(9)], [one(1), one(9)],
                                               [one(4), one(9)], [np.array([True]), np.array([False])])
    np.testing.assert_allclose([w_c2[0], w_q2[0], w_r[0]], [1 / 3, 0.75, 0.0], rtol=1e-6)
    # two neighbours, M_c = 2, M_1 = 1, M_2 = 3: shares π_1 = (1 + 1) / 6, π_2 = (3 + 1) / 6
    w_c, (w1, w2) = reuse.pairwise_weights(one(2), one(2), [one(1), one(3)], [one(1), one(2)], [one(1), one(2)],
                                           [one(2), one(1)], [np.array([True]), np.array([True])])
    np.testing.assert_allclose(w1[0], (2 / 6) * 1 / (1 + 1), rtol=1e-6)
    np.testing.assert_allclose(w2[0], (4 / 6) * 6 / (6 + 2), rtol=1e-6)
    np.testing.assert_allclose(w_c[0], (2 / 6) * 2 / (2 + 2) + (4 / 6) * 2 / (3 + 2), rtol=1e-6)


def test_pairwise_weights_sum_to_one_for_every_sample():
    """For a sample y, the weights every technique would give it sum to 1 (unbiasedness)."""
    g = np.random.default_rng(0)
    n, k = 1000, 3
    m_c, m_q = g.uniform(0.5, 5, n).astype(F), [g.uniform(0.5, 5, n).astype(F) for _ in range(k)]
    # targets p[i] of technique i (0 = canonical) at the canonical sample and at each neighbour's sample
    at_c = [g.uniform(0.1, 2, n).astype(F) for _ in range(k + 1)]
    oks = [np.ones(n, bool)] * k
    w_c, _ = reuse.pairwise_weights(m_c, at_c[0], m_q, [np.ones(n, F)] * k, [np.ones(n, F)] * k, at_c[1:], oks)
    # the weight technique q gives y_c: π_q M_q p_q(y_c) / (M_q p_q(y_c) + M_c/k p_c(y_c))
    total = m_c + sum(m_q)
    others = sum((mq + m_c / k) / total * mq * pq / (mq * pq + m_c / k * at_c[0]) for mq, pq in zip(m_q, at_c[1:]))
    np.testing.assert_allclose(w_c + others, 1.0, rtol=1e-5)


@pytest.mark.parametrize("bias", ["NONE", "UNBIASED"])
def test_merge_weights_and_selection(bias):
    """Canonical (sample 0: M 1, W 1.5, p̂_c 2) and one neighbour (sample 1: M 1, W 2, p̂_q(y_q) 3,
    p̂_c(y_q) 1, p̂_q(y_c) 4) over 40000 rows: W is Σw / (p̂_c(y) · D) for the kept sample, which is kept
    with probability w / Σw (binomial z-score < 5)."""
    n = 40000
    canon = reservoirs(np.zeros(n), np.ones(n), np.full(n, 1.5), np.full(n, 2.0))
    src = reservoirs(np.ones(n), np.ones(n), np.full(n, 2.0), np.full(n, 3.0))
    nb = reuse.Neighbour(src, np.arange(n), np.ones(n, bool), np.ones(n, F), np.ones(n, F), np.full(n, 4.0, F))
    out = reuse.merge(canon, [nb], bias, np.random.default_rng(1))
    if bias == "UNBIASED":
        w_c, w_q = (1 / 3) * 2 * 1.5, 0.75 * 1 * 2.0  # m · p̂_c · W
        expect_w = {0: (w_c + w_q) / 2.0, 1: (w_c + w_q) / 1.0}
    else:
        w_c, w_q = 2 * 1.5 * 1, 1 * 2.0 * 1  # p̂_c · W · M
        expect_w = {0: (w_c + w_q) / (2.0 * 2), 1: (w_c + w_q) / (1.0 * 2)}
    assert np.all(out.M == 2.0)
    for sid, w in expect_w.items():
        sel = out.sid == sid
        np.testing.assert_allclose(out.W[sel], w, rtol=1e-6)
        np.testing.assert_allclose(out.p_hat[sel], 2.0 if sid == 0 else 1.0)
    p = w_q / (w_c + w_q)
    frac = np.mean(out.sid == 1)
    assert abs(frac - p) < 5 * np.sqrt(p * (1 - p) / n), (frac, p)


def _gbuffer(depth, ns=None, material=(0, 0, 0)):
    """Three surfaces in a 3 x 1 window, surface i at pixel i."""
    n = len(depth)
    gb = GBuffer(np.arange(n), n, 1, np.array(depth, F), np.zeros(n, np.int32), np.array(material, np.int32),
                 Terms(np.arange(n), np.zeros((3, n))))
    gb.normals = np.tile(np.array([[0], [0], [1]], F), (1, n)) if ns is None else np.array(ns, F)
    return gb


def test_spatial_reuse_merges_the_neighbour_and_skips_rejected_ones(monkeypatch):
    """Every pixel's neighbour is the pixel to its right (fixed offsets): pixel 0 is rejected by depth
    (20 % apart), pixel 2's neighbour lies outside the window; pixel 1 merges pixel 2 exactly as
    :func:`reuse.merge` says."""
    monkeypatch.setattr(reuse, "neighbor_offsets", lambda k, r, rng, n: np.tile(np.array([[[1.0], [0.0]]], F), (k, 1, n)))
    table = [[5, 5, 5],   # p̂ at surface 0 of samples 0, 1, 2
             [5, 2, 1],   # surface 1: its own sample 1 has p̂ 2, the neighbour's sample 2 has p̂ 1
             [5, 4, 3]]   # surface 2: p̂_q(y_c) = 4, p̂_q(y_q) = 3
    space = TableSpace(table)
    res = reservoirs([0, 1, 2], [1, 1, 1], [0.5, 1.5, 2.0], [5, 2, 3])
    gb = _gbuffer([1.2, 1.0, 1.05])
    cfg = reuse.SpatialSettings(neighbors=1, radius=1.0, passes=1, bias_correction="UNBIASED")
    hits = {0: 0, 1: 0}
    for seed in range(200):
        out = reuse.spatial_reuse(space, gb, res, space.prepare(res), np.arange(3), cfg, np.random.default_rng(seed))
        # rejected or outside: the canonical reservoir comes back unchanged
        for i in (0, 2):
            assert (out.sid[i], out.M[i], out.W[i], out.p_hat[i]) == (res.sid[i], 1.0, res.W[i], res.p_hat[i])
        assert out.M[1] == 2.0
        w = (1 / 3) * 2 * 1.5 + 0.75 * 1 * 2.0
        assert out.sid[1] in (1, 2)
        np.testing.assert_allclose(out.W[1], w / (2.0 if out.sid[1] == 1 else 1.0), rtol=1e-6)
        hits[int(out.sid[1] == 2)] += 1
    assert hits[0] > 0 and hits[1] > 0


def test_temporal_reuse_caps_confidence_and_rejects_disocclusions():
    """Same camera, same surfaces: each surface finds its previous self. Surface 0 merges (previous M 50
    capped at 20 x 1), surface 1 changed material (rejected), surface 2 moved 50 % in depth (rejected)."""
    cam = top_down_camera(3, 1, height_above=2.0, half_extent=1.5)
    xs = np.array([-1.0, 0.0, 1.0], F)  # pixel centres of the 3 x 1 window on the z = 0 plane
    p = np.stack([xs, np.zeros(3, F), np.zeros(3, F)])
    gb = _gbuffer([2.0, 2.0, 2.0], material=(0, 1, 0))
    gb.terms = Terms(np.arange(3), p)
    prev_gb = _gbuffer([2.0, 2.0, 3.0], material=(0, 0, 0))
    table = [[2, 1, 0, 0], [0, 0, 1, 0], [0, 0, 3, 3]]  # surface i: p̂ of samples 0..3 (3 = surface 0's old one)
    space = TableSpace(np.array(table, F))
    res = reservoirs([0, 2, 2], [1, 1, 1], [1.5, 1.0, 1.0], [2, 1, 3])
    prev = reservoirs([1, 3, 3], [50, 5, 5], [2.0, 1.0, 1.0], [3, 1, 1])
    hist = TemporalHistory(prev_gb, prev, cam, ())
    out = reuse.temporal_reuse(space, gb, res, space.prepare(res), hist, space.prepare(prev), np.arange(3), 20.0,
                               "NONE", None, np.random.default_rng(0))
    assert out.M.tolist() == [21.0, 1.0, 1.0]
    assert out.sid[1] == 2 and out.sid[2] == 2 and out.W[1] == 1.0 and out.W[2] == 1.0  # unchanged
    # surface 0, 1/M: w_c = p̂ W M = 2·1.5·1, w_prev = p̂_c(y_prev) W_prev M_prev = 1·2·20
    w = 2 * 1.5 + 1 * 2.0 * 20
    np.testing.assert_allclose(out.W[0], w / ((2.0 if out.sid[0] == 0 else 1.0) * 21), rtol=1e-6)


def test_history_remap_when_lights_switch():
    """Old table: lights with stable ids [0, 2, 5]; new table: [2, 5, 7] (id 0 went out, 7 came on)."""
    res = DIReservoirs(light=np.array([0, 1, 2, -1], np.int32), b1=np.full(4, 0.2, F), b2=np.full(4, 0.3, F),
                       M=np.array([4, 5, 6, 7], F), W=np.ones(4, F), p_hat=np.ones(4, F))
    hist = TemporalHistory(None, res, None, ("old",), 3, np.array([0, 2, 5]), (6, 2))

    @dataclasses.dataclass
    class Lights:
        signature: tuple
        light_uid: np.ndarray
        uid_space: tuple
        n_tri: int

    same = hist.remapped(Lights(("old",), np.array([0, 2, 5]), (6, 2), 3))
    assert same is hist
    new = hist.remapped(Lights(("new",), np.array([2, 5, 7]), (6, 2), 3))
    assert new.res.light.tolist() == [-1, 0, 1, -1]
    assert new.res.W.tolist() == [0, 1, 1, 1] and new.res.p_hat.tolist() == [0, 1, 1, 1]
    assert new.res.M.tolist() == [4, 5, 6, 7]  # confidence kept
    assert new.had_light.tolist() == [True, True, False]
    assert res.W.tolist() == [1, 1, 1, 1]  # the original history is untouched
    assert hist.remapped(Lights(("other",), np.array([0, 1]), (4, 0), 2)) is None  # other triangles: no map
    # with the world's points (light index n_tri, stable id 6 + 2 = 8): a world sample follows the world's new index
    res_w = res.replace(light=np.array([0, 3, 2, -1], np.int32))
    hist_w = TemporalHistory(None, res_w, None, ("old", True), 3, np.array([0, 2, 5, 8]), (6, 2))
    new_w = hist_w.remapped(Lights(("new", True), np.array([2, 5, 7, 6, 8]), (6, 2), 4))
    assert new_w.res.light.tolist() == [-1, 4, 1, -1]
    assert new_w.had_light.tolist() == [True, True, False, False, True]
    gone = hist_w.remapped(Lights(("new", False), np.array([2, 5, 7]), (6, 2), 3))  # the world turned black
    assert gone.res.light.tolist() == [-1, -1, 1, -1] and gone.res.W.tolist() == [0, 0, 1, 1]


def test_reuse_over_a_slice_equals_reuse_over_its_indices(monkeypatch):
    """The renderer hands reuse contiguous chunks as slices (views instead of gathers): same output."""
    monkeypatch.setattr(reuse, "neighbor_offsets", lambda k, r, rng, n: np.tile(np.array([[[1.0], [0.0]]], F), (k, 1, n)))
    space = TableSpace([[5, 5, 5], [5, 2, 1], [5, 4, 3]])
    res = reservoirs([0, 1, 2], [1, 1, 1], [0.5, 1.5, 2.0], [5, 2, 3])
    gb = _gbuffer([1.2, 1.0, 1.05])
    cfg = reuse.SpatialSettings(neighbors=1, radius=1.0, passes=1, bias_correction="UNBIASED")
    for seed in range(20):
        a = reuse.spatial_reuse(space, gb, res, space.prepare(res), np.arange(3), cfg, np.random.default_rng(seed))
        b = reuse.spatial_reuse(space, gb, res, space.prepare(res), slice(0, 3), cfg, np.random.default_rng(seed))
        for name in IdSamples.fields():
            assert np.array_equal(getattr(a, name), getattr(b, name)), name


def test_neighbour_offsets_fill_the_disc():
    """Offsets (k, 2, n): inside the radius, every pixel's k offsets at the spiral's radii, pixels rotated
    differently."""
    offs = reuse.neighbor_offsets(5, 30.0, np.random.default_rng(0), 1000)
    assert offs.shape == (5, 2, 1000)
    r = np.hypot(offs[:, 0], offs[:, 1])
    np.testing.assert_allclose(r, (30.0 * np.sqrt((np.arange(5) + 0.5) / 5))[:, None] * np.ones((1, 1000)), rtol=1e-5)
    angle = np.arctan2(offs[0, 1], offs[0, 0])
    assert np.histogram(angle, bins=8, range=(-np.pi, np.pi))[0].min() > 80  # uniform rotations (expect 125)
