"""Geometry > Pointiness and Random Per Island derived from a mesh as Cycles derives them (export/
derived_attributes.py); exact checks on meshes whose values follow from the definitions. The comparison with
Cycles' own renders is tests/cycles/test_nodes_cycles.py::test_pointiness_and_random_per_island_match_cycles."""
import numpy as np

from restir_engine.core.materials.nodes.hashing import hash_uint, to_unit
from restir_engine.export.derived_attributes import island_roots, pointiness, random_per_island

CUBE = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], np.float32)
CUBE_EDGES = np.array([[a, b] for a in range(8) for b in range(a + 1, 8)
                       if np.abs(CUBE[a] - CUBE[b]).sum() == 2])
CORNER = np.arccos(-1 / np.sqrt(3)) / np.pi  # a cube corner: its normal against the mean of its three edges


def grid(n=5, bump=0.0):
    """An n x n grid of unit spacing in z = 0, normals +z, its middle vertex raised by ``bump``."""
    ij = np.stack(np.meshgrid(np.arange(n), np.arange(n), indexing="ij"), -1).reshape(-1, 2)
    co = np.c_[ij, np.zeros(len(ij))].astype(np.float32)
    co[(n * n) // 2, 2] = bump
    idx = np.arange(n * n).reshape(n, n)
    edges = np.concatenate([np.stack([idx[:, :-1].ravel(), idx[:, 1:].ravel()], 1),
                            np.stack([idx[:-1].ravel(), idx[1:].ravel()], 1)])
    return co, np.tile(np.float32([0, 0, 1]), (n * n, 1)), edges


def test_a_cube_corner_and_a_flat_vertex_read_their_angles():
    got = pointiness(CUBE, CUBE / np.sqrt(3), CUBE_EDGES)
    np.testing.assert_allclose(got, CORNER, rtol=1e-6)  # every neighbour alike: the blur keeps the value
    co, nrm, edges = grid()
    np.testing.assert_allclose(pointiness(co, nrm, edges), 0.5, rtol=1e-6)


def test_a_raised_vertex_is_pointier_and_a_sunken_one_less():
    mid = 12
    up, down = (pointiness(*grid(bump=b))[mid] for b in (0.5, -0.5))
    assert up > 0.5 > down
    np.testing.assert_allclose(up - 0.5, 0.5 - down, atol=1e-6)  # mirror images about the plane


def test_the_blur_averages_a_vertex_with_its_edge_neighbours():
    """Raw values: a tip of height 1 over a flat square's four corners; the tip reads (raw + 4 corners) / 5."""
    co = np.float32([[0, 0, 1], [1, 1, 0], [-1, 1, 0], [-1, -1, 0], [1, -1, 0]])
    nrm = np.float32([[0, 0, 1]] * 5)
    edges = np.array([[0, 1], [0, 2], [0, 3], [0, 4], [1, 2], [2, 3], [3, 4], [4, 1]])
    d = co[1:] - co[0]
    raw_tip = np.arccos(np.dot(nrm[0], (d / np.linalg.norm(d, axis=1)[:, None]).mean(0))) / np.pi
    e = np.stack([co[0] - co[1], co[2] - co[1], co[4] - co[1]])
    raw_corner = np.arccos(np.dot(nrm[1], (e / np.linalg.norm(e, axis=1)[:, None]).mean(0))) / np.pi
    got = pointiness(co, nrm, edges)
    np.testing.assert_allclose(got[0], (raw_tip + 4 * raw_corner) / 5, rtol=1e-5)
    np.testing.assert_allclose(got[1], (raw_corner * 3 + raw_tip) / 4, rtol=1e-5)


def test_split_vertices_are_welded_as_one():
    """A cube whose six faces have their own four vertices (as after Edge Split) reads as the welded cube."""
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    co = np.concatenate([CUBE[list(f)] for f in faces])
    nrm = np.concatenate([np.repeat(((CUBE[list(f)].mean(0)))[None], 4, 0) for f in faces])
    edges = np.array([[4 * k + i, 4 * k + (i + 1) % 4] for k in range(6) for i in range(4)])
    np.testing.assert_allclose(pointiness(co, nrm, edges), CORNER, rtol=1e-6)


def test_island_roots_follow_union_by_rank_in_edge_order():
    np.testing.assert_array_equal(island_roots(2, np.array([[1, 0]])), [1, 1])  # a tie keeps the first's root
    np.testing.assert_array_equal(island_roots(3, np.array([[0, 1], [2, 1]])), [0, 0, 0])  # the higher rank wins
    np.testing.assert_array_equal(island_roots(4, np.array([[0, 1], [2, 3], [3, 1]])), [2, 2, 2, 2])
    np.testing.assert_array_equal(island_roots(5, np.array([[3, 4], [0, 1]])), [0, 0, 2, 3, 3])


def test_random_per_island_is_one_hashed_value_per_island():
    edges = np.concatenate([CUBE_EDGES, CUBE_EDGES + 8])  # two cubes in one mesh
    got = random_per_island(16, edges)
    assert len(np.unique(got[:8])) == 1 and len(np.unique(got[8:])) == 1 and got[0] != got[8]
    np.testing.assert_array_equal(got, to_unit(hash_uint(island_roots(16, edges).astype(np.uint32))))
