"""Cycles' Voronoi (Worley) noise in 1-4 dimensions, vectorized over points: the same cell hashes (a float hash of
the cell in 1D, PCG of the integer cell in 2-4D), search order, distance metrics, features and fractal sums, so a
Voronoi Texture gives the same pattern as in Cycles. Coordinates are lists of float32 arrays of one shape (already
multiplied by the node's Scale); the cells searched are a Python loop over the 3ᵈ (Smooth F1: 5ᵈ) neighbour
offsets, each step vectorized over every point."""
from __future__ import annotations

from itertools import product

import numpy as np

from .hashing import hash_floats, hash_floats_to_color, pcg, pcg_color

_F = np.float32


def _offsets(dims: int, reach: int):
    """Neighbour cell offsets in Cycles' order: the last axis outermost, the first innermost."""
    for t in product(range(-reach, reach + 1), repeat=dims):
        yield t[::-1]


class _Cells:
    """The points' cells: float and int32 cell coordinates and the position within the cell."""

    def __init__(self, coords):
        self.dims = len(coords)
        self.cell_f = [np.floor(c).astype(np.float32) for c in coords]
        self.cell_i = [c.astype(np.int32) for c in self.cell_f]
        self.local = [(c - f).astype(np.float32) for c, f in zip(coords, self.cell_f)]

    def jitter(self, off) -> list:
        """The hashed point offsets (in [0, 1) per axis) of the cells at ``off`` (a tuple or per-point arrays)."""
        if self.dims == 1:
            return [hash_floats(self.cell_f[0] + _F(off[0]))]
        return pcg(*[c + np.int32(o) if np.ndim(o) == 0 else c + o for c, o in zip(self.cell_i, off)])[:self.dims]

    def jitter_all(self, offs: np.ndarray) -> list:
        """The hashed point offsets of the cells at every offset of ``offs`` (m, dims) int32 at once: ``dims``
        arrays (m, ...) (the offsets along a new leading axis)."""
        lead = (len(offs),) + (1,) * np.ndim(self.local[0])
        if self.dims == 1:
            return [hash_floats(self.cell_f[0] + offs[:, 0].astype(np.float32).reshape(lead))]
        return pcg(*[c + offs[:, k].reshape(lead) for k, c in enumerate(self.cell_i)])[:self.dims]

    def color(self, off) -> np.ndarray:
        """(3, ...) the colours of the cells at ``off``."""
        if self.dims == 1:
            return hash_floats_to_color(self.cell_f[0] + np.asarray(off[0], np.float32))
        return pcg_color(*[c + np.asarray(o, np.int32) for c, o in zip(self.cell_i, off)])


def metric_distance(vec: list, metric: str, exponent) -> np.ndarray:
    """The length of the vector ``vec`` (list of arrays) in the node's metric (1D: always |x|)."""
    if len(vec) == 1:
        return np.abs(vec[0]).astype(np.float32)
    if metric == "MANHATTAN":
        return sum(np.abs(x) for x in vec).astype(np.float32)
    if metric == "CHEBYCHEV":
        return np.maximum.reduce([np.abs(x) for x in vec]).astype(np.float32)
    if metric == "MINKOWSKI":
        e = np.asarray(exponent, np.float32)
        return np.power(sum(np.power(np.abs(x), e) for x in vec), 1 / e).astype(np.float32)
    return np.sqrt(sum(x * x for x in vec)).astype(np.float32)


def _smoothstep(x):
    t = np.clip(x, 0, 1)
    return t * t * (_F(3) - _F(2) * t)


def _points(cells: _Cells, offs: np.ndarray, metric: str, exponent, rand):
    """The feature points of the cells at offsets ``offs`` (m, dims) relative to each point's cell (``dims``
    arrays (m, ...)) and their distances (m, ...) from the point, every offset at once."""
    lead = (len(offs),) + (1,) * np.ndim(cells.local[0])
    point = [offs[:, k].astype(np.float32).reshape(lead) + j * rand for k, j in enumerate(cells.jitter_all(offs))]
    return point, metric_distance([p - q for p, q in zip(point, cells.local)], metric, exponent)


def _nearest(to: np.ndarray, skip: np.ndarray | None = None):
    """Index (...) along the leading axis of the first of the least distances ``to`` (m, ...) that are below
    float32's largest (NaN never is), leaving out index ``skip``, and whether there is one: what a scan in order
    keeping a strictly smaller distance finds (Cycles' search)."""
    clean = np.where(np.isnan(to), np.inf, to)
    if skip is not None:
        clean = clean.copy()
        np.put_along_axis(clean, skip[None], np.inf, axis=0)
    i = np.argmin(clean, axis=0)
    found = np.take_along_axis(clean, i[None], axis=0)[0] < np.finfo(np.float32).max
    return i, found


def _octave(feature: str, metric: str, coords, exponent, randomness, smoothness):
    """One octave: (distance, colour (3, ...), position (list of ``dims`` arrays)) for F1, F2 or Smooth F1. The
    neighbour cells are hashed and measured all at once along a leading axis; F1 is the first nearest in Cycles'
    order, F2 the first nearest of the others."""
    cells = _Cells(coords)
    d, shape = cells.dims, np.shape(cells.local[0])
    rand = np.asarray(randomness, np.float32)
    if feature == "SMOOTH_F1":
        k = np.asarray(smoothness, np.float32)
        offs = np.array(list(_offsets(d, 2)), np.int32)
        dist = np.zeros(shape, np.float32)
        color = np.zeros((3, *shape), np.float32)
        pos = [np.zeros(shape, np.float32) for _ in range(d)]
        group = max(1, (1 << 18) // max(int(np.prod(shape)), 1))  # offsets per batch: about 256k points each
        for lo in range(0, len(offs), group):
            part = offs[lo:lo + group]
            points, tos = _points(cells, part, metric, exponent, rand)
            colors = cells.color([part[:, j].reshape((len(part),) + (1,) * len(shape)) for j in range(d)])
            for m in range(len(part)):
                to, point = tos[m], [p[m] for p in points]
                if lo + m == 0:
                    h = np.ones(shape, np.float32)
                else:
                    h = _smoothstep(_F(0.5) + _F(0.5) * (dist - to) / k)
                corr = k * h * (1 - h)
                dist = dist + (to - dist) * h - corr
                corr = corr / (1 + 3 * k)
                color = color + (colors[:, m] - color) * h - corr
                pos = [p + (q - p) * h - corr for p, q in zip(pos, point)]
        return dist, color, [p + f for p, f in zip(pos, cells.cell_f)]
    inf = np.float32(np.finfo(np.float32).max)
    offs = np.array(list(_offsets(d, 1)), np.int32)
    points, to = _points(cells, offs, metric, exponent, rand)
    best, found = _nearest(to)
    if feature == "F2":
        best, found2 = _nearest(to, best)
        found = found & found2
    dist = np.where(found, np.take_along_axis(to, best[None], axis=0)[0], inf)
    pos = [np.where(found, np.take_along_axis(np.broadcast_to(p, to.shape), best[None], axis=0)[0], _F(0))
           for p in points]
    cell = [np.where(found, offs[best, j], np.int32(0)) for j in range(d)]
    return dist, cells.color(cell), [p + f for p, f in zip(pos, cells.cell_f)]


def _distance_to_edge(coords, randomness):
    cells = _Cells(coords)
    d, shape = cells.dims, np.shape(cells.local[0])
    rand = np.asarray(randomness, np.float32)
    if d == 1:
        x = cells.local[0]
        mid = cells.jitter((0,))[0] * rand
        left = _F(-1) + cells.jitter((-1,))[0] * rand
        right = _F(1) + cells.jitter((1,))[0] * rand
        return np.minimum(np.abs((mid + left) / 2 - x), np.abs((mid + right) / 2 - x)).astype(np.float32)
    vectors = []
    best = np.full(shape, np.float32(np.finfo(np.float32).max), np.float32)
    closest = [np.zeros(shape, np.float32) for _ in range(d)]
    for off in _offsets(d, 1):
        v = [_F(o) + j * rand - q for o, j, q in zip(off, cells.jitter(off), cells.local)]
        vectors.append(v)
        dd = sum(x * x for x in v)
        near = dd < best
        best = np.where(near, dd, best)
        closest = [np.where(near, a, b) for a, b in zip(v, closest)]
    edge = np.full(shape, np.float32(np.finfo(np.float32).max), np.float32)
    for v in vectors:
        perp = [a - b for a, b in zip(v, closest)]
        ll = sum(x * x for x in perp)
        ok = ll > _F(1e-4)
        inv = 1 / np.sqrt(np.where(ok, ll, 1))
        e = sum((a + b) / 2 * p * inv for a, b, p in zip(closest, v, perp))
        edge = np.where(ok, np.minimum(edge, e), edge)
    return edge.astype(np.float32)


def n_sphere_radius(coords, randomness) -> np.ndarray:
    """Half the Euclidean distance from each point's nearest feature point to that point's own nearest neighbour."""
    cells = _Cells(coords)
    d, shape = cells.dims, np.shape(cells.local[0])
    rand = np.asarray(randomness, np.float32)
    inf = np.float32(np.finfo(np.float32).max)
    best = np.full(shape, inf, np.float32)
    closest = [np.zeros(shape, np.float32) for _ in range(d)]
    closest_off = [np.zeros(shape, np.int32) for _ in range(d)]
    for off in _offsets(d, 1):
        point = [_F(o) + j * rand for o, j in zip(off, cells.jitter(off))]
        to = metric_distance([p - q for p, q in zip(point, cells.local)], "EUCLIDEAN", 1)
        near = to < best
        best = np.where(near, to, best)
        closest = [np.where(near, b, a) for a, b in zip(closest, point)]
        closest_off = [np.where(near, np.int32(o), a) for a, o in zip(closest_off, off)]
    best = np.full(shape, inf, np.float32)
    neighbour = [np.zeros(shape, np.float32) for _ in range(d)]
    for off in _offsets(d, 1):
        if not any(off):
            continue
        cell_off = [np.int32(o) + c for o, c in zip(off, closest_off)]
        point = [c.astype(np.float32) + j * rand for c, j in zip(cell_off, cells.jitter(cell_off))]
        to = metric_distance([p - q for p, q in zip(point, closest)], "EUCLIDEAN", 1)
        near = to < best
        best = np.where(near, to, best)
        neighbour = [np.where(near, b, a) for a, b in zip(neighbour, point)]
    return (metric_distance([a - b for a, b in zip(neighbour, closest)], "EUCLIDEAN", 1) / 2).astype(np.float32)


def _max_distance(dims: int, metric: str, exponent, randomness):
    m = _F(0.5) + _F(0.5) * np.asarray(randomness, np.float32)
    return metric_distance([m] * dims, metric, exponent)


def voronoi(feature: str, metric: str, coords: list, detail, roughness, lacunarity, smoothness, exponent,
            randomness, normalize: bool):
    """The Voronoi Texture at ``coords`` (scaled): (distance, colour (3, ...), position (list of ``dims``
    arrays, in the input's units times Scale), radius) for the node's ``feature`` ("F1", "F2", "SMOOTH_F1",
    "DISTANCE_TO_EDGE", "N_SPHERE_RADIUS"); outputs a feature does not have are None. ``detail`` in [0, 15]
    octaves at coords · lacunarityⁱ with amplitudes roughnessⁱ, the fraction of the last blended in."""
    coords = [np.asarray(c, np.float32) for c in coords]
    shape = np.broadcast_shapes(*[c.shape for c in coords])
    coords = [np.broadcast_to(c, shape).astype(np.float32) for c in coords]
    d = len(coords)
    rand = np.clip(np.asarray(randomness, np.float32), 0, 1)
    if feature == "N_SPHERE_RADIUS":
        return None, None, None, n_sphere_radius(coords, rand)
    detail = np.clip(np.broadcast_to(np.asarray(detail, np.float32), shape), 0, 15)
    rough = np.clip(np.broadcast_to(np.asarray(roughness, np.float32), shape), 0, 1)
    lac = np.broadcast_to(np.asarray(lacunarity, np.float32), shape)
    detail = np.where((detail == 0) | (rough == 0), _F(0), detail)  # one octave, as Cycles' zero input
    top = np.ceil(detail)
    frac = detail - np.floor(detail)
    octaves = int(top.max()) if top.size else 0
    amp = np.ones(shape, np.float32)
    scale = np.ones(shape, np.float32)
    if feature == "DISTANCE_TO_EDGE":
        maxd = _F(0.5) + _F(0.5) * rand
        top_amp = np.broadcast_to(maxd, shape).astype(np.float32)
        dist = np.full(shape, _F(8), np.float32)
        for i in range(octaves + 1):
            od = _distance_to_edge([c * scale for c in coords], rand)
            full, part = i <= detail, (i > detail) & (i <= top) & (frac != 0)
            lerp_amp = top_amp + (maxd / scale - top_amp) * amp
            lerp_dist = dist + (np.minimum(dist, od / scale) - dist) * amp
            top_amp = np.where(full, lerp_amp, np.where(part, top_amp + (lerp_amp - top_amp) * frac, top_amp))
            dist = np.where(full, lerp_dist, np.where(part, dist + (np.minimum(dist, lerp_dist) - dist) * frac,
                                                        dist))
            scale = np.where(full, scale * lac, scale)
            amp = np.where(full, amp * rough, amp)
        if normalize:
            dist = dist / top_amp
        return dist.astype(np.float32), None, None, None
    k = np.clip(np.asarray(smoothness, np.float32) / 2, 0, 0.5)
    smooth = feature == "SMOOTH_F1" and np.any(k != 0)
    total = np.zeros(shape, np.float32)
    dist = np.zeros(shape, np.float32)
    color = np.zeros((3, *shape), np.float32)
    pos = [np.zeros(shape, np.float32) for _ in range(d)]
    for i in range(octaves + 1):
        q = [c * scale for c in coords]
        od, oc, op = _octave("F1" if feature == "SMOOTH_F1" else feature, metric, q, exponent, rand, k)
        if smooth:
            sd, sc, sp = _octave("SMOOTH_F1", metric, q, exponent, rand, np.where(k != 0, k, _F(1)))
            use = np.broadcast_to(k != 0, shape)
            od, oc = np.where(use, sd, od), np.where(use, sc, oc)
            op = [np.where(use, a, b) for a, b in zip(sp, op)]
        full, part = i <= detail, (i > detail) & (i <= top) & (frac != 0)
        w = np.where(full, _F(1), np.where(part, frac, _F(0)))
        total = total + w * amp
        dist = dist + w * od * amp
        color = color + w * oc * amp
        pos = [p + w * (o / scale - p) * amp for p, o in zip(pos, op)]
        scale = np.where(full, scale * lac, scale)
        amp = np.where(full, amp * rough, amp)
    if normalize:
        maxd = _max_distance(d, metric, exponent, rand) * (_F(2) if feature == "F2" else _F(1))
        dist = dist / (total * maxd)
        color = color / total
    return dist.astype(np.float32), color.astype(np.float32), [p.astype(np.float32) for p in pos], None
