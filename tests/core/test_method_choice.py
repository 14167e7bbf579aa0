"""The automatic direct and indirect methods (core/integrators/method_choice.py) and that the renderer applies and reports them."""
import numpy as np
from scenes_core import bounce_room, floor_with_emitter, plane_under_world
from test_light_tiles import _many_coloured_lights
from test_sphere_lights import floor_under_sphere

from restir_engine.core.integrators import camera_paths, trace_context
from restir_engine.core.integrators.method_choice import (FEW_LIGHTS, GI_MAX_UNCACHED, GI_MIN_SHARE, choose_direct_method,
                                              choose_indirect_method, choose_world_method)
from restir_engine.core.renderer import RenderSettings, render_frame


def lights_of(scene):
    return trace_context.build_context(scene, 0).lights


def test_rules():
    sphere, square, many = lights_of(floor_under_sphere()), lights_of(floor_with_emitter()), lights_of(_many_coloured_lights())
    assert many.n_tri > FEW_LIGHTS >= square.n_tri
    assert choose_direct_method(sphere, False, 0)[0] == "LIGHT_SAMPLING"  # cone-sampled lamps
    assert choose_direct_method(square, False, 0)[0] == "RESTIR"          # area light, direct only
    assert choose_direct_method(square, False, 4)[0] == "LIGHT_SAMPLING"  # indirect noise dominates
    assert choose_direct_method(square, False, 4, gi_expected=True)[0] == "RESTIR"  # unless GI takes it away
    assert choose_direct_method(sphere, False, 4, gi_expected=True)[0] == "LIGHT_SAMPLING"
    assert choose_direct_method(many, False, 4)[0] == "RESTIR"
    assert choose_direct_method(sphere, True, 4)[0] == "RESTIR"          # a reservoir pass needs reservoirs
    method, reason = choose_direct_method(many, False, 0)
    assert str(many.n_tri) in reason


def test_world_rules():
    """The world enters the reservoirs for an environment image that is the only light; a constant world, or an
    image beside lamps, is light-sampled; the user's choice holds; a black world is never resampled."""
    from test_world_light import sun_sky
    hdri = plane_under_world(width=8)
    hdri.world_image = sun_sky()
    hdri_lamp = floor_with_emitter(width=8)
    hdri_lamp.world_image = sun_sky()
    const = plane_under_world(width=8)
    black = floor_with_emitter(width=8)
    assert choose_world_method(lights_of(hdri))[0] == "RESAMPLED"
    assert choose_direct_method(lights_of(hdri), False, 0)[0] == "RESTIR"
    assert choose_direct_method(lights_of(hdri), False, 3)[0] == "LIGHT_SAMPLING"
    assert choose_direct_method(lights_of(hdri), False, 3, gi_expected=True)[0] == "RESTIR"
    assert choose_direct_method(lights_of(const), False, 0)[0] == "LIGHT_SAMPLING"
    assert choose_world_method(lights_of(hdri_lamp))[0] == "LIGHT_SAMPLED"
    assert choose_world_method(lights_of(const))[0] == "LIGHT_SAMPLED"
    assert choose_world_method(lights_of(const), "RESAMPLED") == ("RESAMPLED", "set by the user")
    assert choose_world_method(lights_of(black), "RESAMPLED")[0] == "LIGHT_SAMPLED"
    r = render_frame(hdri, RenderSettings(samples=1, integrator="RESTIR", direct_method="AUTO", max_bounces=0))
    assert (r.stats["direct_method"], r.stats["world_method"]) == ("RESTIR", "RESAMPLED")
    r = render_frame(const, RenderSettings(samples=1, integrator="RESTIR", direct_method="RESTIR", max_bounces=0,
                                           world_method="RESAMPLED", world_candidates=0))
    assert r.stats["world_method"] == "LIGHT_SAMPLED" and "0" in r.stats["world_reason"]


def test_renderer_applies_and_reports_the_choice():
    r = render_frame(floor_under_sphere(width=16), RenderSettings(samples=1, integrator="RESTIR", direct_method="AUTO",
                                                                  max_bounces=1))
    assert r.stats["direct_method"] == "LIGHT_SAMPLING" and "Reservoir M" not in r.passes
    r = render_frame(_many_coloured_lights(16), RenderSettings(samples=1, integrator="RESTIR", direct_method="AUTO",
                                                               max_bounces=0))
    assert r.stats["direct_method"] == "RESTIR" and "Reservoir M" in r.passes
    assert r.stats["spatial_radius"] >= 4.0


def test_indirect_rules():
    assert choose_indirect_method(GI_MIN_SHARE / 2, 0.0)[0] == "PATH"       # nothing to cache
    assert choose_indirect_method(0.9, 0.0)[0] == "RESTIR_GI"
    assert choose_indirect_method(0.9, GI_MAX_UNCACHED * 1.5)[0] == "PATH"  # noise GI cannot touch
    assert "cannot cache" in choose_indirect_method(0.9, 0.9)[1]


DIFFUSE = {"base_color": (0.7, 0.7, 0.7), "roughness": 1.0, "f0": 0.0}
MIRROR = {"base_color": (0.9, 0.9, 0.9), "roughness": 0.05, "metallic": 1.0}


def _auto(scene, samples=2, frame=0, **kw):
    st = dict(samples=samples, max_bounces=2, seed=3, frame=frame, integrator="RESTIR", direct_method="AUTO",
              indirect_method="AUTO", data_passes=False)
    return render_frame(scene, RenderSettings(**{**st, **kw}))


def test_auto_indirect_follows_what_the_reservoirs_can_carry():
    """A room lit by bounce light off diffuse walls: ReSTIR GI in every pass, and ReSTIR DI for its one panel
    (the direct light's noise is what GI leaves). The same room with a mirror floor (what the camera sees of it
    and what lights the walls is specular, which GI does not cache) and a plane under the world (nothing to
    cache): path tracing, and light sampling for the panel; the reason is reported."""
    r = _auto(bounce_room(DIFFUSE, DIFFUSE, 48, 36))
    assert r.stats["indirect_method"] == "RESTIR_GI" and r.stats["gi_skipped_passes"] == 0
    assert r.stats["reuse"]["gi_uncached_measured"] < GI_MAX_UNCACHED / 4
    assert r.stats["direct_method"] == "RESTIR" and "GI" in r.stats["direct_reason"]
    r = _auto(bounce_room(MIRROR, DIFFUSE, 48, 36), samples=4)
    assert r.stats["indirect_method"] == "PATH" and r.stats["gi_skipped_passes"] >= 3, r.stats["reuse"]
    assert r.stats["reuse"]["gi_uncached_measured"] > 2 * GI_MAX_UNCACHED
    assert "cannot cache" in r.stats["indirect_reason"]
    # a pass that expected GI resampled the direct light; the passes after the choice light-sample it
    assert r.stats["direct_method"] == "LIGHT_SAMPLING"
    r = _auto(plane_under_world(width=16))
    assert r.stats["indirect_method"] == "PATH" and "no bounce light" in r.stats["indirect_reason"]


def test_auto_indirect_choice_carries_to_the_next_frame():
    """A frame without a measurement probes one pixel in 32 (their own random stream) before its first
    pass; the measurement is kept with the scene's context for the next frame: frame 1 of the mirror room chooses
    light sampling for its direct light and path tracing from its first pass on, without a probe. Only frame f + 1
    uses frame f's measurement, so rendering a frame again gives the same image."""
    scene = bounce_room(MIRROR, DIFFUSE, 48, 36)
    first = _auto(scene, samples=1, frame=0)
    assert first.stats["gi_skipped_passes"] == 1  # nothing measured yet: a probe chose before the first pass
    assert first.stats["direct_method"] == "LIGHT_SAMPLING"
    r = _auto(scene, samples=1, frame=1)
    assert r.stats["direct_method"] == "LIGHT_SAMPLING" and "Reservoir M" not in r.passes
    assert r.stats["indirect_method"] == "PATH" and r.stats["gi_skipped_passes"] == 1
    again = _auto(scene, samples=1, frame=0)
    assert np.array_equal(again.passes["Combined"], first.passes["Combined"])


def test_gi_reservoir_pass_makes_auto_resample():
    r = _auto(bounce_room(MIRROR, DIFFUSE, 48, 36), gi_reservoir_passes=True)
    assert r.stats["indirect_method"] == "RESTIR_GI" and "GI Reservoir M" in r.passes


def test_auto_probe_traces_at_most_probe_max_paths(monkeypatch):
    """The probe of a frame without a measurement traces one pixel in PROBE_PIXELS, at most PROBE_MAX (its cost
    stays bounded at high resolutions): its camera rays are the first the frame traces."""
    from restir_engine.core.pipeline import indirect_choice
    sizes = []
    real = camera_paths.primary

    def recording(ctx, x, *a, **k):
        sizes.append(len(x))
        return real(ctx, x, *a, **k)

    monkeypatch.setattr(camera_paths, "primary", recording)
    scene = bounce_room(DIFFUSE, DIFFUSE, 48, 36)
    _auto(scene, samples=1, seed=11)
    assert sizes[0] == 48 * 36 // indirect_choice.PROBE_PIXELS
    monkeypatch.setattr(indirect_choice, "PROBE_MAX", 20)
    sizes.clear()
    r = _auto(scene, samples=1, seed=12)
    assert sizes[0] == 20 and r.stats["indirect_method"] == "RESTIR_GI"
