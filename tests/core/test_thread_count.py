"""The same seed gives the same image whatever the number of threads: the work's split into chunks (each with its
own random stream) depends on the image and the settings, never on the pool's size."""
import numpy as np
import pytest
from scenes_core import regression_room

from restir_engine.core.parallel import pool as pool_mod
from restir_engine.core.parallel import tasks
from restir_engine.core.renderer import RenderSettings, render_frame


def _render(settings):
    scene = regression_room(160, 120)
    first = render_frame(scene, settings)
    return render_frame(scene, RenderSettings(**{**settings.__dict__, "frame": 2}), history=first.history).passes


@pytest.mark.parametrize("settings", [
    RenderSettings(integrator="PATH", samples=2, max_bounces=2, tile_pixels=2048),
    RenderSettings(integrator="RESTIR", direct_method="RESTIR", indirect_method="RESTIR_GI", samples=1,
                   max_bounces=1, tile_pixels=2048),
], ids=["path", "restir-di-gi"])
def test_one_and_several_threads_give_the_same_image(settings, monkeypatch):
    images = []
    for threads in (1, 3, 5):
        monkeypatch.setattr(pool_mod, "thread_count", lambda n=threads: n)
        monkeypatch.setattr(tasks, "thread_count", lambda n=threads: n, raising=False)  # wherever it is read
        monkeypatch.setattr(pool_mod, "_POOL", None)  # a pool of that many threads
        images.append(_render(settings))
        assert pool_mod.pool()._max_workers == threads
        pool_mod.pool().shutdown()
        monkeypatch.setattr(pool_mod, "_POOL", None)
    monkeypatch.setattr(pool_mod, "_POOL", None)
    for other in images[1:]:
        for name in ("Combined", "Direct", "Indirect"):
            assert np.array_equal(images[0][name], other[name]), name


def test_the_split_ignores_the_pool_and_balances_it():
    assert tasks.chunk_size(230400, 32768) == 28800  # 640x360: 8 chunks
    assert tasks.chunk_size(921600, 32768) == 28800  # 1280x720: 32 chunks (MIN_CHUNKS), 16 processes get 2 each
    assert tasks.chunk_size(14400, 16384) == 7200  # 2 chunks: both threads of a small viewport pass work
    n = 100000
    count = -(-n // tasks.chunk_size(n, 4096))
    assert count % tasks.BALANCE == 0
