"""Attributes Cycles derives from a mesh's shape for the Geometry node: Pointiness and Random Per Island (per
vertex).

Pointiness, as Cycles defines it: vertices at the same position are welded; each welded vertex's normal is the
normalized sum of its copies' normals; its raw value is the angle (over pi) between that normal and the mean unit
direction of its edges, so a flat vertex reads 0.5, a convex one more and a concave one less; the value is then
averaged with its edge neighbours' raw values (a two-ring blur). Computed in object space on the evaluated mesh's
edges (not the triangulation's), so an instance's transform does not change it.

Random Per Island, as Cycles defines it: the mesh's vertices are joined along its edges, in edge order, by a
union-find with union by rank (ties keep the first vertex's root); an island's value is Cycles' lookup3 hash of its
root vertex's index, as a float in [0, 1]. Which vertex ends up the root depends on that sequence of joins, so it is
replayed exactly: a sequential loop over the edges, run at export only for meshes whose materials read it."""
from __future__ import annotations

import numpy as np

from ..core.materials.nodes.hashing import hash_uint, to_unit

POINTINESS = "@pointiness"  # attribute names the node programs read ("attr_alpha:@pointiness")
RANDOM_PER_ISLAND = "@random_per_island"
DERIVED = (POINTINESS, RANDOM_PER_ISLAND)


def _welded(co: np.ndarray) -> tuple:
    """(group (nv,) int, groups): each vertex's weld group, vertices at exactly the same position sharing one."""
    _uniq, group = np.unique(co, axis=0, return_inverse=True)
    return group.reshape(-1), len(_uniq)


def pointiness(co: np.ndarray, normals: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """(nv,) float32 pointiness of vertices ``co`` (nv, 3) with vertex normals ``normals`` (nv, 3) and
    ``edges`` (ne, 2) vertex indices; 0 for a vertex without edges (before the blur)."""
    co = np.asarray(co, np.float32).reshape(-1, 3)
    nv = len(co)
    if nv == 0:
        return np.zeros(0, np.float32)
    group, ng = _welded(co)
    first = np.full(ng, nv, np.int64)
    np.minimum.at(first, group, np.arange(nv))
    gco = co[first]
    gn = np.zeros((ng, 3), np.float32)
    for k in range(3):  # per axis, vectorized over vertices
        gn[:, k] = np.bincount(group, weights=normals[:, k], minlength=ng)
    gn /= np.maximum(np.linalg.norm(gn, axis=1, keepdims=True), np.float32(1e-30))
    e = group[np.asarray(edges, np.int64).reshape(-1, 2)]
    e = np.unique(np.sort(e, axis=1), axis=0)  # each welded edge once, in either direction
    e = e[e[:, 0] != e[:, 1]]
    v0, v1 = e[:, 0], e[:, 1]
    d = gco[v1] - gco[v0]
    d /= np.maximum(np.linalg.norm(d, axis=1, keepdims=True), np.float32(1e-30))
    count = np.bincount(v0, minlength=ng) + np.bincount(v1, minlength=ng)
    accum = np.zeros((ng, 3), np.float64)
    for k in range(3):
        accum[:, k] = np.bincount(v0, weights=d[:, k], minlength=ng) - np.bincount(v1, weights=d[:, k], minlength=ng)
    mean = (accum / np.maximum(count, 1)[:, None]).astype(np.float32)
    cos = np.clip(np.einsum("ij,ij->i", gn, mean), -1.0, 1.0)
    raw = np.where(count > 0, np.arccos(cos) / np.float32(np.pi), 0.0).astype(np.float32)
    blurred = raw + np.bincount(v0, weights=raw[v1], minlength=ng) + np.bincount(v1, weights=raw[v0], minlength=ng)
    blurred /= count + 1
    return blurred.astype(np.float32)[group]


def island_roots(nv: int, edges: np.ndarray) -> np.ndarray:
    """(nv,) int64: each vertex's island root, as the union-find described above leaves it after joining ``edges``
    (ne, 2) in order."""
    parent = list(range(nv))
    rank = [0] * nv

    def root(x: int) -> int:
        r = x
        while parent[r] != r:
            r = parent[r]
        while parent[x] != r:  # path compression (it does not change which vertex is a root)
            parent[x], x = r, parent[x]
        return r
    for a, b in np.asarray(edges, np.int64).reshape(-1, 2).tolist():  # sequential by definition (module docstring)
        ra, rb = root(a), root(b)
        if ra == rb:
            continue
        if rank[ra] < rank[rb]:
            ra, rb = rb, ra
        parent[rb] = ra
        if rank[ra] == rank[rb]:
            rank[ra] += 1
    top = np.asarray(parent, np.int64)
    while True:  # every vertex's root, vectorized (pointer jumping)
        up = top[top]
        if np.array_equal(up, top):
            return top
        top = up


def random_per_island(nv: int, edges: np.ndarray) -> np.ndarray:
    """(nv,) float32 Random Per Island of each vertex's island."""
    return to_unit(hash_uint(island_roots(nv, edges).astype(np.uint32)))


def read_derived(mesh, name: str) -> np.ndarray | None:
    """(nv,) float32 per-vertex values of derived attribute ``name`` of a Blender mesh; None for another name."""
    if name not in DERIVED:
        return None
    nv = len(mesh.vertices)
    ed = np.empty(len(mesh.edges) * 2, np.int32)
    mesh.edges.foreach_get("vertices", ed)
    if name == RANDOM_PER_ISLAND:
        return random_per_island(nv, ed.reshape(-1, 2))
    co = np.empty(nv * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    vn = np.empty(nv * 3, np.float32)
    mesh.vertex_normals.foreach_get("vector", vn)
    return pointiness(co.reshape(-1, 3), vn.reshape(-1, 3), ed.reshape(-1, 2))
