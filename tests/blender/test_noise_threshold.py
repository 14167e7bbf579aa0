"""Render Properties > Sampling > Noise Threshold: on in a new scene (as in Cycles), F12 stops converged pixels and
writes the Sample Count pass when asked for; off, every pixel takes the samples asked for and the pass does not
exist (no placeholder)."""
import numpy as np
import pytest


def _cornell(samples: int):
    import bpy
    from bpy_scenes import cornell_box
    scene = cornell_box("EMISSIVE", (40, 40))
    scene.render.engine = "RESTIR"
    scene.restir.samples = samples
    scene.restir.max_bounces = 1
    bpy.context.view_layer.restir.use_pass_sample_count = True
    return scene


def test_new_scene_renders_adaptively_with_a_sample_count_pass(addon):
    import bpy
    from bpy_scenes import render_passes
    scene = _cornell(160)
    assert scene.restir.use_adaptive_sampling and abs(scene.restir.adaptive_threshold - 0.01) < 1e-7
    passes = render_passes(scene)
    counts = passes["Sample Count"][..., 0]
    # the defaults: at least 64 samples, the first check after 80, every 16 after that, at most 160
    assert counts.min() >= 80 and counts.max() <= 160
    assert set(np.unique(counts)) <= {80.0, 96.0, 112.0, 128.0, 144.0, 160.0}
    assert counts.min() < counts.max(), "the box has converging and noisy pixels"
    assert np.isfinite(passes["Combined"]).all()
    scene.restir.use_adaptive_sampling = False
    scene.restir.samples = 4  # what is checked is which passes exist, not the samples
    bpy.context.view_layer.update_render_passes()
    assert "Sample Count" not in render_passes(scene)


@pytest.mark.slow_case  # long: dealt out between the Blenders in CI (tests/conftest.py)
def test_adaptive_image_agrees_with_uniform_sampling(addon):
    """The box's mean radiance from the adaptive render (Noise Threshold 0.01) against a uniform render of as many
    samples: the lower quadrants of the image (floor and walls; the upper ones hold the lamp's edge, whose pixel
    coverage noise swamps the comparison), each within the two renders' joint standard error (z < 5; the spread of the
    pixels' differences within a block is their noise). Power: a 4 % error in a quadrant is at least 5 of its standard
    errors in both."""
    from bpy_scenes import configure_restir, render_passes
    scene = _cornell(256)
    scene.restir.adaptive_min_samples = 16
    adaptive = render_passes(scene)["Combined"][..., :3].astype(np.float64)
    configure_restir(scene, 256, 1, 1)
    uniform = render_passes(scene)["Combined"][..., :3].astype(np.float64)
    # the lamp seen directly (and its edge, noisy from pixel coverage alone) left out: what is compared is the
    # light the box reflects
    keep = (uniform.max(axis=-1) < 0.5).reshape(2, 20, 2, 20)
    diff = (adaptive - uniform).mean(axis=-1).reshape(2, 20, 2, 20)
    n = keep.sum(axis=(1, 3))

    def block_mean(a):
        return np.where(keep, a.mean(axis=-1).reshape(2, 20, 2, 20), 0.0).sum(axis=(1, 3)) / n

    ma, mu = block_mean(adaptive), block_mean(uniform)
    d = np.where(keep, diff, 0.0)
    var = (np.where(keep, diff ** 2, 0.0).sum(axis=(1, 3)) - d.sum(axis=(1, 3)) ** 2 / n) / (n - 1)
    se = np.sqrt(var / n)
    lit = (mu > 0.01) & (np.arange(2)[:, None] == 0)  # the lower half: the upper holds the lamp's edge
    z = np.abs(ma - mu)[lit] / se[lit]
    assert (z < 5).all(), (z.round(1), (ma / np.maximum(mu, 1e-9)).round(4))
    assert (0.04 * mu[lit] > 5 * se[lit]).all(), "too noisy to see a 4 % error"
