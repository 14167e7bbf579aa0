"""Render > Time Limit: a frame stops after the sample that reaches the limit (F12 and animation frames, one or
several processes); the samples it did render are the same as without the limit, one sample per pass (the
limit is checked between samples, so a limited frame renders them one at a time)."""
import numpy as np


def _scene():
    from bpy_scenes import cornell_box
    from restir_engine.export import export_scene
    import bpy
    cornell_box("EMISSIVE", (48, 48))
    return export_scene(bpy.context.evaluated_depsgraph_get())


def test_time_limit_stops_early_with_the_same_samples(addon):
    from restir_engine.core.renderer import RenderSettings, render_frame
    scene = _scene()
    limited = render_frame(scene, RenderSettings(samples=10000, max_bounces=1, seed=2, time_limit=0.3), processes=1)
    assert 1 <= limited.samples_done < 10000 and limited.seconds < 0.3 + 10 * limited.seconds / limited.samples_done
    same = render_frame(scene, RenderSettings(samples=limited.samples_done, max_bounces=1, seed=2, sample_batch=1),
                        processes=1)
    np.testing.assert_array_equal(limited.passes["Combined"], same.passes["Combined"])


def test_time_limit_in_worker_processes(addon):
    from restir_engine.core.renderer import RenderSettings, render_frame
    scene = _scene()
    limited = render_frame(scene, RenderSettings(samples=10000, max_bounces=1, seed=2, time_limit=0.5), processes=2)
    assert 1 <= limited.samples_done < 10000
    same = render_frame(scene, RenderSettings(samples=limited.samples_done, max_bounces=1, seed=2, sample_batch=1),
                        processes=1)
    np.testing.assert_array_equal(limited.passes["Combined"], same.passes["Combined"])
