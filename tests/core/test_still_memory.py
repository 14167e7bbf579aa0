"""A still frame (F12: no next frame) keeps no temporal history, in one process and in a team of two: it renders the
same image as a frame that keeps one, and between its sample passes it holds less memory by at least the DI and GI
target terms the kept first pass would hold (tracemalloc of the core's arrays: deterministic, no noise). The film's
running sums are float32."""
import tracemalloc

import numpy as np
import pytest
from scenes_core import regression_room

from restir_engine.core.pipeline import film
from restir_engine.core.pipeline.frame import FrameRenderer
from restir_engine.core.renderer import RenderSettings, render_frame
from restir_engine.core.restir.target import WIDTH

W, H = 64, 48
ST = RenderSettings(samples=3, integrator="RESTIR", direct_method="RESTIR", indirect_method="RESTIR_GI",
                    max_bounces=2)


def _held_after_first_pass(keep_history: bool) -> int:
    """Bytes of NumPy arrays a frame renderer holds between its first and second sample pass (tracemalloc)."""
    scene = regression_room(W, H)
    render_frame(scene, ST, processes=1, bands=1)  # the scene's context is built (and cached) before counting
    film.BUFFERS.free.clear()
    tracemalloc.start()
    base = tracemalloc.get_traced_memory()[0]
    fr = FrameRenderer(scene, ST, keep_history=keep_history)
    assert fr.sample_pass(None, None, 1)
    held = tracemalloc.get_traced_memory()[0] - base
    tracemalloc.stop()
    assert (fr.history is not None) == keep_history
    fr.release()
    return held


def test_a_still_keeps_no_history_and_renders_the_same_image_in_less_memory():
    kept = render_frame(regression_room(W, H), ST, processes=1, bands=1, keep_history=True)
    still = render_frame(regression_room(W, H), ST, processes=1, bands=1, keep_history=False)
    assert kept.history is not None and still.history is None
    assert kept.stats["indirect_method"] == "RESTIR_GI" and kept.stats["direct_method"] == "RESTIR"
    for key, image in kept.passes.items():
        np.testing.assert_array_equal(image, still.passes[key], err_msg=key)
    # between its passes a frame that keeps its history holds the first pass's DI and GI target terms (WIDTH
    # float32 rows per pixel each) beyond what a still holds
    kept_bytes, still_bytes = _held_after_first_pass(True), _held_after_first_pass(False)
    assert kept_bytes - still_bytes >= 2 * WIDTH * 4 * W * H, (kept_bytes, still_bytes)


@pytest.mark.parametrize("keep_history", [True, False])
def test_a_team_keeps_history_only_when_asked(keep_history):
    solo = render_frame(regression_room(W, H), ST, processes=1, keep_history=keep_history)
    team = render_frame(regression_room(W, H), ST, processes=2, keep_history=keep_history)
    assert (team.history is not None) == keep_history == (solo.history is not None)
    for key, image in solo.passes.items():
        np.testing.assert_array_equal(image, team.passes[key], err_msg=key)


def test_film_sums_are_float32():
    f = film.Film(8, 4, gi=True, denoise_data=True, adaptive=True)
    assert {a.dtype for a in f.acc.values()} == {np.dtype(np.float32)}
    f.release()


def test_estimate_counts_the_target_terms_extension_rows():
    """A scene with an anisotropic lobe widens every target-term block by its six extension rows (restir/target.py):
    four float32 blocks per pixel (DI and GI, this frame's and the history's) under ReSTIR DI + GI, none under the
    path tracer."""
    from restir_engine.core.pipeline import memory
    from restir_engine.core.restir import target
    scene = regression_room()
    st = RenderSettings(integrator="RESTIR", direct_method="RESTIR", indirect_method="RESTIR_GI")
    plain = memory.frame_estimate(scene, st)
    scene.materials.aniso_aspect = scene.materials.aniso_aspect.copy()
    scene.materials.aniso_aspect[0] = 0.5
    rows = target.width(True) - target.WIDTH
    wide = memory.frame_estimate(scene, st)
    assert wide.low - plain.low == rows * 4 * 4 * plain.pixels
    assert memory.frame_estimate(scene, RenderSettings(integrator="PATH")).low == \
        memory.frame_estimate(regression_room(), RenderSettings(integrator="PATH")).low
