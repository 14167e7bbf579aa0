"""Motion blur in the core (geometry/motion_blur.py): decomposed matrix interpolation, the passes' shutter times,
and a moving emitter whose blurred image is known in closed form."""
import dataclasses

import numpy as np
import pytest
from scenes_core import quad, top_down_camera, tris
from stats import Z_MAX

from restir_engine.core.geometry.motion_blur import ShutterMotion, interpolate
from restir_engine.core.renderer import RenderSettings, render_frame
from restir_engine.core.scene import Lamps, MaterialTable, Scene


def _rz(angle, t=(0.0, 0.0, 0.0), s=(1.0, 1.0, 1.0)):
    m = np.eye(4)
    c, si = np.cos(angle), np.sin(angle)
    m[:3, :3] = np.array([[c, -si, 0], [si, c, 0], [0, 0, 1]]) @ np.diag(s)
    m[:3, 3] = t
    return m


def test_interpolation_is_decomposed():
    """Rotation by slerp (the angle goes linearly, the shorter way), translation and scale linearly, mirroring kept;
    the ends are the matrices themselves."""
    a = _rz(0.2, (0, 0, 0), (1, 1, 1))
    b = _rz(0.2 + np.radians(170), (2, -4, 1), (3, 1, 1))
    for f in (0.0, 0.25, 0.5, 1.0):
        m = interpolate(a[None], b[None], f)[0]
        np.testing.assert_allclose(m, _rz(0.2 + f * np.radians(170), (2 * f, -4 * f, f), (1 + 2 * f, 1, 1)),
                                   atol=1e-9)
    # 350° apart one way is 10° the other: slerp takes the short arc
    m = interpolate(_rz(0.0)[None], _rz(np.radians(-10))[None], 0.5)[0]
    np.testing.assert_allclose(m, _rz(np.radians(-5)), atol=1e-9)
    mirror = _rz(0.3, s=(1, 1, -1))
    m = interpolate(mirror[None], _rz(0.5, s=(1, 1, -1))[None], 0.5)[0]
    assert np.linalg.det(m[:3, :3]) < 0
    np.testing.assert_allclose(m, _rz(0.4, s=(1, 1, -1)), atol=1e-9)


def test_pass_times_are_stratified_deterministic_and_follow_the_curve():
    blur = ShutterMotion(np.repeat(np.eye(4)[None, None], 3, axis=0), np.eye(4)[None])
    times = np.array([blur.pass_time(7, 3, s, 16) for s in range(16)])
    assert np.array_equal(np.sort(np.floor(times * 16)), np.arange(16))  # one time in each sixteenth
    assert np.array_equal(times, [blur.pass_time(7, 3, s, 16) for s in range(16)])
    assert not np.array_equal(times, [blur.pass_time(8, 3, s, 16) for s in range(16)])
    # a curve closed in the first half: every time in the second half, spread as the curve (a ramp up: density 2τ)
    x = np.linspace(0, 1, 256)
    ramp = ShutterMotion(blur.instance_steps, blur.current, curve=np.where(x < 0.5, 0.0, x - 0.5))
    t = np.array([ramp.pass_time(1, 1, s, 400) for s in range(400)])
    assert t.min() >= 0.5 - 1e-9
    # density ∝ (τ - ½) on [½, 1]: P(τ < ¾) = ¼
    assert abs((t < 0.75).mean() - 0.25) < 0.02


SIZE, HALF = 48, 1.0  # pixels, and the half extent (m) the top-down camera sees
SIDE, TRAVEL, LE = 0.5, 1.0, 2.0  # the emitter's side, its travel along x over the shutter (m), its radiance


def _moving_emitter(blur: bool = True):
    """A square emitter (radiance LE) over black, seen from above, travelling TRAVEL along x during the shutter
    (from -TRAVEL/2 to +TRAVEL/2 about where the frame has it), in 3 steps."""
    mats = MaterialTable.build([{"base_color": (0, 0, 0), "f0": 0.0, "emission": (LE,) * 3}])
    geom = tris(quad((0, 0, 0.1), (SIDE / 2, 0, 0), (0, SIDE / 2, 0)), 0)
    geom.instance = np.zeros(len(geom), np.int32)
    scene = Scene(geom, mats, Lamps.empty(), top_down_camera(SIZE, SIZE, half_extent=HALF))
    if blur:
        steps = np.repeat(np.eye(4)[None, None], 3, axis=0)
        steps[:, 0, 0, 3] = np.array([-0.5, 0.0, 0.5]) * TRAVEL
        scene.blur = ShutterMotion(steps, np.eye(4)[None])
    return scene


def _expected() -> np.ndarray:
    """(h, w) the pixels' mean radiance: LE times the share of the pixel and the shutter the square covers."""
    px = 2 * HALF / SIZE
    edges = -HALF + px * np.arange(SIZE + 1)
    # x: a pixel [a, b] and the square's x-interval [c - s/2, c + s/2], c = TRAVEL (τ - ½), τ uniform: the mean
    # overlap integrates in closed form, here on a fine τ grid (exact to 1e-6 of a pixel)
    tau = (np.arange(20000) + 0.5) / 20000
    c = TRAVEL * (tau - 0.5)
    lo = np.maximum(edges[:-1, None], c[None] - SIDE / 2)
    hi = np.minimum(edges[1:, None], c[None] + SIDE / 2)
    fx = np.clip(hi - lo, 0, None).mean(axis=1) / px
    fy = np.clip(np.minimum(edges[1:], SIDE / 2) - np.maximum(edges[:-1], -SIDE / 2), 0, None) / px
    return LE * fy[:, None] * fx[None, :]


def _renders(scene, seeds=16, samples=32, **kw):
    out = []
    for seed in range(seeds):
        st = RenderSettings(samples=samples, seed=seed, max_bounces=0, **kw)
        out.append(render_frame(scene, st, processes=1).passes["Combined"][..., :3].mean(axis=2))
    return np.array(out, np.float64)


def _columns(images: np.ndarray) -> np.ndarray:
    """(k, w): the mean of each column over the rows the square spans (the blur runs along x)."""
    rows = _expected().max(axis=1) > 0
    return images[:, rows].mean(axis=1)


@pytest.mark.slow_case  # long: dealt out between the Blenders in CI (tests/conftest.py)
@pytest.mark.parametrize("integrator", ["PATH", "RESTIR"])
def test_a_moving_emitter_blurs_as_integrated_over_the_shutter(integrator):
    """Each column's mean (over the square's rows; 16 seeds of 32 passes, strata shorter than the time the square
    takes to cross a pixel) within Z_MAX standard errors (plus 1e-3 for float32) of the closed form, the rows
    beside the square black; the sharp frame (no blur) fails in a fifth of the columns or more (the test sees the
    blur)."""
    exp = _columns(_expected()[None])[0]
    kw = {"integrator": integrator}
    for blur, must_pass in ((True, True), (False, False)):
        im = _renders(_moving_emitter(blur), **kw)
        cols = _columns(im)
        se = cols.std(axis=0, ddof=1) / np.sqrt(len(cols))
        bad = np.abs(cols.mean(axis=0) - exp) > Z_MAX * se + 1e-3
        if must_pass:
            assert not bad.any(), f"{bad.sum()} columns off; worst |Δ| {np.abs(cols.mean(0) - exp).max():.4f}"
            assert abs(im.mean() - _expected().mean()) < 1e-3 * LE  # the emitter's light is kept
            assert not im[:, _expected().max(axis=1) == 0].any()
        else:
            assert bad.mean() > 0.2, f"a sharp frame passes in all but {bad.mean():.1%} of the columns"


def test_motion_blur_renders_the_same_in_worker_processes():
    """The passes' times and poses depend on (seed, frame, pass) only: two worker processes give the image of one
    process bit for bit."""
    scene = _moving_emitter()
    st = RenderSettings(samples=4, seed=3, max_bounces=0, integrator="PATH", tile_pixels=512)
    one = render_frame(scene, st, processes=1).passes["Combined"]
    two = render_frame(scene, st, processes=2).passes["Combined"]
    assert np.array_equal(one, two)


def test_a_still_scene_with_blur_data_renders_as_without():
    """Steps that do not move anything leave the frame as it is (no work, the same image)."""
    scene = _moving_emitter(blur=False)
    still = dataclasses.replace(scene, blur=ShutterMotion(np.repeat(np.eye(4)[None, None], 3, axis=0),
                                                          np.eye(4)[None]))
    st = RenderSettings(samples=2, seed=1, max_bounces=0, integrator="PATH")
    assert not still.blur.moves
    a = render_frame(scene, st, processes=1).passes["Combined"]
    b = render_frame(still, st, processes=1).passes["Combined"]
    assert np.array_equal(a, b)


def test_the_bands_of_a_blurred_frame_share_the_still_triangles_bvh(monkeypatch):
    """A banded frame renders each band with its own renderer: the Embree scene of the triangles that do not move is
    built once for all of them (and the banded image keeps the blur's light)."""
    from restir_engine.core.geometry import accel
    from restir_engine.core.integrators import context_cache
    scene = _moving_emitter()
    floor = tris(np.concatenate([quad((x, y, 0), (1, 0, 0), (0, 1, 0)) for x in (-1, 1) for y in (-1, 1)]), 0)
    geom = scene.geometry
    scene.geometry = dataclasses.replace(geom, verts=np.concatenate([geom.verts, floor.verts]),
                                         normals=np.concatenate([geom.normals, floor.normals]),
                                         material=np.concatenate([geom.material, floor.material]),
                                         instance=np.concatenate([geom.instance, np.ones(8, np.int32)]))
    scene.blur = ShutterMotion(np.concatenate([scene.blur.instance_steps, np.repeat(np.eye(4)[None, None], 3, 0)],
                                              axis=1), np.repeat(np.eye(4)[None], 2, axis=0))
    built = []
    original = accel.Accel.__init__

    def counting(self, triangles, *args, **kwargs):
        built.append(len(triangles))
        original(self, triangles, *args, **kwargs)

    monkeypatch.setattr(accel.Accel, "__init__", counting)
    context_cache.clear()
    st = RenderSettings(samples=4, seed=2, max_bounces=0, integrator="PATH")
    out = render_frame(scene, st, processes=1, bands=3)
    assert built.count(8) == 1, built  # the still floor's 8 triangles: one Embree scene for the three bands
    assert np.isfinite(out.passes["Combined"]).all() and out.passes["Combined"].max() > 0
