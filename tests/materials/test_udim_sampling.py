"""UDIM sets in the core (core/materials/textures.UdimImage): the tile a UV falls on, as Cycles maps it (tile 1001 +
10 int(v) + int(u), int truncating toward zero; magenta on no tile), for every sampler (bilinear, nearest, the node
programs' interpolations and extensions, the bump gradient), the mean colour, and the set crossing to worker
processes intact."""
import numpy as np

from restir_engine.core.materials.nodes.ops_texture import sample_image
from restir_engine.core.materials.textures import NearestImage, UdimImage, gradient, mean_color, sample, texture_bytes
from restir_engine.core.parallel import wire


def _set(nearest=False):
    ramp = np.linspace(0, 1, 4, dtype=np.float32)
    a = np.broadcast_to(np.stack([ramp, ramp * 0, ramp * 0], -1)[None], (2, 4, 3)).copy()  # red ramp in u
    b = np.full((8, 8, 3), (0.0, 0.5, 0.0), np.float32)
    c = np.full((8, 8, 3), (0.0, 0.0, 0.25), np.float32)
    tiles = [(1001, a), (1002, b), (1011, c)]
    if nearest:
        tiles = [(n, t.view(NearestImage)) for n, t in tiles]
    return UdimImage(tiles)


def test_each_uv_reads_the_tile_it_falls_on():
    img = _set()
    uv = np.array([[0.5, 0.5], [1.5, 0.2], [0.3, 1.7], [-0.5, 0.5], [2.5, 0.5], [0.5, -1.5], [10.5, 0.5],
                   [np.nan, 0.5]], np.float32)
    got = sample(img, uv)
    np.testing.assert_allclose(got[0], sample(img.tiles[0][1], uv[:1])[0])
    np.testing.assert_allclose(got[1], (0.0, 0.5, 0.0))
    np.testing.assert_allclose(got[2], (0.0, 0.0, 0.25))
    # int(-0.5) = 0 in Cycles: tile 1001 at u' = -0.5 (wrapped by the tile's own repeat); no tile 1003, none below 0
    np.testing.assert_allclose(got[3], sample(img.tiles[0][1], np.array([[-0.5, 0.5]], np.float32))[0])
    np.testing.assert_allclose(got[4:7], [(1, 0, 1)] * 3)
    np.testing.assert_allclose(got[7], sample(img.tiles[0][1], np.array([[0.0, 0.5]], np.float32))[0])
    assert img.shape == (2, 4, 3)  # code that knows no tiles sees the first


def test_every_sampler_goes_by_tile():
    img, near = _set(), _set(nearest=True)
    u = np.array([0.3, 1.3, 0.3, 2.3]), np.array([0.5, 0.5, 1.5, 0.5])
    uv = np.stack(u, axis=1).astype(np.float32)
    for interp in ("Linear", "Closest", "Cubic"):
        for ext in ("REPEAT", "EXTEND", "CLIP"):
            got = sample_image(img, *u, interp, ext)
            np.testing.assert_allclose(got[1], (0.0, 0.5, 0.0), atol=1e-6)
            np.testing.assert_allclose(got[2], (0.0, 0.0, 0.25), atol=1e-6)
            np.testing.assert_allclose(got[3], (1.0, 0.0, 1.0))
            np.testing.assert_allclose(got[0], sample_image(np.asarray(img.tiles[0][1]), u[0][:1], u[1][:1], interp,
                                                            ext)[0], atol=1e-6)
    np.testing.assert_allclose(sample(near, uv)[0], sample(near.tiles[0][1], uv[:1])[0])
    g = gradient(img, uv)
    np.testing.assert_allclose(g[0], gradient(img.tiles[0][1], uv[:1])[0])
    assert g[0, 0] > 0 and np.all(g[1:] == 0)  # the ramp's slope in tile 1001; flat tiles and no tile: none
    np.testing.assert_allclose(mean_color(img), np.mean([mean_color(t) for _n, t in img.tiles], axis=0))
    assert texture_bytes(img) == sum(t.nbytes for _n, t in img.tiles)


def test_a_set_crosses_to_the_workers_whole():
    img = _set(nearest=True)
    seg, packed = wire.pack({"textures": [img]})
    try:
        back = wire.unpack(packed, keep := [])["textures"][0]
        assert isinstance(back, UdimImage) and [n for n, _t in back.tiles] == [1001, 1002, 1011]
        assert all(isinstance(t, NearestImage) for _n, t in back.tiles)
        uv = np.array([[0.3, 0.5], [1.5, 0.5], [0.5, 1.5]], np.float32)
        np.testing.assert_array_equal(sample(back, uv), sample(img, uv))
    finally:
        for s in keep:
            wire.release_segment(s)
        wire.unlink_segments([seg])
