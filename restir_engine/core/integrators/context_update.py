"""A trace context brought up to date for a scene whose triangles moved in a few rows (objects moved between
animation frames or by a viewport edit), instead of built again.

A scene is an update of the last context's when it holds the same triangles in the same rows (the same count,
materials, instances, UVs, colour attributes and object-space corners) and only positions changed: corners,
shading normals, UV tangents. The rows that changed are found by comparing the arrays. The context's Embree
scene is then split in two (geometry/accel.py SplitAccel): the triangles that did not move, built once, and the
moving rows, rebuilt at each update. The moving set is sticky: while later updates move only rows already in it
(the same objects moving frame after frame, or dragged again in the viewport), only its small Embree scene is
rebuilt; rows outside it join it, paying one build of the still part. The per-triangle arrays (geometric and
shading normals, flatness, each instance's box) are recomputed in the changed rows only; the light table is
rebuilt only when an emissive triangle moved or the scene's bounds changed. Rays find the same nearest
triangles as in a context built from scratch; only ties between coincident triangles may resolve differently.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..geometry.accel import Accel, SplitAccel
from ..lights.table import triangle_geometry
from .trace_context import GeometryDerived, TraceContext, boxes_by_instance, instance_box_table, scene_bounds, scene_lights

MAX_MOVING_SHARE = 0.1  # beyond this share of the triangles in the moving set, a full rebuild is cheaper to trace


def same_layout(a, b) -> bool:
    """Whether TriangleSets ``a`` and ``b`` hold the same triangles in the same rows, positions aside."""
    if len(a) != len(b) or (a.tangents is None) != (b.tangents is None):
        return False
    for name in ("material", "instance", "uvs", "local_verts"):
        x, y = getattr(a, name), getattr(b, name)
        if (x is None) != (y is None) or (x is not None and x is not y and not np.array_equal(x, y)):
            return False
    ax, bx = a.attributes or {}, b.attributes or {}
    if ax.keys() != bx.keys() or not all(ax[k] is bx[k] or np.array_equal(ax[k], bx[k]) for k in ax):
        return False
    oa, ob = a.objects, b.objects
    if (oa is None) != (ob is None):
        return False
    if oa is None or oa is ob:
        return True
    # what node programs and passes read of the objects, their placement (world_to_object, location) aside
    return all(np.array_equal(np.asarray(getattr(oa, f.name)), np.asarray(getattr(ob, f.name)))
               for f in dataclasses.fields(oa) if f.name not in ("world_to_object", "location"))


def changed_rows(a, b) -> np.ndarray:
    """(k,) int64: the rows where ``b``'s corners, shading normals or tangents differ from ``a``'s."""
    n = len(a)
    diff = (a.verts != b.verts).reshape(n, 9).any(axis=1)
    diff |= (a.normals != b.normals).reshape(n, 9).any(axis=1)
    if a.tangents is not None:
        diff |= (a.tangents != b.tangents).reshape(n, -1).any(axis=1)
    return np.flatnonzero(diff)


def updated_context(last: TraceContext, scene, rows: np.ndarray, max_bounces: int,
                    film_transparent: bool) -> TraceContext | None:
    """``last`` for ``scene`` (same layout, materials, lamps and world; the rows ``rows`` moved), or None where
    a context built from scratch is the better choice (too many rows would move)."""
    geom = scene.geometry
    n = len(geom)
    old = last.geom_accel
    split = isinstance(old, SplitAccel)
    if split and np.isin(rows, old.moving_rows, assume_unique=True).all():
        moving = old.moving_rows
        still, still_rows = old.still_part()
    else:
        moving = np.union1d(rows, old.moving_rows) if split else rows
        if len(moving) > MAX_MOVING_SHARE * n:
            return None
        keep = np.ones(n, bool)
        keep[moving] = False
        still_rows = np.flatnonzero(keep)
        still = Accel(geom.verts[still_rows])
    derived = updated_derived(last.geom_derived, geom, rows)
    cut = old.cutout
    cut = None if cut is None else cut.with_geometry(geom)
    accel = SplitAccel(still, still_rows, geom.verts[moving], moving, cut, derived.ng_rows if cut else None)
    lights, emit_accel = moved_lights(last, scene, rows, derived)
    return dataclasses.replace(last, scene=scene, geom_accel=accel, lights=lights, emit_accel=emit_accel,
                               geom_ng=derived.ng, geom_ng_rows=derived.ng_rows, geom_normal_rows=derived.normal_rows,
                               geom_flat=derived.flat, geom_derived=derived, max_bounces=int(max(0, max_bounces)),
                               film_transparent=film_transparent, measured={})


def moved_lights(last: TraceContext, scene, rows: np.ndarray, derived: GeometryDerived) -> tuple:
    """(light table, emissive triangles' Accel) of ``scene``, ``last``'s scene with the rows ``rows`` moved
    (``derived``: its GeometryDerived): ``last``'s, unless an emissive triangle moved or the scene's bounds changed
    (the light table's scene radius and the world's sphere follow them): then built again."""
    lights, emit_accel = last.lights, last.emit_accel
    emitter_moved = bool(lights.n_geom) and bool((lights.geom_to_light[rows] >= 0).any())
    new_box, old_box = scene_bounds(scene, derived.bounds), scene_bounds(last.scene, last.geom_derived.bounds)
    if emitter_moved or not (np.array_equal(new_box[0], old_box[0]) and np.array_equal(new_box[1], old_box[1])):
        lights = scene_lights(scene, derived.bounds, last.world)
        emit_accel = Accel(lights.tri_verts[:lights.n_geom]) if lights.n_geom else None
    return lights, emit_accel


def updated_derived(base: GeometryDerived, geom, rows: np.ndarray, into: GeometryDerived | None = None
                    ) -> GeometryDerived:
    """``base`` (GeometryDerived.of an earlier geometry of the same layout) for ``geom``, where only the rows
    ``rows`` changed: equal to ``GeometryDerived.of(geom)``. ``into``: an earlier result of this call with the same
    ``base`` and ``rows``, whose per-triangle arrays are overwritten in those rows (it is not to be used after)."""
    if into is None:
        ng, ng_rows = base.ng.copy(), base.ng_rows.copy()
        normal_rows, flat = base.normal_rows.copy(), base.flat.copy()
    else:
        ng, ng_rows, normal_rows, flat = into.ng, into.ng_rows, into.normal_rows, into.flat
    if rows.size:
        ng[rows], _ = triangle_geometry(geom.verts[rows])
        ng_rows[:, rows] = ng[rows].T
        nrm = geom.normals[rows]
        normal_rows[:, rows] = nrm.reshape(len(rows), 9).T
        flat[rows] = (nrm[:, 0] == nrm[:, 1]).all(axis=1) & (nrm[:, 0] == nrm[:, 2]).all(axis=1)
    ids, lo, hi = _updated_boxes(base, geom, rows)
    if ids is None:  # one box (no instances): the scene's bounds, over every vertex
        verts = geom.verts.reshape(-1, 3)
        finite = verts[np.isfinite(verts).all(axis=1)]
        bounds = (finite.min(0), finite.max(0)) if len(finite) else None
        _ids, lo, hi = instance_box_table(geom, bounds)
        return GeometryDerived(bounds, ng, ng_rows, flat, normal_rows, (lo, hi), _ids)
    bounds = (lo.min(axis=0), hi.max(axis=0)) if len(lo) else None
    return GeometryDerived(bounds, ng, ng_rows, flat, normal_rows, (lo, hi), ids)


def _updated_boxes(base: GeometryDerived, geom, rows: np.ndarray) -> tuple:
    """(ids, lo, hi) of :func:`instance_box_table` for ``geom``, recomputing only the instances with a changed
    row; (None, None, None) without instances (one box: the caller recomputes the bounds)."""
    inst = geom.instance
    if base.box_ids is None or inst is None:
        return None, None, None
    if not rows.size:
        return base.box_ids, base.boxes[0], base.boxes[1]
    touched = np.unique(inst[rows])
    mask = np.isin(inst, touched)
    t_ids, t_lo, t_hi = boxes_by_instance(geom.verts[mask], inst[mask])
    keep = ~np.isin(base.box_ids, touched)
    ids = np.concatenate([base.box_ids[keep], t_ids])
    order = np.argsort(ids, kind="stable")
    lo = np.concatenate([base.boxes[0][keep], t_lo])[order]
    hi = np.concatenate([base.boxes[1][keep], t_hi])[order]
    return ids[order], lo, hi
