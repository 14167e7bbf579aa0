"""Point cloud objects -> local-space triangle arrays: each point a sphere of its radius, as Cycles renders point
clouds, tessellated into a subdivided icosahedron (20, 80 or 320 triangles, fewer for larger clouds) with radial
(smooth) normals. The polyhedron is scaled so that its surface area, and so its mean projected area, is the sphere's:
a point covers as many pixels on average as Cycles' exact sphere. No Python loop over points."""
from __future__ import annotations

import functools

import numpy as np

#: points up to which a cloud gets 320, then 80, then 20 triangles per point
DETAIL_LIMITS = ((5_000, 2), (50_000, 1))


@functools.lru_cache(maxsize=4)
def unit_sphere(level: int) -> np.ndarray:
    """(f, 3, 3) float64 triangle corners of the icosahedron subdivided ``level`` times, on the unit sphere,
    outward winding, scaled by √(4π / area) (its area is the unit sphere's)."""
    t = (1 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
         (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6),
         (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10),
         (8, 6, 7), (9, 8, 1)]
    tris = np.array(v, np.float64)[np.array(f)]
    tris /= np.linalg.norm(tris, axis=2, keepdims=True)
    for _ in range(level):  # each triangle into four, the new corners pushed onto the sphere
        a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
        ab, bc, ca = (a + b), (b + c), (c + a)
        for m in (ab, bc, ca):
            m /= np.linalg.norm(m, axis=1, keepdims=True)
        tris = np.concatenate([np.stack(s, axis=1) for s in ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))])
    area = 0.5 * np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1).sum()
    return tris * np.sqrt(4 * np.pi / area)


def detail_level(points: int) -> int:
    return next((level for limit, level in DETAIL_LIMITS if points <= limit), 0)


def read_points(cloud) -> dict | None:
    """The arrays export/meshes.py reads from a mesh (verts, normals (t, 3, 3), slot (t,), no UVs or tangents,
    texspace) for a PointCloud datablock: points of radius ≤ 0 are left out; None when none is left."""
    n = len(cloud.points)
    if n == 0:
        return None
    co = np.empty(n * 3, np.float32)
    cloud.points.foreach_get("co", co)
    radius = np.empty(n, np.float32)
    cloud.points.foreach_get("radius", radius)
    slot = np.zeros(n, np.int32)
    attr = cloud.attributes.get("material_index")
    if attr is not None and attr.domain == "POINT" and attr.data_type == "INT":
        attr.data.foreach_get("value", slot)
    keep = np.isfinite(radius) & (radius > 0)
    co, radius, slot = co.reshape(n, 3)[keep], radius[keep], slot[keep]
    if not len(co):
        return None
    shape = unit_sphere(detail_level(len(co))).astype(np.float32)  # (f, 3, 3)
    f = len(shape)
    verts = (co[:, None, None, :] + radius[:, None, None, None] * shape[None]).reshape(-1, 3, 3)
    normals = np.broadcast_to(shape / np.linalg.norm(shape, axis=2, keepdims=True), (len(co), f, 3, 3))
    lo, hi = (co - radius[:, None]).min(0), (co + radius[:, None]).max(0)
    half = np.maximum((hi - lo) / 2, 1e-5)
    return {"verts": verts, "normals": np.ascontiguousarray(normals.reshape(-1, 3, 3)), "uvs": None,
            "slot": np.repeat(slot, f), "tangents": None, "attributes": {},
            "texspace": (((lo + hi) / 2 - half).astype(np.float32), (2 * half).astype(np.float32)),
            "triangles_per_point": f}
