"""Sample batches (core/renderer.py): a pass without reservoirs renders several samples of every pixel at once.

The batched image must be the same estimator as one sample per pass: the samples' sums go to the right pixels
(exact checks on what has no variance: alpha, the world seen directly, the sample count) and the lit surfaces
agree with unbatched renders within noise (Welch z-scores of block means over independent seeds, as
tests/core/test_regression_images.py).
"""
import dataclasses

import numpy as np
from regression import block_stats
from scenes_core import regression_room, small_plane_under_world

from restir_engine.core.renderer import FrameRenderer, RenderSettings, render_frame
from stats import welch_se


def test_batches_count_and_place_every_sample():
    """Batches of 3 for 8 samples: passes of 3, 3, 2 samples; alpha exactly 1; the world seen directly sums to
    exactly k/8 in every pixel (k of its 8 camera rays missed the square) and is exactly 1 away from it."""
    scene = small_plane_under_world()
    st = RenderSettings(samples=8, max_bounces=1, seed=4, data_passes=False, sample_batch=3)
    fr = FrameRenderer(scene, st)
    done = []
    while fr.samples_done < st.samples:
        assert fr.sample_pass(batch=fr.batch_size(st.samples - fr.samples_done))
        done.append(fr.samples_done)
    assert done == [3, 6, 8]
    res = render_frame(scene, st)
    assert res.samples_done == 8
    alpha = res.passes["Combined"][..., 3]
    assert np.array_equal(alpha, np.ones_like(alpha))
    emission = res.passes["Emission"][..., 0]
    assert np.allclose(emission * 8, np.round(emission * 8), atol=1e-4)
    assert np.allclose(emission[:4], 1.0, atol=1e-6) and np.allclose(emission[:, :4], 1.0, atol=1e-6)
    assert np.allclose(emission[12:20, 12:20], 0.0)
    lit = res.passes["Direct"][12:20, 12:20, 0]  # albedo 0.5 under a unit world, unoccluded: exactly 0.5 in mean
    assert abs(lit.mean() - 0.5) < 0.02
    # the denoising data are summed the same way: inside the square every sample's albedo is 0.5
    res = render_frame(scene, dataclasses.replace(st, denoise_data=True))
    assert np.allclose(res.passes["Denoising Albedo"][12:20, 12:20], 0.5, atol=1e-5)
    assert np.allclose(res.passes["Denoising Albedo"][:4], 0.0)


def test_batched_passes_render_the_same_image():
    """The regression room, path tracer and light sampling, 4 spp: batches of 4 (sample_batch) against one
    sample per pass, 24 seeds each; every block statistic |z| < 5."""
    scene = regression_room(64, 48)
    for cfg in (dict(integrator="PATH", max_bounces=2),
                dict(integrator="RESTIR", direct_method="LIGHT_SAMPLING", max_bounces=1)):
        stats = {}
        for batch in (1, 4):
            stats[batch] = np.array([block_stats(render_frame(scene, RenderSettings(
                samples=4, seed=300 + k, data_passes=False, sample_batch=batch, **cfg)).passes)
                for k in range(24)])
        a, b = stats[4], stats[1]
        se = welch_se(a, b)
        assert se[-2] < 0.01 * b[:, -2].mean()  # can see a 3 % change of the direct light
        z = np.where(se > 1e-12, (a.mean(axis=0) - b.mean(axis=0)) / np.maximum(se, 1e-12), 0.0)
        assert np.abs(z).max() < 5.0, (cfg, z)


def test_auto_batches_only_where_few_pixels_see_a_surface():
    """Automatic batches: none in the first pass (nothing measured), none where a chunk's pixels all see a surface
    (chunks of 256 pixels here), some where few do, and none where the pass resamples (ReSTIR keeps per-pixel
    reservoirs)."""
    room = regression_room(64, 48)
    fr = FrameRenderer(room, RenderSettings(samples=8, integrator="PATH", max_bounces=1, data_passes=False,
                                            tile_pixels=256))
    assert fr.batch_size(8) == 1
    fr.sample_pass()
    assert fr.batch_size(7) == 1  # the room fills the view: a chunk already holds its pixels' surfaces

    fr = FrameRenderer(small_plane_under_world(), RenderSettings(samples=8, integrator="PATH", max_bounces=1, data_passes=False,
                                           tile_pixels=256))
    fr.sample_pass()
    assert 1 < fr.batch_size(7) <= 7
    fr = FrameRenderer(room, RenderSettings(samples=8, integrator="RESTIR", direct_method="RESTIR", max_bounces=0,
                                            data_passes=False, sample_batch=4))
    assert fr.batch_size(8) == 1  # asked for 4, but this pass resamples: render_frame's progress counts 1
    assert fr.sample_pass(batch=4) and fr.samples_done == 1
    sparse = FrameRenderer(small_plane_under_world(), RenderSettings(
        samples=8, integrator="RESTIR", direct_method="RESTIR", max_bounces=1, data_passes=False, tile_pixels=256))
    sparse.sample_pass()
    assert sparse.batch_size(7) == 1  # few surfaces per chunk, but reservoirs keep per-pixel state
