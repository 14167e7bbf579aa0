"""Coloured transparency (a Transparent BSDF's Color): rays passing a cut-out's transparent points keep its tint,
camera, bounce and shadow rays alike (no bpy; exact checks where the estimator has no variance)."""
import numpy as np
from scenes_core import concat, quad, top_down_camera, tris

from restir_engine.core.geometry.accel import Accel
from restir_engine.core.materials.cutout import Cutout
from restir_engine.core.renderer import RenderSettings, render_frame
from restir_engine.core.scene import Lamps, MaterialTable, Scene

RED_FILM = (0.8, 0.5, 0.2)
BLUE_FILM = (0.3, 0.6, 0.9)


def films(tints):
    """Rows: an opaque diffuse floor (material 0), then one fully transparent film per tint."""
    return MaterialTable.build([{"base_color": (0.5, 0.5, 0.5), "f0": 0.0}] +
                               [{"base_color": (0.0, 0.0, 0.0), "f0": 0.0, "alpha": 0.0, "transparent_tint": t}
                                for t in tints])


def stack():
    """A floor at z = 0 and two films above it: red over x < 0 at z = 1, blue over everything at z = 2."""
    geometry = concat([tris(quad((0, 0, 0), (5, 0, 0), (0, 5, 0)), 0),
                       tris(quad((-2.5, 0, 1), (2.5, 0, 0), (0, 5, 0)), 1),
                       tris(quad((0, 0, 2), (5, 0, 0), (0, 5, 0)), 2)])
    return geometry, films([RED_FILM, BLUE_FILM])


def accel_of(geometry, materials):
    ng = np.ascontiguousarray(geometry.normals[:, 0].T)
    return Accel(geometry.verts, Cutout.of(geometry, materials), ng)


def test_rays_keep_the_product_of_the_tints_they_pass():
    geometry, materials = stack()
    accel = accel_of(geometry, materials)
    assert accel.tinted
    o = np.array([[-1.0, 1.0, -1.0], [0.0, 0.0, 0.0], [3.0, 3.0, 0.5]], np.float32)  # two rays from z = 3, one below
    d = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [-1.0, -1.0, 1.0]], np.float32)
    hits = accel.intersect(o, d)
    floor = np.flatnonzero(geometry.material == 0)
    assert np.isin(hits.prim[:2], floor).all()  # both camera-like rays reach the floor
    np.testing.assert_allclose(hits.tint[:, 0], np.multiply(RED_FILM, BLUE_FILM), rtol=1e-6)
    np.testing.assert_allclose(hits.tint[:, 1], BLUE_FILM, rtol=1e-6)
    assert hits.prim[2] < 0  # up from under the red film, through both, to the sky
    np.testing.assert_allclose(hits.tint[:, 2], np.multiply(RED_FILM, BLUE_FILM), rtol=1e-6)
    # shadow rays: light from above the blue film to points on the floor and beside it
    far = np.array([2.5, 2.5, 0.5], np.float32)
    tr = accel.transmittance(np.array([[-1.0, 1.0, 3.0], [0.0, 0.0, 0.0], [3.0, 3.0, 0.6]], np.float32),
                             np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [-1.0, -1.0, -1.0]], np.float32), far)
    np.testing.assert_allclose(tr[:, 0], np.multiply(RED_FILM, BLUE_FILM), rtol=1e-6)
    np.testing.assert_allclose(tr[:, 1], BLUE_FILM, rtol=1e-6)
    np.testing.assert_allclose(tr[:, 2], 1.0)  # a segment between the films that meets none
    # ... and one that ends below the floor is blocked
    assert accel.transmittance(o[:, :1], d[:, :1], np.array([4.0], np.float32)).max() == 0.0
    keep, passed = accel.passed(o[:, :1], d[:, :1], np.array([2.5], np.float32))
    assert keep.tolist() == [0]
    np.testing.assert_allclose(passed[:, 0], np.multiply(RED_FILM, BLUE_FILM), rtol=1e-6)


def test_white_transparency_is_not_tinted():
    geometry, _ = stack()
    materials = films([(1.0, 1.0, 1.0), (1.0, 1.0, 1.0)])
    accel = accel_of(geometry, materials)
    assert not accel.tinted
    hits = accel.intersect(np.array([[-1.0], [0.0], [3.0]], np.float32), np.array([[0.0], [0.0], [-1.0]], np.float32))
    assert hits.tint is None and hits.prim[0] >= 0


def test_a_filter_under_a_constant_world_tints_the_floor_twice():
    """A diffuse floor (albedo 0.5) under a constant world of 2, seen from above through a filter that covers the
    sky (half-width 500 at height 1): the world reaches the floor through the filter once and the camera sees the
    floor through it once more, so each channel reads 0.5 · 2 · t² (the directions that pass beside the filter,
    cos² θ ≈ 4e-6 of the cosine-weighted hemisphere, aside). Cosine-weighted sampling of a constant world has no
    variance, so the check is exact; dropping the tint would read 1 in every channel."""
    geometry = concat([tris(quad((0, 0, 0), (50, 0, 0), (0, 50, 0)), 0),
                       tris(quad((0, 0, 1), (500, 0, 0), (0, 500, 0)), 1)])
    scene = Scene(geometry, films([RED_FILM]), Lamps.empty(), top_down_camera(16, 16),
                  world_radiance=np.full(3, 2.0, np.float32))
    rgb = render_frame(scene, RenderSettings(samples=2, max_bounces=0)).passes["Combined"][..., :3]
    expected = np.square(np.array(RED_FILM, np.float32))
    np.testing.assert_allclose(rgb.reshape(-1, 3).mean(axis=0), expected, rtol=1e-4)
    assert np.abs(rgb - expected).max() < 1e-3


def test_a_hit_behind_a_passed_cut_out_lies_on_its_surface():
    """A ray that passes a transparent point continues from an origin stepped off that surface along its normal;
    the hit it reports (o + d t from the original origin) must still lie on the surface it hits, not up to the
    step's size beside it, where the shadow ray's own small offset could not clear it (the floor then shadowed
    itself: black patches behind alpha cut-outs). A vertical film 6 units from the origin, 45° rays through it to
    a floor near the origin: the step there is 10x the floor's own offset."""
    geometry = concat([tris(quad((0, 0, 0), (1, 0, 0), (0, 1, 0)), 0),
                       tris(quad((-6, 0, 5), (0, 8, 0), (0, 0, 8)), 1)])  # the film: the plane x = -6
    materials = films([(1.0, 1.0, 1.0)])
    accel = accel_of(geometry, materials)
    n = 64
    rng = np.random.default_rng(3)
    target = np.vstack([rng.uniform(-0.9, 0.9, (2, n)), np.zeros((1, n))]).astype(np.float32)
    o = np.repeat(np.array([[-12.0], [0.0], [11.0]], np.float32), n, axis=1)
    d = target - o
    d /= np.linalg.norm(d, axis=0)
    hits = accel.intersect(o, d)
    assert (geometry.material[hits.prim] == 0).all()  # every ray passed the film and met the floor
    p = o + d * hits.t
    assert np.abs(p[2]).max() < 2e-5, np.abs(p[2]).max()  # on the floor (the film's step is 1.2e-3 there)
