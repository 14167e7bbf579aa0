"""Per-frame orchestration: tiles on the thread pool, sample passes, accumulation, passes out.

Images are (h, w, c) float32 with row 0 at the *bottom* (Blender's pass order), covering the
camera window (border) only.
"""
from __future__ import annotations

import time
from concurrent.futures import FIRST_COMPLETED, wait
from dataclasses import dataclass, field

import numpy as np

from . import pathtracer
from .accel import pool
from .sampling import STREAM_CAMERA, STREAM_PATH, rng
from .scene import Scene

INTEGRATORS = ("PATH",)


class Cancelled(Exception):
    """Raised when ``should_stop`` asked to stop before any sample pass finished."""


@dataclass
class RenderSettings:
    """samples: sample passes averaged per frame; seed: noise seed; max_bounces: 0 = direct only;
    frame: frame number (keys the random streams)."""

    samples: int = 16
    seed: int = 0
    max_bounces: int = 4
    frame: int = 0
    integrator: str = "PATH"
    film_transparent: bool = False
    tile_pixels: int = 16384


@dataclass
class FrameResult:
    """passes: name -> (h, w, c) float32 (bottom row first); samples_done; seconds; cancelled."""

    passes: dict
    samples_done: int
    seconds: float
    cancelled: bool = False
    stats: dict = field(default_factory=dict)


def _tiles(w: int, h: int, tile_pixels: int):
    """Square-ish tiles (x, y, tw, th) covering a w x h window."""
    side = max(8, int(np.sqrt(max(tile_pixels, 64))))
    return [(x, y, min(side, w - x), min(side, h - y)) for y in range(0, h, side) for x in range(0, w, side)]


def render_frame(scene: Scene, settings: RenderSettings, progress=None, should_stop=None) -> FrameResult:
    """Render one frame with the chosen integrator.

    progress(fraction, message) is called after every tile; should_stop() is polled after every tile,
    and a stop keeps the sample passes already completed (raises :class:`Cancelled` if none).
    """
    if settings.integrator not in INTEGRATORS:
        raise ValueError(f"unknown integrator {settings.integrator!r}; available: {INTEGRATORS}")
    t0 = time.perf_counter()
    ctx = pathtracer.build_context(scene, settings.max_bounces, settings.film_transparent)
    t_build = time.perf_counter() - t0
    x0, y0, w, h = scene.camera.window
    tiles = _tiles(w, h, settings.tile_pixels)
    acc = {"emit": np.zeros((h, w, 3), np.float64), "direct": np.zeros((h, w, 3), np.float64),
           "indirect": np.zeros((h, w, 3), np.float64), "alpha": np.zeros((h, w), np.float64)}
    # data passes at pixel centres (one ray per pixel; no mixing of depths at silhouettes, as Cycles)
    depth = np.empty((h, w, 1), np.float32)
    normal = np.empty((h, w, 3), np.float32)

    def gbuffer_tile(tile):
        tx, ty, tw, th = tile
        cy, cx = np.mgrid[0:th, 0:tw]
        dep, nrm = pathtracer.gbuffer(ctx, (x0 + tx + cx.ravel() + 0.5).astype(np.float32),
                                      (y0 + ty + cy.ravel() + 0.5).astype(np.float32))
        depth[ty:ty + th, tx:tx + tw] = dep.reshape(th, tw, 1)
        normal[ty:ty + th, tx:tx + tw] = nrm.reshape(th, tw, 3)

    list(pool().map(gbuffer_tile, tiles))
    done = 0
    cancelled = False
    total_units = max(1, settings.samples * len(tiles))

    def run_tile(args):
        s, ti, (tx, ty, tw, th) = args
        cam_rng = rng(settings.seed, settings.frame, s, STREAM_CAMERA, ti)
        path_rng = rng(settings.seed, settings.frame, s, STREAM_PATH, ti)
        jy, jx = np.mgrid[0:th, 0:tw]
        jx = jx.ravel().astype(np.float32)
        jy = jy.ravel().astype(np.float32)
        j = cam_rng.random((jx.size, 2), dtype=np.float32)
        x = x0 + tx + jx + j[:, 0]
        y = y0 + ty + jy + j[:, 1]
        out = pathtracer.trace(ctx, x, y, path_rng)
        return (tx, ty, tw, th), out

    for s in range(settings.samples):
        futures = {pool().submit(run_tile, (s, ti, t)) for ti, t in enumerate(tiles)}
        pass_out = []
        stop = False
        while futures:
            finished, futures = wait(futures, timeout=0.25, return_when=FIRST_COMPLETED)
            pass_out.extend(f.result() for f in finished)
            if progress:
                progress((s * len(tiles) + len(pass_out)) / total_units, f"Sample {s + 1}/{settings.samples}")
            if should_stop and should_stop():
                for f in futures:
                    f.cancel()
                wait(futures)
                stop = True
                break
        if stop:
            cancelled = True
            break
        for (tx, ty, tw, th), (emit, direct, indirect, alpha) in pass_out:
            sl = (slice(ty, ty + th), slice(tx, tx + tw))
            acc["emit"][sl] += emit.reshape(th, tw, 3)
            acc["direct"][sl] += direct.reshape(th, tw, 3)
            acc["indirect"][sl] += indirect.reshape(th, tw, 3)
            acc["alpha"][sl] += alpha.reshape(th, tw)
        done += 1
    if done == 0:
        raise Cancelled("render cancelled before the first sample pass finished")
    inv = 1.0 / done
    emit, direct, indirect = (acc[k] * inv for k in ("emit", "direct", "indirect"))
    rgb = emit + direct + indirect
    passes = {
        "Combined": np.concatenate([rgb, (acc["alpha"] * inv)[..., None]], axis=2).astype(np.float32),
        "Depth": depth,
        "Normal": normal,
        "Direct": direct.astype(np.float32),
        "Indirect": indirect.astype(np.float32),
        "Emission": emit.astype(np.float32),
    }
    for k, v in passes.items():
        passes[k] = np.where(np.isfinite(v), v, 0.0).astype(np.float32)
    seconds = time.perf_counter() - t0
    return FrameResult(passes, done, seconds, cancelled,
                       {"build_seconds": t_build, "triangles": len(scene.geometry),
                        "light_triangles": ctx.lights.n_tri, "suns": ctx.lights.n_sun})
