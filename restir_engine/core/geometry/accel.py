"""Embree ray queries over structure-of-arrays rays, chunked across a thread pool.

``embreex``'s ``EmbreeScene.run`` is a single-threaded loop over rtcIntersect1/rtcOccluded1
that releases the GIL, so chunks of rays run concurrently on the shared thread pool (core/parallel/pool.py).
``tnear`` is fixed at 0 by embreex: callers must offset origins (see :func:`offset_origin`).
Rays are (3, n) rows like every vector of the core; each call transposes them into the (n, 3) arrays
``EmbreeScene.run`` reads.
"""
from __future__ import annotations

import time

import numpy as np

from ..parallel.pool import run_chunks
from ..profile import add_embree_seconds
from ..sampling import cols, dot, norm, vmax

CHUNK_RAYS = 32768  # rays per Embree call: large enough to amortize the call, small for load balance
MAX_CUTOUT_LAYERS = 32  # transparent cut-out points one ray passes at most (the next hit then counts as opaque)

def offset_origin(p: np.ndarray, ng: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Move points p (3, n) off their surface along the geometric normal ng (3, n), to the side ``direction``
    (3, n) leaves by. The offset scales with the coordinate magnitude (float32 spacing), so it works at any
    scene scale."""
    side = np.where(dot(ng, direction) >= 0.0, np.float32(1.0), np.float32(-1.0))
    mag = np.maximum(vmax(np.abs(p)), np.float32(1.0))
    return (p + ng * (side * mag * np.float32(1e-4))).astype(np.float32, copy=False)


def shadow_rays(p: np.ndarray, ng: np.ndarray, light_pos: np.ndarray, wi: np.ndarray, dist: np.ndarray):
    """Origins (3, n), unit directions (3, n) and tmax (n,) of shadow rays from surface points p towards light
    points.

    The direction and length are recomputed from the *offset* origin: at grazing angles the offset
    along the normal changes the distance to the light's plane by far more than any epsilon, so a
    tmax taken before the offset would stop short of (or pass) the light. Points with an infinite
    ``dist`` (distant lights) keep ``wi`` and get tmax = 1e30.
    """
    o = offset_origin(p, ng, wi)
    finite = np.isfinite(dist)
    if finite.all():
        d = light_pos - o
        ln = norm(d)
        d /= np.maximum(ln, np.float32(1e-30))
        return o, d.astype(np.float32, copy=False), (ln * np.float32(1.0 - 1e-4)).astype(np.float32, copy=False)
    d = np.where(finite, light_pos - o, wi)
    ln = norm(d)
    d = d / np.maximum(ln, 1e-30)
    far = np.where(finite, ln * (1.0 - 1e-4), 1e30)
    return o, d.astype(np.float32), far.astype(np.float32)


class Hits:
    """Closest-hit results, SoA: prim (int32, -1 = miss), t (float32 distance), u, v (barycentrics); ``tint``
    (3, n) float32, the product of the transparent tints of the cut-out points each ray passed on its way (None:
    white for every ray)."""

    __slots__ = ("prim", "t", "u", "v", "tint")

    def __init__(self, n: int):
        self.prim = np.full(n, -1, dtype=np.int32)
        self.t = np.full(n, np.inf, dtype=np.float32)
        self.u = np.zeros(n, dtype=np.float32)
        self.v = np.zeros(n, dtype=np.float32)
        self.tint = None

    def take(self, rows) -> "Hits":
        out = Hits.__new__(Hits)
        out.prim, out.t, out.u, out.v = self.prim[rows], self.t[rows], self.u[rows], self.v[rows]
        out.tint = None if self.tint is None else self.tint[:, rows]
        return out

    def put(self, rows, other: "Hits") -> None:
        """Write ``other`` (len(rows) hits) into rows ``rows``."""
        self.prim[rows], self.t[rows], self.u[rows], self.v[rows] = other.prim, other.t, other.u, other.v
        if other.tint is not None:
            if self.tint is None:
                self.tint = np.ones((3, len(self.prim)), np.float32)
            self.tint[:, rows] = other.tint


class Accel:
    """A static triangle scene. ``triangles`` is (n, 3, 3) float32 world-space vertices. With ``cutout`` (a
    cutout.Cutout) rays pass through the transparent points of cut-out surfaces (``ng_rows``: the triangles'
    geometric normals (3, n), to step past them)."""

    def __init__(self, triangles: np.ndarray, cutout=None, ng_rows: np.ndarray | None = None):
        self.n_triangles = len(triangles)
        self.cutout = cutout
        self._ng_rows = ng_rows
        self._scene = None
        if self.n_triangles:
            from embreex import rtcore_scene
            from embreex.mesh_construction import TriangleMesh
            self._scene = rtcore_scene.EmbreeScene()
            self._mesh = TriangleMesh(self._scene, np.ascontiguousarray(triangles, dtype=np.float32))

    def with_cutout(self, cutout=None, ng_rows: np.ndarray | None = None) -> "Accel":
        """The same Embree scene (not rebuilt) with other cut-out materials: for a scene whose triangles are
        unchanged and whose materials were edited."""
        out = Accel.__new__(Accel)
        out.__dict__.update(self.__dict__)
        out.cutout, out._ng_rows = cutout, ng_rows
        return out

    # -- chunked execution -------------------------------------------------------------
    def _chunks(self, n: int):
        return [(s, min(n, s + CHUNK_RAYS)) for s in range(0, n, CHUNK_RAYS)]

    def intersect(self, origins: np.ndarray, directions: np.ndarray, tmax: np.ndarray | None = None,
                  shadow: bool = False, camera: bool = False) -> Hits:
        """Closest hit of each ray (origins/directions (3, n) float32 rows; directions need not be unit,
        ``t`` is then in units of the direction length), through transparent cut-out points (for ``shadow``
        rays only those of materials with transparent shadows) and, for ``camera`` rays, through objects the
        camera does not see."""
        hits = self._intersect(origins, directions, tmax)
        if self.cutout is not None:
            self._pass_through(hits, origins, directions, tmax, shadow, camera)
        return hits

    def _pass_through(self, hits: Hits, o: np.ndarray, d: np.ndarray, tmax, shadow: bool = False,
                      camera: bool = False) -> None:
        """Replace hits on transparent cut-out points by what lies behind them (in place; t stays measured from
        the original origins)."""
        for _layer in range(MAX_CUTOUT_LAYERS):
            live = np.flatnonzero(hits.prim >= 0)
            if live.size == 0:
                return
            go = live[~self.cutout.opaque(hits.prim[live], hits.u[live], hits.v[live], cols(d, live), shadow,
                                          camera)]
            if go.size == 0:
                return
            if self.cutout.tinted:
                if hits.tint is None:
                    hits.tint = np.ones((3, len(hits.prim)), np.float32)
                hits.tint[:, go] *= self.cutout.tint(hits.prim[go], hits.u[go], hits.v[go], cols(d, go), shadow,
                                                     camera)
            t = hits.t[go]
            dg = cols(d, go)
            p = cols(o, go) + dg * t
            o2 = offset_origin(p, cols(self._ng_rows, hits.prim[go]), dg)
            far = None if tmax is None else np.maximum(tmax[go] - t, np.float32(0.0))
            sub = self._intersect(o2, dg, far)
            hit = sub.prim >= 0
            hits.prim[go] = sub.prim
            # t from the original origin: the offset of o2 along the ray counted, then the point o + d t put on the
            # hit triangle's plane (the offset's part across the ray would leave it up to the offset's size off
            # the surface, on either side, where a shadow ray's own offset could not clear it)
            along = dot(o2 - p, dg) / np.maximum(dot(dg, dg), np.float32(1e-30))
            t_hit = np.where(hit, sub.t + t + along, np.inf)
            on = np.flatnonzero(hit)
            if on.size:
                t_hit[on] = self._on_plane(sub.prim[on], cols(o, go[on]), cols(dg, on), t_hit[on])
            hits.t[go] = t_hit
            hits.u[go] = sub.u
            hits.v[go] = sub.v

    def _on_plane(self, prim: np.ndarray, o: np.ndarray, d: np.ndarray, t: np.ndarray) -> np.ndarray:
        """``t`` (n,) of rays o + d t near triangles ``prim`` moved to where each ray meets its triangle's plane
        (float64), where the ray is not grazing that plane and the move is within a few offsets; else kept."""
        ng = cols(self._ng_rows, prim).astype(np.float64)
        v0 = self.cutout.geometry.verts[prim, 0].T.astype(np.float64)
        d64 = d.astype(np.float64)
        den = (d64 * ng).sum(axis=0)
        dn = np.sqrt((d64 * d64).sum(axis=0))
        ok = np.abs(den) > 1e-3 * dn
        tp = ((v0 - o.astype(np.float64)) * ng).sum(axis=0) / np.where(ok, den, 1.0)
        mag = np.maximum(np.abs(o).max(axis=0), np.abs(v0).max(axis=0))
        near = np.abs(tp - t) * dn < 1e-2 * np.maximum(mag, 1.0)
        return np.where(ok & near & (tp > 0), tp, t).astype(np.float32)

    def _intersect(self, origins: np.ndarray, directions: np.ndarray, tmax: np.ndarray | None = None) -> Hits:
        n = origins.shape[1]
        hits = Hits(n)
        if self._scene is None or n == 0:
            return hits
        o = np.ascontiguousarray(origins.T, dtype=np.float32)  # Embree reads (n, 3) rays
        d = np.ascontiguousarray(directions.T, dtype=np.float32)
        far = None if tmax is None else np.ascontiguousarray(tmax, dtype=np.float32)

        def work(span):
            s, e = span
            t0 = time.perf_counter()
            r = self._scene.run(o[s:e], d[s:e], dists=None if far is None else far[s:e].copy(), output=1)
            add_embree_seconds(time.perf_counter() - t0)
            prim = r["primID"]
            hits.prim[s:e] = prim
            hit = prim >= 0
            hits.t[s:e] = np.where(hit, r["tfar"], np.inf)
            hits.u[s:e] = r["u"]
            hits.v[s:e] = r["v"]

        run_chunks(work, self._chunks(n))
        return hits

    def occluded(self, origins: np.ndarray, directions: np.ndarray, tmax: np.ndarray, shadow: bool = True
                 ) -> np.ndarray:
        """True where something opaque lies on the segment origin + t*direction, 0 < t < tmax (rays as (3, n)
        rows). Blocked rays are traced again through cut-out points when there are any, as shadow rays pass them
        (``shadow``) or as rays that bounce off surfaces do (not ``shadow``: see :meth:`intersect`)."""
        out = self._occluded(origins, directions, tmax)
        if self.cutout is not None:
            rows = np.flatnonzero(out)
            if rows.size:
                far = np.ascontiguousarray(tmax, dtype=np.float32)[rows]
                out[rows] = self.intersect(cols(origins, rows), cols(directions, rows), far,
                                           shadow=shadow).prim >= 0
        return out

    @property
    def tinted(self) -> bool:
        """Whether rays passing cut-out points may change colour (then shadow rays need :meth:`transmittance`)."""
        return self.cutout is not None and self.cutout.tinted

    def passed(self, origins: np.ndarray, directions: np.ndarray, tmax: np.ndarray, bounce=None):
        """(the indices of the shadow rays that reach their end, their transmittance (3, k) or None where no cut-out
        tints light): :meth:`occluded` and :meth:`transmittance` in one, for light to be scaled by what passes.
        ``bounce`` (n,) bool or None: the rays that stand for light Cycles gathers with rays bouncing off the
        surface rather than with shadow rays (a constant world: lights.world.World.lit_by_bounces); they pass
        cut-outs as such rays do (not ``shadow`` in :meth:`intersect`)."""
        if bounce is not None and self.cutout is not None and np.any(bounce):
            sets = [np.flatnonzero(~bounce), np.flatnonzero(bounce)]
            got = [self._passed(cols(origins, r), cols(directions, r), np.asarray(tmax)[r], shadow=k == 0)
                   for k, r in enumerate(sets)]
            keep = np.concatenate([r[kept] for r, (kept, _tr) in zip(sets, got)])
            order = np.argsort(keep, kind="stable")
            if all(tr is None for _k, tr in got):
                return keep[order], None
            tr = np.concatenate([np.ones((3, len(k)), np.float32) if t is None else t for k, t in got], axis=1)
            return keep[order], tr[:, order]
        return self._passed(origins, directions, tmax, True)

    def _passed(self, origins, directions, tmax, shadow: bool):
        if not self.tinted:
            return np.flatnonzero(~self.occluded(origins, directions, tmax, shadow)), None
        tr = self.transmittance(origins, directions, tmax, shadow)
        keep = np.flatnonzero(vmax(tr) > 0)
        return keep, tr[:, keep]

    def transmittance(self, origins: np.ndarray, directions: np.ndarray, tmax: np.ndarray, shadow: bool = True
                      ) -> np.ndarray:
        """(3, n) float32: the light the segments origin + t*direction, 0 < t < tmax, let through: 0 where
        something opaque lies on them, else the product of the transparent tints of the cut-out points they pass
        (1 without any), passed as shadow rays pass them (``shadow``) or as bouncing rays do."""
        blocked = self._occluded(origins, directions, tmax)
        out = np.ones((3, len(blocked)), np.float32)
        rows = np.flatnonzero(blocked)
        if rows.size:
            far = np.ascontiguousarray(tmax, dtype=np.float32)[rows]
            if self.cutout is None:
                out[:, rows] = 0.0
                return out
            hits = self.intersect(cols(origins, rows), cols(directions, rows), far, shadow=shadow)
            if hits.tint is not None:
                out[:, rows] = hits.tint
            out[:, rows[hits.prim >= 0]] = 0.0
        return out

    def _occluded(self, origins: np.ndarray, directions: np.ndarray, tmax: np.ndarray) -> np.ndarray:
        n = origins.shape[1]
        out = np.zeros(n, dtype=bool)
        if self._scene is None or n == 0:
            return out
        o = np.ascontiguousarray(origins.T, dtype=np.float32)
        d = np.ascontiguousarray(directions.T, dtype=np.float32)
        far = np.ascontiguousarray(tmax, dtype=np.float32)

        def work(span):
            s, e = span
            t0 = time.perf_counter()
            out[s:e] = self._scene.run(o[s:e], d[s:e], dists=far[s:e].copy(), query="OCCLUDED") >= 0
            add_embree_seconds(time.perf_counter() - t0)

        run_chunks(work, self._chunks(n))
        return out


class SplitAccel(Accel):
    """The triangles of one scene in two Embree scenes: ``still`` (an Accel over the rows ``still_rows``, built once)
    and the rows ``moving_rows`` whose corners change (``moving_triangles`` (m, 3, 3), rebuilt for each pose), so
    that a moving object costs the build of its own triangles only. Primitive indices are the scene's rows."""

    def __init__(self, still: Accel, still_rows: np.ndarray, moving_triangles: np.ndarray, moving_rows: np.ndarray,
                 cutout=None, ng_rows: np.ndarray | None = None):
        self.n_triangles = still.n_triangles + len(moving_rows)
        self.cutout, self._ng_rows = cutout, ng_rows
        self.still, self.still_rows = still, np.asarray(still_rows, np.int32)
        self.moving, self.moving_rows = Accel(moving_triangles), np.asarray(moving_rows, np.int32)
        self._scene = self.still._scene if self.still._scene is not None else self.moving._scene

    def still_part(self) -> tuple:
        """(the Accel of the unmoved rows, those rows): to share with the next pose's SplitAccel."""
        return self.still, self.still_rows

    def _intersect(self, origins: np.ndarray, directions: np.ndarray, tmax: np.ndarray | None = None) -> Hits:
        a = self.still._intersect(origins, directions, tmax)
        b = self.moving._intersect(origins, directions, tmax)
        hit_a = a.prim >= 0
        a.prim[hit_a] = self.still_rows[a.prim[hit_a]]
        nearer = (b.prim >= 0) & (b.t < a.t)
        a.prim[nearer] = self.moving_rows[b.prim[nearer]]
        a.t[nearer], a.u[nearer], a.v[nearer] = b.t[nearer], b.u[nearer], b.v[nearer]
        return a

    def _occluded(self, origins: np.ndarray, directions: np.ndarray, tmax: np.ndarray) -> np.ndarray:
        out = self.still._occluded(origins, directions, tmax)
        rest = np.flatnonzero(~out)
        if rest.size:
            out[rest] = self.moving._occluded(cols(origins, rest), cols(directions, rest), tmax[rest])
        return out
