"""Reuse of the acceleration structures and light table between frames whose scene content is unchanged.

Every frame of an animation exports a fresh core Scene; when its geometry, materials, lamps and world are
bit-identical to the previous frame's (a static scene seen by a moving camera, or only objects that do not
move), the Embree scenes and the light table built for that frame are reused instead of rebuilt. The
fingerprint is a BLAKE2b digest of every array of those parts (about 0.1 s per 100 MB of scene data), so
any change, however small, rebuilds. One entry is kept (the last frame's), shared by renders and the
viewport.
"""
from __future__ import annotations

import dataclasses
import hashlib
import threading

import numpy as np

_LOCK = threading.Lock()
_LAST: tuple | None = None  # (fingerprint, TraceContext, geometry's fingerprint, lamp triangles' fingerprint)


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


def scene_key(scene, geometry_key: bytes | None = None) -> bytes:
    """What the acceleration structures and the light table depend on (not the camera or the motion)."""
    return fingerprint(geometry_key if geometry_key is not None else fingerprint(scene.geometry), scene.materials,
                       scene.lamps, scene.world_radiance, getattr(scene, "world_image", None),
                       getattr(scene, "world_rotation", None))


def context_for(scene, max_bounces: int, film_transparent: bool, build):
    """(TraceContext, reused) for ``scene``: the last one with ``scene`` swapped in when the scene's content
    is unchanged, else ``build(scene, max_bounces, film_transparent, accels=...)`` (which then becomes the last
    one); ``accels`` hands over the last context's Embree scenes whose triangles are unchanged (an edit of
    materials, lamp power or the world rebuilds the tables, not the acceleration structures)."""
    global _LAST
    with _LOCK:
        last = _LAST
    # the same TriangleSet object as the last context's is the same triangles (an exported scene's arrays are
    # never modified; the viewport's edits of materials or lamps hand the previous geometry on): no hashing
    same_geometry = last is not None and last[1].scene.geometry is scene.geometry
    geom_key = last[2] if same_geometry else fingerprint(scene.geometry)
    key = scene_key(scene, geom_key)
    if last is not None and last[0] == key:
        ctx = dataclasses.replace(last[1], scene=scene, max_bounces=int(max(0, max_bounces)),
                                  film_transparent=film_transparent)
        return ctx, True
    lamp_key = fingerprint(scene.lamps.tris.verts)
    accels = {}
    if last is not None:
        if last[2] == geom_key:
            accels["geom"], accels["derived"] = last[1].geom_accel, last[1].geom_derived
        if last[3] == lamp_key:
            accels["lamp"] = last[1].lamp_accel
    ctx = build(scene, max_bounces, film_transparent, accels=accels)
    with _LOCK:
        _LAST = (key, ctx, geom_key, lamp_key)
    return ctx, False


def clear() -> None:
    """Forget the kept context (frees its acceleration structures)."""
    global _LAST
    with _LOCK:
        _LAST = None
