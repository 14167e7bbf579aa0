"""Frames with unchanged scene content reuse the acceleration structures and light table."""
import numpy as np

from restir_engine.core.integrators import context_cache
from restir_engine.core.renderer import RenderSettings, render_frame
from scenes_core import floor_with_emitter

ST = dict(samples=2, max_bounces=1, integrator="RESTIR", direct_method="RESTIR", light_candidates=4)


def test_unchanged_scene_reuses_the_context_and_renders_the_same():
    context_cache.clear()
    first = render_frame(floor_with_emitter(width=16), RenderSettings(**ST, seed=3))
    again = render_frame(floor_with_emitter(width=16), RenderSettings(**ST, seed=3))  # a fresh export, same content
    assert not first.stats["context_reused"] and again.stats["context_reused"]
    assert np.array_equal(first.passes["Combined"], again.passes["Combined"])
    context_cache.clear()
    rebuilt = render_frame(floor_with_emitter(width=16), RenderSettings(**ST, seed=3))
    assert not rebuilt.stats["context_reused"]
    assert np.array_equal(first.passes["Combined"], rebuilt.passes["Combined"])


def test_any_change_rebuilds():
    context_cache.clear()
    render_frame(floor_with_emitter(width=16), RenderSettings(**ST))
    moved = floor_with_emitter(width=16)
    moved.geometry.verts[2:, :, 0] += 1e-3  # the emitter moved by a millimetre
    assert not render_frame(moved, RenderSettings(**ST)).stats["context_reused"]
    brighter = floor_with_emitter(width=16, le=4.5)  # same geometry, another emission
    assert not render_frame(brighter, RenderSettings(**ST)).stats["context_reused"]
    camera_only = floor_with_emitter(width=16, le=4.5)
    camera_only.camera.cam_to_world[0, 3] += 0.2  # only the camera moved: reuse
    assert render_frame(camera_only, RenderSettings(**ST)).stats["context_reused"]
