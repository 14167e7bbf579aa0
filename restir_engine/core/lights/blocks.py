"""Spatially aware light candidates: one light tile per 16 x 16 pixel block, drawn from a distribution that
favours the lights near that block's surfaces (a two-level light hierarchy in the spirit of light trees and of
ReGIR's per-cell reservoirs, Boksansky et al. 2021, evaluated per screen block).

Clusters (built once per light table): surface lights sorted along a Morton curve of their centres and cut into
up to CLUSTERS groups of equal count; each has a bounding box and its share of the power.
Per sample pass and block b (its box = the bounds of the block's primary hits), cluster c has the importance
    I(b, c) = P_c / max(d²(box_b, box_c), s_c²)       (s_c: half the diagonal of the cluster's box)
an upper bound of the irradiance-like falloff with distance; the block picks clusters with
    q_b(c) = (1 - DEFENSIVE) I(b, c) / Σ_c' I(b, c') + DEFENSIVE P_c / Σ P
(positive for every cluster with power: candidates stay unbiased whatever the bound misses) and a light in the
cluster by power. A light point's area pdf in block b is q_b(c) (p_l / p_c) / A_l (p: power fractions).
Each block's tile holds TILE_POINTS points drawn from its own distribution; its pixels draw their candidates
uniformly from the tile (so each candidate is distributed as q_b: RIS stays unbiased, candidates of one block are
correlated as with the plain light tiles). The BSDF candidates' MIS needs the same pdf: :meth:`pdf_area`.
"""
from __future__ import annotations

import warnings

import numpy as np

from ..parallel.pool import in_worker, pool
from .tiles import LightPoints, light_points

CLUSTERS = 1024
BLOCK = 16  # pixels per side of a screen block
DEFENSIVE = 0.1
TILE_POINTS = 256
PARTS = 32  # block ranges built in parallel (a fixed count: images do not depend on threads or processes)


class LightClusters:
    """Surface lights grouped for block importance: ``order`` (n,) lights sorted into clusters, ``start`` (k+1,)
    cluster boundaries in that order, box_min/box_max (3, k), p_cluster (k,) power fractions, ``cluster_of`` (n,),
    ``cum`` (n+1,) the cumulative power fractions along ``order`` (float64)."""

    def __init__(self, lights):
        n = lights.n_tri
        p = lights.tri_alias.pdf.astype(np.float64)
        verts = lights.tri_verts.astype(np.float64)  # (n, 3, 3); spheres: the centre in every corner
        r = lights.sphere_r.astype(np.float64)[:, None]
        lo = verts.min(axis=1) - r
        hi = verts.max(axis=1) + r
        centre = 0.5 * (lo + hi)
        span = np.maximum(centre.max(axis=0) - centre.min(axis=0), 1e-12)
        q = np.clip(((centre - centre.min(axis=0)) / span * 1023).astype(np.int64), 0, 1023)
        self.order = np.argsort(_morton3(q[:, 0], q[:, 1], q[:, 2]), kind="stable")
        k = int(min(CLUSTERS, n))
        self.start = (np.arange(k + 1) * n) // k
        seg = np.repeat(np.arange(k), np.diff(self.start))
        self.cluster_of = np.empty(n, np.int64)
        self.cluster_of[self.order] = seg
        lo_s, hi_s = lo[self.order], hi[self.order]
        self.box_min = np.minimum.reduceat(lo_s, self.start[:-1], axis=0).T
        self.box_max = np.maximum.reduceat(hi_s, self.start[:-1], axis=0).T
        self.p_light = p
        ps = p[self.order]
        self.cum = np.concatenate([[0.0], np.cumsum(ps)])
        self.p_cluster = np.add.reduceat(ps, self.start[:-1])
        half = 0.5 * (self.box_max - self.box_min)
        self.size2 = np.maximum((half * half).sum(axis=0), 1e-12)
        self.count = k


def clusters_of(lights) -> LightClusters:
    """The light table's clusters, built once and kept on the table."""
    c = getattr(lights, "_clusters", None)
    if c is None:
        c = lights._clusters = LightClusters(lights)
    return c


class BlockLightTiles:
    """One tile of light points per 16 x 16 pixel block, each from its block's distribution (module docstring).
    Same interface as light_tiles.LightTiles (points, rows, size, tile_base) plus :meth:`pdf_area`."""

    def __init__(self, lights, positions: np.ndarray, width: int, height: int, rng: np.random.Generator,
                 size: int = TILE_POINTS, team=None):
        """``positions``: (3, height, width) primary-hit positions of the window (NaN where nothing is hit).
        The blocks are processed in PARTS ranges, each with its own random stream: on the thread pool, or by the
        processes of ``team`` (parallel/team.py; each its own ranges, into the team's shared buffers)."""
        cl = clusters_of(lights)
        self.size = int(size)
        self.blocks_x = (width + BLOCK - 1) // BLOCK
        blocks_y = (height + BLOCK - 1) // BLOCK
        bmin, bmax = _block_bounds(positions, self.blocks_x, blocks_y)  # (3, blocks)
        blocks = bmin.shape[1]
        shared = team is not None and team.size > 1
        empty = team.empty if shared else np.empty
        self.q = empty((blocks, cl.count), np.float64)  # (blocks, clusters), rows sum to 1
        self.rows = empty((11, blocks * self.size), np.float32)
        self.lights, self.clusters = lights, cl
        light = empty(blocks * self.size, np.int32)
        bary = empty((2, blocks * self.size), np.float32)
        bounds = np.linspace(0, blocks, PARTS + 1).astype(int)
        seeds = rng.integers(0, 2 ** 63, PARTS)

        def part(k):
            b0, b1 = bounds[k], bounds[k + 1]
            if b1 > b0:
                self._part(b0, b1, bmin[:, b0:b1], bmax[:, b0:b1], np.random.default_rng(seeds[k]), light, bary)

        mine = [k for k in range(PARTS) if not shared or team.owns(k)]
        run = map if in_worker() else pool().map
        list(run(part, mine))
        if shared:
            team.barrier()
        self.points = LightPoints(light, bary[0], bary[1], self.rows[0:3], self.rows[3:6], self.rows[6:9], self.rows[9],
                                  self.rows[10] > 0, lights.spot_lamp_tri(light), block=self.rows)

    def _part(self, b0, b1, bmin, bmax, rng, light_out, bary_out):
        """Blocks b0..b1: their cluster probabilities (rows of ``q``) and tiles (columns of ``rows``)."""
        cl, lights = self.clusters, self.lights
        blocks = b1 - b0
        # squared distance between block and cluster boxes (0 where they overlap), floored by the cluster size
        bmin32, bmax32 = bmin.astype(np.float32), bmax.astype(np.float32)
        cmin, cmax = cl.box_min.astype(np.float32), cl.box_max.astype(np.float32)
        d2 = np.zeros((blocks, cl.count), np.float32)
        for a in range(3):
            g = np.maximum(cmin[a][None, :] - bmax32[a][:, None], bmin32[a][:, None] - cmax[a][None, :])
            np.maximum(g, 0.0, out=g)
            g *= g
            d2 += g
        np.maximum(d2, cl.size2.astype(np.float32)[None, :], out=d2)
        imp = np.divide(cl.p_cluster.astype(np.float32)[None, :], d2, out=d2)
        imp[~np.isfinite(imp)] = 0.0  # blocks without hits: NaN bounds -> power only
        tot = imp.sum(axis=1, keepdims=True, dtype=np.float64)
        has = tot[:, 0] > 0
        q = self.q[b0:b1]
        q[:] = cl.p_cluster[None, :]
        q[has] = (1.0 - DEFENSIVE) * imp[has] / tot[has] + DEFENSIVE * cl.p_cluster[None, :]
        # each block's tile: a cluster by the block's CDF, a light in it by power, a point on the light; the
        # cluster uniforms are sorted within each block, so the search runs over increasing keys
        n = blocks * self.size
        u = rng.random((4, n))
        u[0] = np.sort(u[0].reshape(blocks, self.size), axis=1).ravel()
        cdf = np.cumsum(q, axis=1)
        cdf /= cdf[:, -1:]
        block_of = np.repeat(np.arange(blocks), self.size)
        flat = (cdf + np.arange(blocks)[:, None]).ravel()  # row b shifted by b: one sorted array for all rows
        c = np.searchsorted(flat, u[0] + block_of, side="right") - block_of * cl.count
        c = np.clip(c, 0, cl.count - 1)
        lo, hi = cl.cum[cl.start[c]], cl.cum[cl.start[c + 1]]
        pos = np.searchsorted(cl.cum, lo + u[1] * (hi - lo), side="right") - 1
        pos = np.clip(pos, cl.start[c], cl.start[c + 1] - 1)
        light = cl.order[pos].astype(np.int32)
        b1s, b2s = lights.area_coords(light, u[2].astype(np.float32), u[3].astype(np.float32))
        cols_ = slice(b0 * self.size, b1 * self.size)
        light_points(lights, light, b1s, b2s, out=self.rows[:, cols_])
        self.rows[9, cols_] = self._pdf(lights, cl, light, block_of + b0)
        light_out[cols_] = light
        bary_out[0, cols_], bary_out[1, cols_] = b1s, b2s

    def _pdf(self, lights, cl, light, block) -> np.ndarray:
        c = cl.cluster_of[light]
        p = self.q[block, c] * cl.p_light[light] / np.maximum(cl.p_cluster[c], 1e-300)
        return (p / np.maximum(lights.tri_area[light], 1e-30)).astype(np.float32)

    def block_of(self, px: np.ndarray, py: np.ndarray) -> np.ndarray:
        return (py // BLOCK) * self.blocks_x + px // BLOCK

    def tile_base(self, px: np.ndarray, py: np.ndarray) -> np.ndarray:
        """First point index of the tile serving window pixels (px, py) (integers, window coordinates)."""
        return self.block_of(px, py) * self.size

    def pdf_area(self, light: np.ndarray, px: np.ndarray, py: np.ndarray) -> np.ndarray:
        """Area-measure pdf (n,) with which a light candidate of pixel (px, py) is the point on ``light``."""
        return self._pdf(self.lights, self.clusters, light, self.block_of(px, py))


def _block_bounds(positions: np.ndarray, bx: int, by: int):
    """Per 16 x 16 block of a (3, h, w) position image (NaN = no hit): min and max (3, by * bx) (NaN: no hit)."""
    _, h, w = positions.shape
    pad = np.full((3, by * BLOCK, bx * BLOCK), np.nan, np.float64)
    pad[:, :h, :w] = positions
    blocks = pad.reshape(3, by, BLOCK, bx, BLOCK).transpose(0, 1, 3, 2, 4).reshape(3, by * bx, BLOCK * BLOCK)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN blocks (no hit) give NaN bounds
        return np.nanmin(blocks, axis=2), np.nanmax(blocks, axis=2)


def _morton3(x, y, z) -> np.ndarray:
    """Interleaved bits of three 10-bit integer arrays."""
    def spread(v):
        v = v.astype(np.uint64) & np.uint64(0x3FF)
        v = (v | (v << np.uint64(16))) & np.uint64(0x30000FF)
        v = (v | (v << np.uint64(8))) & np.uint64(0x300F00F)
        v = (v | (v << np.uint64(4))) & np.uint64(0x30C30C3)
        v = (v | (v << np.uint64(2))) & np.uint64(0x9249249)
        return v
    return spread(x) | (spread(y) << np.uint64(1)) | (spread(z) << np.uint64(2))
