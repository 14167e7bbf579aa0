"""The Vector Transform node as a vectorized operation: points, directions and normals between world, object
(each hit's instance) and camera space. Camera space is Cycles': x right, y up, +z forward (Blender's camera looks
down its -z). A normal goes with the inverse transpose of the direction transform and is normalized, as Cycles
normalizes a transformed normal; without an object (the world's shader) object space is world space."""
from __future__ import annotations

import numpy as np

from ...sampling import inverse3
from .ops_math import f32

_FLIP = np.diag([1.0, 1.0, -1.0])  # Blender's camera frame -> Cycles' camera space


def _camera_to_world(params) -> np.ndarray:
    """(3, 4) float64: Cycles' camera space to world."""
    cam = params.get("camera")
    if cam is None:
        return np.hstack([np.eye(3), np.zeros((3, 1))])
    c2w = np.asarray(cam.cam_to_world, np.float64)[:3]
    return np.hstack([c2w[:, :3] @ _FLIP, c2w[:, 3:4]])


def _inverse(m: np.ndarray) -> np.ndarray:
    """Inverse of affine (..., 3, 4) matrices."""
    lin = inverse3(m[..., :3])
    return np.concatenate([lin, -(lin @ m[..., 3:4])], axis=-1)


def _apply(m: np.ndarray, v: np.ndarray, kind: str) -> np.ndarray:
    """(3, n) ``v`` through affine ``m`` ((3, 4), or (n, 3, 4) per column) as a POINT, VECTOR or NORMAL."""
    lin = m[..., :3]
    if kind == "NORMAL":
        lin = np.swapaxes(inverse3(lin), -1, -2)
    if lin.ndim == 2:
        out = lin @ v
        if kind == "POINT":
            out = out + m[:, 3:4]
        return out
    out = np.einsum("nij,jn->in", lin, v)
    if kind == "POINT":
        out = out + m[:, :, 3].T
    return out


def vector_transform(attrs, params, vector):
    """Vector Transform node: ``vector`` (3, n) of type params["type"] from space params["from"] to params["to"]
    (WORLD, OBJECT, CAMERA)."""
    n = len(attrs)
    v = np.broadcast_to(np.asarray(f32(vector), np.float64), (3, n))
    kind, src, dst = params["type"], params["from"], params["to"]
    if src != dst:
        w2o = attrs.world_to_object()
        to_world = {"WORLD": None, "CAMERA": _camera_to_world(params),
                    "OBJECT": None if w2o is None else _inverse(w2o)}
        from_world = {"WORLD": None, "CAMERA": _inverse(_camera_to_world(params)), "OBJECT": w2o}
        if to_world[src] is not None:
            v = _apply(to_world[src], v, kind)
        if from_world[dst] is not None:
            v = _apply(from_world[dst], v, kind)
    if kind == "NORMAL":
        ln = np.sqrt((v * v).sum(axis=0))
        v = v / np.where(ln > 0, ln, 1.0)
    return np.ascontiguousarray(v, dtype=np.float32)


OPERATIONS = {"vector_transform": vector_transform}
#: operations that read the hits: never folded into constants at export
READS_HITS = frozenset({"vector_transform"})
