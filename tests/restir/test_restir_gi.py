"""ReSTIR GI in the core: the reconnection Jacobian, convergence of the unbiased mode to the path tracer (stills,
temporal chains, glossy and mirror surfaces, thin walls), the furnace's exact indirect light, history rules.

Statistical checks compare independent repetitions by Welch z-scores over image blocks (tests/stats.py): a
correct estimator stays within 5 standard errors; each test also checks that its standard error is small
enough to see the error it guards against."""
import numpy as np
import pytest

from restir_engine.core.renderer import RenderSettings, render_frame
from restir_engine.core.restir.gi import GIReservoirs, age_history, reconnection_jacobian
from restir_engine.core.scene import MaterialTable, Scene
from scenes_core import bounce_room, concat, one_moving_instance, quad, regression_room, tris
from stats import compare, standard_error

pytestmark = pytest.mark.slow_case  # statistical: dealt out between the Blenders in CI (tests/conftest.py)

Z = 5.0


def _solid_angle(o, a, b, c):
    """Exact solid angle of triangle (a, b, c) seen from o (Van Oosterom & Strackee 1983)."""
    r1, r2, r3 = a - o, b - o, c - o
    l1, l2, l3 = np.linalg.norm(r1), np.linalg.norm(r2), np.linalg.norm(r3)
    num = abs(np.dot(r1, np.cross(r2, r3)))
    den = l1 * l2 * l3 + np.dot(r1, r2) * l3 + np.dot(r1, r3) * l2 + np.dot(r2, r3) * l1
    return 2 * np.arctan2(num, den)


def test_reconnection_jacobian_is_the_ratio_of_solid_angles():
    """|J| of moving x2 from receiver r to receiver q is dω_q/dω_r: the solid angle a tiny patch around x2 subtends
    from q over the one from r (exact triangle solid angles), for a hand-checked geometry and random ones."""
    x2 = np.zeros(3)
    n2 = np.array([0.0, 0.0, 1.0])
    r, q = np.array([0.0, 0.0, 2.0]), np.array([3.0, 0.0, 4.0])
    j = reconnection_jacobian(r[:, None], q[:, None], x2[:, None], n2[:, None])[0]
    assert j == pytest.approx((0.8 / 1.0) * (4.0 / 25.0), rel=1e-5)  # cos φ_q = 4/5, d_r² = 4, d_q² = 25
    rng = np.random.default_rng(1)
    for _ in range(20):
        x2 = rng.normal(size=3)
        n2 = rng.normal(size=3)
        n2 /= np.linalg.norm(n2)
        t = np.cross(n2, [1.0, 0, 0]) if abs(n2[0]) < 0.9 else np.cross(n2, [0, 1.0, 0])
        t /= np.linalg.norm(t)
        b = np.cross(n2, t)
        e = 1e-4
        tri = (x2, x2 + e * t, x2 + e * b)
        r = x2 + n2 * rng.uniform(0.3, 2) + rng.normal(size=3) * 0.5
        q = x2 + n2 * rng.uniform(0.3, 2) + rng.normal(size=3) * 0.5
        if np.dot(r - x2, n2) <= 0.05 or np.dot(q - x2, n2) <= 0.05:
            continue
        ratio = _solid_angle(q, *tri) / _solid_angle(r, *tri)
        j = reconnection_jacobian(r[:, None], q[:, None], x2[:, None], n2[:, None])[0]
        assert j == pytest.approx(ratio, rel=2e-3)


def test_area_measure_weight_carries_the_jacobian():
    """A GI reservoir's W is in area measure. Seen from receiver q its solid-angle weight W·cos φ_q/d_q² must
    equal the solid-angle weight at the receiver r that made it (1/p_ω) times |J(r→q)| (RTXDI's temporal W·J)."""
    rng = np.random.default_rng(2)
    x2, n2 = np.zeros((3, 50)), np.tile([[0.0], [0.0], [1.0]], 50)
    r = rng.uniform(-1, 1, (3, 50)) + [[0], [0], [2]]
    q = rng.uniform(-1, 1, (3, 50)) + [[0], [0], [2]]
    p_omega = rng.uniform(0.1, 2.0, 50)
    g = lambda x: np.abs(((x - x2) * n2).sum(0)) / np.linalg.norm(x - x2, axis=0) / ((x - x2) ** 2).sum(0)  # noqa: E731
    w_area = 1.0 / (p_omega * g(r))  # W = 1 / p_area, p_area = p_ω cos φ_r / d_r²
    assert np.allclose(w_area * g(q), (1.0 / p_omega) * reconnection_jacobian(r, q, x2, n2), rtol=1e-4)


def _runs(scene, seeds, frames=1, bounces=1, samples=1, **kw):
    out = []
    for sd in seeds:
        hist = None
        for f in range(frames):
            # only the last frame's samples are scored; earlier frames feed the history through their first pass
            r = render_frame(scene, RenderSettings(samples=samples if f == frames - 1 else 1, max_bounces=bounces, seed=sd, frame=f, integrator="RESTIR",
                                                   direct_method="LIGHT_SAMPLING", **kw), history=hist)
            hist = r.history
        for name, a in r.passes.items():
            assert np.isfinite(a).all(), name
        out.append(r.passes["Indirect"])
    return np.array(out)


@pytest.fixture(scope="module")
def room():
    """The regression room with its tiny light 100x dimmer and its metal block at roughness 0.5 (not 0.2): as built,
    light reflected by the block is path-traced in both estimators (a metal's light is specular, never cached)
    and its fireflies (one image mean 9x the average in 300) make a standard error from a few hundred repetitions
    unreliable. Mirror-like surfaces are tested in the closed room below."""
    scene = regression_room(48, 36)
    scene.materials.emission[5] = 30.0
    scene.materials.roughness[2] = 0.5
    return scene


@pytest.fixture(scope="module")
def room_reference(room):
    """The path tracer's indirect light of the regression room: 400 independent 1-sample images."""
    return _runs(room, range(1000, 1400), indirect_method="PATH")


@pytest.mark.parametrize("frames", [1, 4])
def test_unbiased_gi_converges_to_the_path_tracer(room, room_reference, frames):
    """The regression room (glossy floor, metal block, textured walls, emitters of every kind, a sun, a world):
    ReSTIR GI unbiased (spatial reuse; with 4 frames temporal too) agrees with the path tracer's indirect light in
    each image quarter and overall within 5 standard errors, able to see a 3 % bias (relative standard error of the
    difference below 0.6 %), with lower per-pixel variance (measured 0.45x still, 0.2x after 4 frames)."""
    a = _runs(room, range(200), frames, indirect_method="RESTIR_GI", bias_correction="UNBIASED")
    z, ma, mb, rse = compare(a, room_reference, 2)
    assert rse[-1] < 0.006, rse
    assert np.all(np.abs(z) < Z), (z, ma, mb)
    assert a.var(axis=0).mean() < 0.7 * room_reference.var(axis=0).mean()


def test_biased_gi_bias_is_bounded_and_does_not_run_away(room, room_reference):
    """The biased mode (1/M, Jacobian outlier rejection, no visibility in the MIS weights) is darker: it counts
    neighbours whose x1 cannot see the sample. Measured on this room: -9 % (still) and -7 % (4 frames), per-pixel
    variance 0.84x and 1.17x the path tracer's (on interior_gi it is 25x better than the path tracer at equal
    time: docs/RESULTS.md). This test pins the bias (a larger one is a regression) and guards against a temporal
    chain that runs away (variance within 1.5x)."""
    for frames in (1, 4):
        a = _runs(room, range(100), frames, indirect_method="RESTIR_GI", bias_correction="NONE")
        bias = a.mean() / room_reference.mean() - 1
        assert -0.15 < bias < 0.02, (frames, bias)
        assert a.var(axis=0).mean() < 1.5 * room_reference.var(axis=0).mean()


def test_furnace_indirect_is_exact_with_gi():
    """Inside a closed emissive Lambert cube the indirect light after two bounces is le (a² + a³) exactly; ReSTIR GI
    (unbiased, temporal chain of 3 frames) must reproduce it within 5 standard errors (over 40 seeds of 4-pass
    frames the standard error is about 0.35 % of the value, able to see a 2 % error)."""
    from scenes_core import emissive_furnace
    a, le = 0.5, 1.0
    scene = emissive_furnace(albedo=a, le=le, width=16)
    exact = le * (a ** 2 + a ** 3)
    m = []
    for s in range(40):
        hist = None
        for f in range(3):
            r = render_frame(scene, RenderSettings(samples=4, max_bounces=2, seed=s, frame=f, integrator="RESTIR",
                                                   direct_method="RESTIR", indirect_method="RESTIR_GI",
                                                   light_candidates=8), history=hist)
            hist = r.history
        m.append(r.passes["Indirect"].mean())
    m = np.array(m)
    se = standard_error(m)
    assert 5 * se < 0.02 * exact, se
    assert abs(m.mean() - exact) < 5 * se, (m.mean(), exact, se)


@pytest.mark.parametrize("floor", [
    {"base_color": (0.9, 0.9, 0.9), "roughness": 0.05, "metallic": 1.0},   # mirror: x1 glossy, x2 glossy
    {"base_color": (0.6, 0.6, 0.6), "roughness": 0.15, "f0": 0.04},        # glossy dielectric below the threshold
    {"base_color": (0.8, 0.5, 0.3), "roughness": 0.5, "metallic": 1.0},    # rough metal (its light is not cached)
], ids=["mirror", "glossy_dielectric", "rough_metal"])
def test_glossy_and_mirror_surfaces_stay_unbiased(floor):
    """Glossy primary surfaces resample their diffuse lobe only, and only the diffuse part of the light leaving a
    secondary surface is cached (its specular part stays path traced): the unbiased mode must still agree with the path tracer (5 standard errors per quarter; 60 runs of 8 samples each,
    able to see a 5 % bias)."""
    scene = bounce_room(floor, {"base_color": (0.7, 0.7, 0.7), "roughness": 1.0, "f0": 0.0}, 48, 36)
    ref = _runs(scene, range(500, 560), bounces=2, samples=8, indirect_method="PATH")
    a = _runs(scene, range(60), 2, bounces=2, samples=8, indirect_method="RESTIR_GI")
    z, ma, mb, rse = compare(a, ref, 2)
    assert rse[-1] < 0.01, rse
    assert np.all(np.abs(z) < Z), (z, ma, mb)


def test_thin_wall_does_not_leak_in_the_unbiased_mode():
    """A 1 mm wall splits the room; the lit half's samples are reconnected to the dark half's pixels only if the
    visibility rays fail to see the wall. The unbiased mode must match the path tracer in the dark half; the biased
    mode's leak there is printed (it has no visibility test in its weights, but shading is shadowed)."""
    wall = {"base_color": (0.7, 0.7, 0.7), "roughness": 1.0, "f0": 0.0}
    scene = bounce_room(wall, wall, 40, 30, divider=True)
    ref = _runs(scene, range(700, 740), bounces=1, indirect_method="PATH")
    a = _runs(scene, range(40), 2, bounces=1, indirect_method="RESTIR_GI")
    z, ma, mb, _ = compare(a, ref, 2)
    assert np.all(np.abs(z) < Z), (z, ma, mb)
    b = _runs(scene, range(40), 2, bounces=1, indirect_method="RESTIR_GI", bias_correction="NONE")
    print("biased/unbiased indirect per quarter", np.round(compare(b, ref, 2)[1] / mb, 3))


def test_history_is_dropped_when_a_light_changes_and_kept_otherwise(room):
    """A GI history is reused by the next frame when nothing that emits changed, and dropped when a light changed
    (its cached radiance would be stale): then the frame matches the path tracer of the new scene at once (lag 0
    frames; z-test over 40 seeds)."""
    st = dict(samples=1, max_bounces=1, integrator="RESTIR", direct_method="LIGHT_SAMPLING",
              indirect_method="RESTIR_GI")
    hist = render_frame(room, RenderSettings(**st, frame=0)).history
    r = render_frame(room, RenderSettings(**st, frame=1), history=hist)
    assert r.stats["reuse"].get("gi_temporal_accepted", 0) > 0.5
    dim = Scene(room.geometry, room.materials, room.lamps, room.camera, room.world_radiance)
    dim.materials = MaterialTable(**{**room.materials.__dict__, "emission": room.materials.emission * 0.25})
    finals, refs = [], []
    for s in range(40):
        h = None
        for f in range(3):
            h = render_frame(room, RenderSettings(**st, seed=s, frame=f), history=h).history
        r = render_frame(dim, RenderSettings(**st, seed=s, frame=3), history=h)
        assert "gi_temporal_accepted" not in r.stats["reuse"]
        finals.append(r.passes["Indirect"])
        refs.append(render_frame(dim, RenderSettings(**{**st, "indirect_method": "PATH"}, seed=900 + s)).passes["Indirect"])
    z, ma, mb, rse = compare(np.array(finals), np.array(refs), 2)
    assert np.all(np.abs(z) < Z), (z, ma, mb)


def test_samples_age_out():
    """A history ages every sample by one frame and drops those older than the maximum age."""
    res = GIReservoirs.empty(4)
    res.age[:] = [0, 5, 29, -1]
    res.W[:] = [1.0, 1.0, 1.0, 0.0]
    res.M[:] = 3.0
    out = age_history(res, max_age=29)
    assert list(out.age) == [1, 6, -1, -1]
    assert list(out.W) == [1.0, 1.0, 0.0, 0.0] and list(out.M) == [3.0] * 4
    assert list(res.age) == [0, 5, 29, -1]  # the frame's reservoirs are untouched


def _room_with_moving_board(x: float, prev_x: float):
    """The closed Lambert room with a 0.6 x 1 m board (instance 1) standing in it at x (prev_x in the previous
    frame), facing the camera: it carries GI samples as it moves and uncovers the wall behind it."""
    wall = {"base_color": (0.7, 0.7, 0.7), "roughness": 1.0, "f0": 0.0}
    scene = bounce_room(wall, wall, 48, 36)
    n_static = len(scene.geometry)
    board = tris(quad((x, 0.4, 0.5), (0.3, 0, 0), (0, 0, 0.5)), 3)
    scene.geometry = concat([scene.geometry, board])
    scene.geometry.instance = np.array([0] * n_static + [1, 1], np.int32)
    one_moving_instance(scene, 2, 1, prev_x - x)
    return scene


def test_moving_object_and_disocclusion_stay_unbiased():
    """A board slides through the room (instance motion as Blender exports it), carrying GI samples and
    uncovering wall whose history belongs to the board: after four frames of temporal + spatial reuse the
    indirect light agrees with the path tracer of the last frame within 5 standard errors, in each quarter and
    overall (50 runs; able to see a 10 % smear in the whole image), and every pass is finite."""
    xs = (-0.6, -0.3, 0.0, 0.3)
    finals = []
    for rep in range(50):
        hist = None
        for f, x in enumerate(xs):
            scene = _room_with_moving_board(x, xs[f - 1] if f else x)
            r = render_frame(scene, RenderSettings(samples=2 if f == len(xs) - 1 else 1, max_bounces=1, seed=rep,
                                                   frame=f, integrator="RESTIR", direct_method="LIGHT_SAMPLING",
                                                   indirect_method="RESTIR_GI"), history=hist)
            hist = r.history
            assert all(np.isfinite(a).all() for a in r.passes.values())
        assert r.stats["reuse"].get("gi_temporal_accepted", 0) > 0.5  # the history was used
        finals.append(r.passes["Indirect"])
    last = _room_with_moving_board(xs[-1], xs[-1])
    ref = np.array([render_frame(last, RenderSettings(samples=4, max_bounces=1, seed=500 + s)).passes["Indirect"]
                    for s in range(50)])
    z, ma, mb, rse = compare(np.array(finals), ref, 2)
    assert rse[-1] < 0.02, rse
    assert np.all(np.abs(z) < Z), (z, ma, mb)


def test_bright_tiny_emitter_and_glossy_caustics_stay_finite():
    """The regression room as built (a 2 x 2 cm light of radiance 3000, a glossy floor and a polished metal
    block: fireflies in the light leaving x2): over a temporal chain in both modes every pass stays finite,
    W and M are finite and non-negative, and M never exceeds what the merges can add up to."""
    scene = regression_room(32, 24)
    for bias in ("UNBIASED", "NONE"):
        hist = None
        for f in range(4):
            r = render_frame(scene, RenderSettings(samples=2, max_bounces=2, seed=3, frame=f, integrator="RESTIR",
                                                   direct_method="RESTIR", indirect_method="RESTIR_GI",
                                                   bias_correction=bias), history=hist)
            hist = r.history
            for name, a in r.passes.items():
                assert np.isfinite(a).all(), (bias, name)
            w, m = r.passes["GI Reservoir UCW"], r.passes["GI Reservoir M"]
            assert (w >= 0).all() and (m >= 0).all()
            # own 1 + history (cap 20) before 4 spatial passes of 3 neighbours: at most 21 * 4**4
            assert m.max() <= 21 * 4 ** 4
        assert np.isfinite(hist.gi_res.W).all() and (hist.gi_res.M <= 20).all()


def test_passes_with_nothing_to_cache_keep_the_path_traced_light(room):
    """A plane under a constant world: its bounce rays find nothing but the world, the GI reservoirs would carry
    none of the indirect light, so every pass keeps the path tracer's (the same image as Indirect Method Path
    Tracing, same seed) and says so; the room, whose bounces land on walls, keeps ReSTIR GI."""
    from scenes_core import plane_under_world
    scene = plane_under_world(width=24)
    # one sample per pass in both (Path Tracing alone would batch its passes: other random streams)
    st = dict(samples=3, max_bounces=2, seed=4, integrator="RESTIR", direct_method="LIGHT_SAMPLING", sample_batch=1)
    gi_run = render_frame(scene, RenderSettings(**st, indirect_method="RESTIR_GI"))
    path_run = render_frame(scene, RenderSettings(**st, indirect_method="PATH"))
    assert gi_run.stats["gi_skipped_passes"] == 3 and gi_run.stats["indirect_method"] == "PATH"
    assert np.array_equal(gi_run.passes["Combined"], path_run.passes["Combined"])
    r = render_frame(room, RenderSettings(**st, indirect_method="RESTIR_GI"))
    assert r.stats["gi_skipped_passes"] == 0 and r.stats["indirect_method"] == "RESTIR_GI"
    assert r.stats["reuse"]["gi_share"] > 0.5
