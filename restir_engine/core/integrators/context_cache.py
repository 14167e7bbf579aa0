"""Reuse of the acceleration structures and light table between frames whose scene content is unchanged.

Every frame of an animation exports a fresh core Scene; when its geometry, materials, lamps and world are
bit-identical to the previous frame's (a static scene seen by a moving camera, or only objects that do not
move), the Embree scenes and the light table built for that frame are reused instead of rebuilt. Materials,
lamps and the world are compared by a BLAKE2b digest of their arrays (about 0.1 s per 100 MB); the triangles by
comparing their arrays with the last frame's. Where only some rows' positions changed (objects moved), the last
context is updated (context_update.py); any other change rebuilds (the geometry's digest then decides whether the
Embree scenes can be handed over). One entry is kept (the last frame's), shared by renders and the viewport.
"""
from __future__ import annotations

import dataclasses
import hashlib
import threading
from typing import NamedTuple

import numpy as np

from .context_update import changed_rows, same_layout, updated_context

_LOCK = threading.Lock()
_LAST = None  # _Last: the last frame's context


def fingerprint(*parts) -> bytes:
    """A digest of nested dataclasses / arrays / lists / scalars (array dtype, shape and bytes)."""
    h = hashlib.blake2b(digest_size=20)

    def walk(x):
        if isinstance(x, np.ndarray):
            h.update(f"{type(x).__name__}{x.dtype}{x.shape}".encode())
            h.update(np.ascontiguousarray(x).data)
        elif dataclasses.is_dataclass(x) and not isinstance(x, type):
            h.update(type(x).__name__.encode())
            for f in dataclasses.fields(x):
                walk(getattr(x, f.name))
        elif isinstance(x, (list, tuple)):
            h.update(b"[")
            for item in x:
                walk(item)
            h.update(b"]")
        elif isinstance(x, dict):
            for k in sorted(x, key=repr):
                h.update(repr(k).encode())
                walk(x[k])
        else:
            h.update(repr(x).encode())

    for p in parts:
        walk(p)
    return h.digest()


def rest_key(scene) -> bytes:
    """What the context depends on besides the triangles: materials, lamps, the world."""
    return fingerprint(scene.materials, scene.lamps, scene.world_radiance, getattr(scene, "world_image", None),
                       getattr(scene, "world_rotation", None), (getattr(scene, "world_camera_view", None) or ())[:2])


def context_for(scene, max_bounces: int, film_transparent: bool, build):
    """(TraceContext, reused) for ``scene``: the last one with ``scene`` swapped in when the scene's content
    is unchanged; the last one updated where only objects moved (context_update.py); else
    ``build(scene, max_bounces, film_transparent, accels=...)`` (which then becomes the last one); ``accels`` hands
    over the last context's Embree scenes whose triangles are unchanged (an edit of materials, lamp power or the
    world rebuilds the tables, not the acceleration structures)."""
    global _LAST
    with _LOCK:
        last = _LAST
    others = rest_key(scene)
    if last is not None and last.others == others:
        ctx, reused = _same_or_moved(last, scene, max_bounces, film_transparent)
        if ctx is not None:
            if not reused:
                with _LOCK:
                    _LAST = _Last(ctx, None, last.lamp_key, others)
            return ctx, reused
    # the same TriangleSet object as the last context's is the same triangles (an exported scene's arrays are
    # never modified; the viewport's edits of materials or lamps hand the previous geometry on): no hashing
    same_geometry = last is not None and last.ctx.scene.geometry is scene.geometry
    geom_key = last.geom_key if same_geometry and last.geom_key is not None else fingerprint(scene.geometry)
    lamp_key = fingerprint(scene.lamps.tris.verts)
    accels = {}
    if last is not None:
        if same_geometry or last.geom_key == geom_key:
            accels["geom"], accels["derived"] = last.ctx.geom_accel, last.ctx.geom_derived
        if last.lamp_key == lamp_key:
            accels["lamp"] = last.ctx.lamp_accel
    ctx = build(scene, max_bounces, film_transparent, accels=accels)
    with _LOCK:
        _LAST = _Last(ctx, geom_key, lamp_key, others)
    return ctx, False


def _same_or_moved(last: "_Last", scene, max_bounces: int, film_transparent: bool):
    """(context, reused) for ``scene`` (same materials, lamps and world as the last one): the last context as it is
    where the triangles are the same (reused), updated where only positions changed in a few rows
    (context_update.py; not reused); (None, False) where the triangles changed otherwise."""
    old = last.ctx.scene.geometry
    geom = scene.geometry
    if old is not geom and not same_layout(old, geom):
        return None, False
    rows = None if old is geom else changed_rows(old, geom)
    if rows is None or rows.size == 0:
        return dataclasses.replace(last.ctx, scene=scene, max_bounces=int(max(0, max_bounces)),
                                   film_transparent=film_transparent), True
    return updated_context(last.ctx, scene, rows, max_bounces, film_transparent), False


class _Last(NamedTuple):
    """The kept context and the fingerprints it was built for (geom_key None: not computed, an updated one)."""

    ctx: object
    geom_key: bytes | None
    lamp_key: bytes
    others: bytes


def clear() -> None:
    """Forget the kept context (frees its acceleration structures)."""
    global _LAST
    with _LOCK:
        _LAST = None
