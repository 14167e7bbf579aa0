"""Frames rendered in horizontal bands (core/pipeline/bands.py) so that memory stays bounded: the bands tile the
window exactly (the pixel-centre data passes are identical to an unbanded render), their estimate converges to the
same image (per block, within the renders' joint standard error), one and two processes give the same image, each
band's history serves the next frame's band, and the band count follows the memory budget."""
import dataclasses

import numpy as np
import pytest
from scenes_core import regression_room

from restir_engine.core.pipeline import bands, memory
from restir_engine.core.renderer import RenderSettings, render_frame

W, H = 96, 72


def _settings(integrator, samples=8, **kw):
    return RenderSettings(samples=samples, integrator=integrator,
                          direct_method="RESTIR" if integrator == "RESTIR" else "RIS", max_bounces=1, **kw)


@pytest.mark.parametrize("integrator", ["PATH", "RESTIR"])
def test_bands_tile_the_window_exactly(integrator):
    one = render_frame(regression_room(W, H), _settings(integrator), processes=1, bands=1)
    three = render_frame(regression_room(W, H), _settings(integrator), processes=1, bands=3)
    assert three.stats["bands"] == 3 and one.passes.keys() == three.passes.keys()
    for key in ("Depth", "Normal", "Vector"):
        np.testing.assert_array_equal(one.passes[key], three.passes[key], err_msg=key)
    assert three.stats["band_margin"] == (0 if integrator == "PATH" else bands.margin_rows(
        _settings(integrator), regression_room(W, H).camera))


@pytest.mark.slow_case  # statistical: dealt out between the Blenders in CI (tests/conftest.py)
@pytest.mark.parametrize("integrator", ["PATH", "RESTIR"])
def test_banded_image_agrees_with_the_unbanded_one(integrator):
    """3 x 4 blocks of 24 x 24 pixels, 64 samples: |banded − unbanded| of each block's mean within 5 joint standard
    errors (the spread of the 576 pixels' differences); the band edges (rows 24 and 48) are block edges, each band's
    rows next to them in a block. Power: the median block sees a 3 % error."""
    st = _settings(integrator, samples=64)
    one = render_frame(regression_room(W, H), st, processes=1, bands=1).passes["Combined"][..., :3]
    three = render_frame(regression_room(W, H), st, processes=1, bands=3).passes["Combined"][..., :3]
    diff = (three.astype(np.float64) - one).mean(axis=-1).reshape(3, 24, 4, 24)
    mean = one.astype(np.float64).mean(axis=-1).reshape(3, 24, 4, 24).mean(axis=(1, 3))
    se = diff.std(axis=(1, 3), ddof=1) / 24.0
    z = np.abs(diff.mean(axis=(1, 3))) / np.maximum(se, 1e-12)
    assert (z < 5).all(), z.round(1)
    assert np.median(0.03 * mean / np.maximum(se, 1e-12)) > 5


def test_bands_in_two_processes_and_their_history():
    st = _settings("RESTIR")
    solo = render_frame(regression_room(W, H), st, processes=1, bands=3)
    team = render_frame(regression_room(W, H), st, processes=2, bands=3)
    for key, image in solo.passes.items():
        np.testing.assert_array_equal(image, team.passes[key], err_msg=key)
    assert isinstance(solo.history, bands.BandHistory) and len(solo.history.histories) == 3
    nxt = render_frame(regression_room(W, H), dataclasses.replace(st, frame=1), processes=1, bands=3,
                       history=solo.history)
    assert nxt.stats["reuse"]["temporal_accepted"] > 0.9  # the scene did not move: every band reprojects
    # each band's history kept in the workers for the same band of the next frame (not overwritten by the other
    # bands' first passes, not dropped when a larger band needs larger buffers)
    team_next = render_frame(regression_room(W, H), dataclasses.replace(st, frame=1), processes=2, bands=3,
                             history=team.history)
    for key, image in nxt.passes.items():
        np.testing.assert_array_equal(image, team_next.passes[key], err_msg=key)
    still = render_frame(regression_room(W, H), st, processes=1, bands=3, keep_history=False)
    assert still.history is None


def test_band_seeds_differ_and_the_layout_covers_the_rows():
    assert bands.band_seed(5, 0) == 5 and len({bands.band_seed(5, i) for i in range(64)}) == 64
    rows = bands.layout(1000, 7)
    assert rows[0][0] == 0 and rows[-1][1] == 1000 and all(a[1] == b[0] for a, b in zip(rows, rows[1:]))


def test_band_count_follows_the_memory_budget():
    scene = regression_room(W, H)
    st = RenderSettings(integrator="RESTIR", direct_method="AUTO", indirect_method="AUTO", max_bounces=2)
    assert bands.bands_needed(scene, st, None) == 1  # a small frame: one band
    cam = scene.camera
    scene.camera = dataclasses.replace(cam, width=3840, height=2160, window=(0, 0, 3840, 2160))
    n, m = bands.plan(scene, st, None)
    _low, high = memory.per_pixel_range(st)
    assert n > 1 and high * 3840 * (-(-2160 // n) + 2 * m) <= memory.BAND_BYTES * 1.05
    assert 0 < m <= bands.margin_rows(st, scene.camera)
    assert bands.plan(scene, st, None, keeps_history=False)[0] < n  # a still holds no second G-buffer: wider bands
    scene.camera = dataclasses.replace(cam, width=7680, height=4320, window=(0, 0, 7680, 4320))
    n8, m8 = bands.plan(scene, st, None)  # 8K: the 97-row radius would dwarf a band: cut to a quarter of it
    assert m8 < bands.margin_rows(st, scene.camera) and 2 * m8 <= (-(-4320 // n8))
    assert high * 7680 * (-(-4320 // n8) + 2 * m8) <= memory.BAND_BYTES * 1.05
    scene.camera = dataclasses.replace(cam, width=3840, height=2160, window=(0, 0, 3840, 2160))
    whole = memory.frame_estimate(scene, st)
    banded = memory.banded_estimate(scene, st, n, m, keeps_history=False)
    assert banded.high < whole.high / 3  # 4K with every ReSTIR stage: about 16 GB whole, 3.8 GB banded
    assert banded.high < 4 << 30
    tight = bands.bands_needed(scene, st, 1 << 30)  # 1 GB free: bands of at most 512 MB
    assert tight > n
