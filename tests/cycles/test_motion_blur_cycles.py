"""Motion blur against Cycles (same bpy, CPU) on frame 2 of an animation: a cube flying over a lit floor, a glowing
bar spinning, the camera panning, a glowing sheet deforming (shape key); 1 bounce, 8 x 8 image cells with the
materials tests' bound (tests/stats.py). Our path tracer, ReSTIR DI and ReSTIR DI + GI in their unbiased modes with
temporal and spatial reuse. Power: the same file rendered sharp (motion blur off) must fail in 3 cells or more."""
import numpy as np
import pytest
from bpy_scenes import motion_blur_scene
from cycles_compare import cycles_reference, ours_cells
from stats import Z_MAX, assert_cells_match, cell_means, image_cells

SIZE = (96, 64)
CASES = {"center": dict(shutter=1.0, camera_pans=True, deform=True),
         "start": dict(shutter=0.5, camera_pans=False, deform=True, position="START")}
METHODS = {"PATH": {"integrator": "PATH"},
           "RESTIR_DI": {"integrator": "RESTIR", "direct_method": "RESTIR", "indirect_method": "PATH",
                         "bias_correction": "UNBIASED", "temporal_reuse": True, "spatial_neighbors": 5},
           "RESTIR_GI": {"integrator": "RESTIR", "direct_method": "RESTIR", "indirect_method": "RESTIR_GI",
                         "bias_correction": "UNBIASED", "temporal_reuse": True, "spatial_neighbors": 5}}


def _build(case, blur=True):
    spec = dict(CASES[case])
    position = spec.pop("position", "CENTER")
    scene = motion_blur_scene(SIZE, **spec)
    scene.render.motion_blur_position = position
    scene.render.use_motion_blur = blur
    return scene


@pytest.mark.parametrize("case,method", [("center", "PATH"), ("center", "RESTIR_DI"), ("center", "RESTIR_GI"),
                                         ("start", "PATH")])
def test_motion_blur_matches_cycles(addon, case, method):
    masks = image_cells(SIZE, 8)
    reduce = lambda im: cell_means(im, masks)  # noqa: E731
    ours = ours_cells(lambda: _build(case), 1, 32, reduce, **METHODS[method])
    ref = cycles_reference(f"motion_blur_{case}_b1", lambda: _build(case), 1, 128, reduce)
    names = [f"cell {i}" for i in range(len(masks))]
    lit = [i for i in range(len(masks)) if ref.mean(0)[i] > 0.02]
    assert_cells_match(ours[:, lit], ref[:, lit], [names[i] for i in lit])
    if method == "PATH":
        sharp = ours_cells(lambda: _build(case, blur=False), 1, 32, reduce, **METHODS[method])
        a, b = sharp[:, lit], ref[:, lit]
        z = np.abs(a.mean(0) - b.mean(0)) / np.sqrt(a.var(0, ddof=1) / len(a) + b.var(0, ddof=1) / len(b))
        assert (z > Z_MAX).sum() >= 3, "the sharp frame is not told apart from the blurred one"
