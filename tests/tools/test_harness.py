"""The evaluation harness in quick mode on the smallest scene: charts and table are produced, and the
reference path tracer converges to the Cycles ground truth within a statistically derived tolerance
(this catches a wrong light unit, BSDF normalization or pixel filter)."""
import json

import numpy as np

from harness import metrics
from harness.evaluate import run
from harness.reference import reference_image
from harness.render import render_blend
from harness.scenes import ensure_blend

Z_MAX = 5.0


def test_quick_run_writes_charts_and_table(addon, tmp_path):
    summary = run("quick", str(tmp_path), ["path"], ["cornell"], animation=False, growth=False, log=lambda *_: None)
    for name in ("cornell-default.png", "cornell-default-strip.png", "summary.md", "results.json"):
        assert (tmp_path / name).exists(), name
    pts = sorted(summary["scenes"][0]["points"], key=lambda p: p["spp"])
    assert [p["spp"] for p in pts] == [1, 2, 4, 8]
    errs = [p["relmse"] for p in pts]
    # an unbiased estimator's error falls with samples (about as 1/spp); one realization per count (sharing
    # their first passes), with the 4-bounce Cornell box's fireflies: only the wide steps are checked (the
    # estimators' convergence itself is tested against Cycles elsewhere)
    assert errs[2] < errs[0] and errs[3] < errs[0], errs
    table = (tmp_path / "summary.md").read_text()
    assert "| cornell | Path tracer" in table
    assert json.loads((tmp_path / "results.json").read_text())["mode"] == "quick"


def test_path_tracer_converges_to_cycles_reference(addon):
    blend = ensure_blend("cornell", "default", "tiny")
    ref = reference_image(blend, 3, 1024)
    img, _wall, _core = render_blend(blend, "RESTIR", 256, 3, seed=7, settings={"integrator": "PATH"})
    bias = metrics.rel_bias(img, ref)
    se = metrics.bias_standard_error(img, ref)  # residual noise of both images
    assert se < 0.006, "too noisy to detect a 3% error"
    assert abs(bias) < Z_MAX * se, f"bias {bias:+.4f}, standard error {se:.4f}"
    for quadrant in (np.s_[:24, :32], np.s_[:24, 32:], np.s_[24:, :32], np.s_[24:, 32:]):
        mask = np.zeros(ref.shape[:2], bool)
        mask[quadrant] = True
        b, s = metrics.rel_bias(img, ref, mask), metrics.bias_standard_error(img, ref, mask)
        assert abs(b) < Z_MAX * s, f"quadrant bias {b:+.4f}, standard error {s:.4f}"


def test_pan_scene_moves_the_camera_and_default_cube_is_the_startup_file(addon):
    """The harness scenes added for the many-lights pan and the default cube build, and are what they say."""
    import bpy
    from harness.scenes import PAN_FRAMES
    bpy.ops.wm.open_mainfile(filepath=ensure_blend("many_lights_pan", "100", "tiny"))
    scene = bpy.context.scene
    scene.frame_set(1)
    first = scene.camera.matrix_world.copy()
    scene.frame_set(PAN_FRAMES)
    assert (scene.camera.matrix_world.translation - first.translation).length > 0.5
    assert abs(scene.camera.matrix_world.to_euler().z - first.to_euler().z) > 0.1
    bpy.ops.wm.open_mainfile(filepath=ensure_blend("default_cube", "default", "tiny"))
    names = {o.name for o in bpy.context.scene.objects}
    assert {"Cube", "Light", "Camera"} <= names
    assert bpy.data.objects["Light"].data.type == "POINT"
