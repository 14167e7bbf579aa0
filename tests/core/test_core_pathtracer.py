"""The reference path tracer against closed-form answers (no bpy)."""
import numpy as np
import pytest
from scenes_core import emissive_furnace, floor_with_emitter, irradiance_square, plane_under_world

from restir_engine.core.renderer import Cancelled, RenderSettings, render_frame
from stats import standard_error, welch_se


def test_plane_under_constant_world_is_exact():
    # cosine-weighted BSDF sampling of a constant world is a zero-variance estimator: L = albedo * world
    r = render_frame(plane_under_world(albedo=0.5, world=2.0), RenderSettings(samples=2, max_bounces=0))
    rgb = r.passes["Combined"][..., :3]
    assert np.allclose(rgb, 1.0, atol=1e-4)
    assert np.allclose(r.passes["Combined"][..., 3], 1.0)


@pytest.mark.parametrize("bounces", [0, 1, 3])
def test_emissive_furnace_matches_geometric_series(bounces):
    """Closed emissive, reflective box: every estimator strategy (emission, NEE, BSDF hits with MIS,
    Russian roulette) has to agree with le * sum_{j<=k+1} albedo^j."""
    albedo, le = 0.5, 1.0
    expected = le * sum(albedo ** j for j in range(bounces + 2))
    reps = [render_frame(emissive_furnace(albedo, le), RenderSettings(samples=10, max_bounces=bounces, seed=s))
            .passes["Combined"][..., :3].mean() for s in range(6)]
    mean, se = np.mean(reps), standard_error(reps)
    assert se < 0.002 * expected  # the test can see a 1% error
    assert abs(mean - expected) < 5 * se + 1e-6, (mean, expected, se)


def test_direct_light_under_square_emitter_matches_form_factor():
    """Floor point under the centre of an emissive square: L = albedo/π · le · F (closed form)."""
    albedo, le, h, a = 0.5, 4.0, 1.0, 0.5
    scene = floor_with_emitter(albedo, le, h, a, width=64)
    # the central 2x2 pixels cover ±1/64 around the centre: irradiance there differs by < 0.05%
    reps = [render_frame(scene, RenderSettings(samples=64, max_bounces=0, seed=s)).passes["Combined"][31:33, 31:33, 0].mean()
            for s in range(8)]
    expected = albedo / np.pi * le * irradiance_square(h, a)
    mean, se = np.mean(reps), standard_error(reps)
    assert se < 0.01 * expected
    assert abs(mean - expected) < 5 * se + 0.0005 * expected, (mean, expected, se)


def test_one_sided_emitter_lights_only_its_front():
    up = floor_with_emitter(two_sided=False)
    up.geometry.verts[2:] = up.geometry.verts[2:, ::-1]  # flip the emitter's winding: it now faces up
    r = render_frame(up, RenderSettings(samples=2, max_bounces=0))
    assert r.passes["Combined"][..., :3].max() == 0.0


def test_same_seed_same_image_and_different_seed_independent_noise():
    scene = floor_with_emitter(width=32)
    a = render_frame(scene, RenderSettings(samples=2, max_bounces=1, seed=7)).passes["Combined"]
    b = render_frame(scene, RenderSettings(samples=2, max_bounces=1, seed=7)).passes["Combined"]
    c = render_frame(scene, RenderSettings(samples=2, max_bounces=1, seed=8)).passes["Combined"]
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)
    # noise (difference from the mean of many seeds) of two seeds is uncorrelated
    ref = np.mean([render_frame(scene, RenderSettings(samples=2, max_bounces=1, seed=s)).passes["Combined"][..., 0]
                   for s in range(20, 28)], axis=0)
    na, nc = (a[..., 0] - ref).ravel(), (c[..., 0] - ref).ravel()
    assert abs(np.corrcoef(na, nc)[0, 1]) < 0.3


def test_passes_are_finite_and_consistent():
    r = render_frame(emissive_furnace(), RenderSettings(samples=2, max_bounces=2))
    p = r.passes
    for name, img in p.items():
        assert np.isfinite(img).all(), name
    assert np.allclose(p["Combined"][..., :3], p["Emission"] + p["Direct"] + p["Indirect"], atol=1e-5)
    # orthographic camera 0.5 above the floor at z=-1 looking down: depth 1.5 - clip, normal +z
    assert np.allclose(p["Depth"], 1.5, atol=1e-4)
    assert np.allclose(p["Normal"], [0, 0, 1], atol=1e-4)


def test_cancel_before_first_pass_raises_and_later_keeps_finished_passes():
    scene = emissive_furnace(width=64)
    with pytest.raises(Cancelled):
        render_frame(scene, RenderSettings(samples=4, tile_pixels=256), should_stop=lambda: True)
    second = {"started": False}

    def progress(fraction, message):
        second["started"] |= message.startswith("Sample 2/")

    # 16 chunks per pass: the stop arrives while the second pass runs
    r = render_frame(scene, RenderSettings(samples=8, tile_pixels=256), progress=progress,
                     should_stop=lambda: second["started"])
    assert r.cancelled and r.samples_done == 1
    assert np.isfinite(r.passes["Combined"]).all()


def test_ris_direct_light_converges_to_the_path_tracer():
    """RIS (light + BSDF candidates, balance heuristic) estimates the same direct light as NEE + MIS."""
    from scenes_core import floor_with_emitter
    scene = floor_with_emitter(width=32)
    ris = RenderSettings(samples=8, max_bounces=0, integrator="RESTIR", direct_method="RIS", light_candidates=8)
    ref = RenderSettings(samples=8, max_bounces=0)
    a = [render_frame(scene, RenderSettings(**{**ris.__dict__, "seed": s})).passes["Combined"][..., 0].mean()
         for s in range(8)]
    b = [render_frame(scene, RenderSettings(**{**ref.__dict__, "seed": s})).passes["Combined"][..., 0].mean()
         for s in range(8)]
    se = welch_se(a, b)
    assert se < 0.005 * np.mean(b)
    assert abs(np.mean(a) - np.mean(b)) < 5 * se, (np.mean(a), np.mean(b), se)


@pytest.mark.parametrize("bias_correction", ["UNBIASED", "NONE"])
def test_spatial_reuse_reduces_noise_and_unbiased_mode_converges(bias_correction):
    """Spatial reuse (area-measure reservoirs) around an occluder: the unbiased mode must agree with
    the path tracer within 5 standard errors; both modes must cut the per-pixel variance."""
    from scenes_core import concat, quad, tris
    scene = floor_with_emitter(width=48)
    scene.geometry = concat([scene.geometry, tris(quad((0.1, 0.05, 0.4), (0.15, 0, 0), (0, 0.3, 0)), 0)])
    st = dict(samples=4, max_bounces=0, integrator="RESTIR", direct_method="RESTIR", light_candidates=4,
              spatial_neighbors=5, spatial_radius=6, bias_correction=bias_correction)
    a = np.array([render_frame(scene, RenderSettings(**st, seed=s)).passes["Combined"][..., 0] for s in range(10)])
    b = np.array([render_frame(scene, RenderSettings(samples=4, max_bounces=0, seed=50 + s)).passes["Combined"][..., 0]
                  for s in range(10)])
    assert a.var(axis=0).mean() < 0.5 * b.var(axis=0).mean()
    if bias_correction == "UNBIASED":
        ma, mb = a.mean(axis=(1, 2)), b.mean(axis=(1, 2))
        se = welch_se(ma, mb)
        assert se < 0.005 * mb.mean()
        assert abs(ma.mean() - mb.mean()) < 5 * se, (ma.mean(), mb.mean(), se)


def test_temporal_reuse_over_frames_is_unbiased_and_caps_confidence():
    """Eight frames of a static scene with temporal + spatial reuse (unbiased): the last frame agrees
    with the path tracer within 5 standard errors, has lower noise, and M never exceeds the cap."""
    from scenes_core import concat, quad, tris
    scene = floor_with_emitter(width=32)
    scene.geometry = concat([scene.geometry, tris(quad((0.1, 0.05, 0.4), (0.15, 0, 0), (0, 0.3, 0)), 0)])
    last, ms = [], []
    for rep in range(10):
        hist = None
        for frame in range(8):
            r = render_frame(scene, RenderSettings(samples=1, max_bounces=0, seed=rep, frame=frame, integrator="RESTIR",
                                                   direct_method="RESTIR", light_candidates=4, spatial_radius=6,
                                                   spatial_neighbors=0, confidence_cap=5), history=hist)
            hist = r.history
            ms.append(hist.res.M.max())
        last.append(r.passes["Combined"][..., 0])
    ref = [render_frame(scene, RenderSettings(samples=1, max_bounces=0, seed=50 + s)).passes["Combined"][..., 0]
           for s in range(10)]
    a, b = np.array(last), np.array(ref)
    assert max(ms) <= 5.0
    assert a.var(axis=0).mean() < 0.7 * b.var(axis=0).mean()
    ma, mb = a.mean(axis=(1, 2)), b.mean(axis=(1, 2))
    se = welch_se(ma, mb)
    assert abs(ma.mean() - mb.mean()) < 5 * se, (ma.mean(), mb.mean(), se)


def test_light_switched_off_leaves_no_energy_in_the_next_frame():
    """A light that goes out changes the light table: the history is dropped (lag 0 frames) and the next
    frame's direct light matches the path tracer of the new scene."""
    from scenes_core import concat, quad, tris
    on = floor_with_emitter(width=32)
    second = tris(quad((0.6, 0.0, 0.8), (0, 0.2, 0), (0.2, 0, 0)), 1)
    on.geometry = concat([on.geometry, second])
    off = floor_with_emitter(width=32)  # the second emitter is gone
    st = dict(samples=1, max_bounces=0, integrator="RESTIR", direct_method="RESTIR", light_candidates=4,
              spatial_radius=6)
    finals = []
    for rep in range(8):
        hist = None
        for frame in range(3):
            hist = render_frame(on, RenderSettings(**st, seed=rep, frame=frame), history=hist).history
        r = render_frame(off, RenderSettings(**st, seed=rep, frame=3), history=hist)
        assert r.passes["Reservoir M"].max() <= 1.0 + 5.0  # own + at most 5 spatial neighbours: no history
        finals.append(r.passes["Combined"][..., 0].mean())
    ref = [render_frame(off, RenderSettings(samples=1, max_bounces=0, seed=40 + s)).passes["Combined"][..., 0].mean()
           for s in range(8)]
    se = welch_se(finals, ref)
    assert abs(np.mean(finals) - np.mean(ref)) < 5 * se, (np.mean(finals), np.mean(ref), se)


def test_restir_integrator_splits_direct_and_indirect_exactly_in_the_furnace():
    """Inside a closed emissive Lambert cube (radiance le x sum of albedo^j), the ReSTIR integrator with two
    bounces gives Direct = le a and Indirect = le (a² + a³): its first-hit direct light comes from the
    reservoirs and the emitters its first BSDF ray finds are not counted again. Within 5 standard errors
    over 32 seeds of 16 samples (able to see a 2 % error: measured over 48 seeds of 8 samples, the image mean of
    Indirect has a standard deviation of 0.0060 per seed, so here se ≈ 0.0007, half the 0.0015 the check needs)."""
    from scenes_core import emissive_furnace
    a, le = 0.5, 1.0
    scene = emissive_furnace(albedo=a, le=le, width=16)
    runs = [render_frame(scene, RenderSettings(samples=16, max_bounces=2, seed=s, integrator="RESTIR",
                                               direct_method="RESTIR", light_candidates=8, spatial_radius=4)).passes
            for s in range(32)]
    for name, exact in (("Direct", le * a), ("Indirect", le * (a ** 2 + a ** 3))):
        m = np.array([r[name].mean() for r in runs])
        se = standard_error(m)
        assert 5 * se < 0.02 * exact, (name, se)
        assert abs(m.mean() - exact) < 5 * se, (name, m.mean(), exact, se)


def _objects_under_world(width=48, height=36):
    """Two small instanced quads (one level, one tilted) and a small point lamp above them in a wide view of a
    constant world: most camera rays meet nothing."""
    import dataclasses

    from scenes_core import concat, perspective_camera, quad, tris

    from restir_engine.core.scene import MaterialTable, Scene
    from test_sphere_lights import floor_under_sphere
    mats = MaterialTable.build([{"base_color": (0.6, 0.5, 0.4), "roughness": 0.4},
                                {"base_color": (0, 0, 0), "f0": 0.0, "emission": (5.0,) * 3,
                                 "two_sided_emission": False}])
    a = tris(quad((-0.6, 0, 0), (0.25, 0, 0), (0, 0.25, 0)), 0)
    b = tris(quad((0.7, 0.2, 0.3), (0.2, 0, 0.1), (0, 0.2, 0)), 0)
    geom = concat([a, b])
    geom = dataclasses.replace(geom, instance=np.array([0, 0, 1, 1], np.int32))
    cam = perspective_camera((0.0, -3.0, 1.5), (0.0, 0.0, 0.0), width, height)
    lamps = floor_under_sphere(radius=0.08, height=0.9).lamps  # a point lamp in view, its proxy's material 1
    return Scene(geom, mats, lamps, cam, world_radiance=np.full(3, 0.7, np.float32))


def test_camera_rays_outside_the_objects_boxes_are_not_traced(monkeypatch):
    """The window pixels outside the projected boxes of the instances (camera.box_pixels) skip the geometry, those
    outside the visible lamps' boxes the lamps: the image is bit-identical to tracing every camera ray against
    everything (same seed), on both integrators."""
    from restir_engine.core.integrators import trace_context
    from restir_engine.core.integrators.context_cache import context_for
    from restir_engine.core.pipeline import coverage
    scene = _objects_under_world()
    for integrator in ("PATH", "RESTIR"):
        st = RenderSettings(samples=2, max_bounces=2, seed=5, integrator=integrator, direct_method="AUTO",
                            indirect_method="AUTO", data_passes=False)
        masked = render_frame(scene, st)
        ctx_mask = coverage.geometry_mask(context_for(scene, 2, False, trace_context.build_context)[0], scene.camera)
        assert ctx_mask is not None and 0.02 < ctx_mask.mean() < 0.5
        lamp_mask = coverage.lamp_mask(context_for(scene, 2, False, trace_context.build_context)[0], scene.camera)
        assert lamp_mask is not None and 0.001 < lamp_mask.mean() < 0.2
        with monkeypatch.context() as m:
            m.setattr(coverage, "geometry_mask", lambda ctx, camera: None)
            m.setattr(coverage, "lamp_mask", lambda ctx, camera: None)
            full = render_frame(scene, st)
        assert np.array_equal(masked.passes["Combined"], full.passes["Combined"])
        # the objects are in the image: the mask did not just cover an empty view
        assert (np.abs(full.passes["Combined"][..., :3] - 0.7).max(axis=2) > 0.05).sum() > 20
        assert full.passes["Emission"].max() > 4.0  # the lamp is seen


def test_per_hit_shading_stays_float32():
    """Every per-hit array of the shading code is float32: one float64 operand (a table lookup once returned float64
    through its integer index) promotes everything computed from it and made the BSDF 1.5-5x slower, with the same
    image. Checked on the regression room (glossy, metal, textured and diffuse materials)."""
    from scenes_core import regression_room

    from restir_engine.core.materials import bsdf
    from restir_engine.core.integrators import camera_paths, pathtracer, trace_context
    from restir_engine.core.sampling import rng
    scene = regression_room(24, 18)
    ctx = trace_context.build_context(scene, 2)
    ys, xs = np.mgrid[0:18, 0:24]
    hits = camera_paths.primary(ctx, xs.ravel().astype(np.float32) + 0.5, ys.ravel().astype(np.float32) + 0.5)
    surf = hits.surf
    assert len(surf) > 100
    for name in ("p", "ng", "ns", "wo", "t", "bt", "wo_l", "albedo", "layer"):
        assert getattr(surf, name).dtype == np.float32, name
    assert surf.params.block.dtype == np.float32
    view = surf.view
    for name, value in vars(view).items():
        if isinstance(value, np.ndarray) and name != "metal_rows":  # (metal_rows: surface indices)
            assert value.dtype == np.float32, name
    u = rng(1, 0, 0, 0).random((3, len(surf)), dtype=np.float32)
    wi, f, pdf = bsdf.sample_bsdf(surf.params, surf.wo_l, u[0], u[1], u[2], view=view)
    assert wi.dtype == f.dtype == pdf.dtype == np.float32
    assert pathtracer.next_event(ctx, surf, rng(1, 0, 0, 1)).dtype == np.float32
