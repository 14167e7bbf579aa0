"""Per-frame orchestration: tiles on the thread pool, sample passes, accumulation, passes out.

Images are (h, w, c) float32 with row 0 at the *bottom* (Blender's pass order), covering the
camera window (border) only.
"""
from __future__ import annotations

import dataclasses
import time
from concurrent.futures import FIRST_COMPLETED, wait
from dataclasses import dataclass, field

import numpy as np

from . import pathtracer, restir_di
from .accel import pool
from .boiling import boiling_filter
from .context_cache import context_for
from .light_tiles import TILE_MODES, LightTiles, TileSettings
from .sampling import STREAM_CAMERA, STREAM_TILES, STREAM_PATH, STREAM_SHADE, STREAM_SPATIAL, STREAM_TEMPORAL, rng
from .scene import Scene
from .target import FramePoints

INTEGRATORS = ("PATH", "RESTIR")


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
    direct_method: str = "RIS"  # with integrator RESTIR: "LIGHT_SAMPLING" (NEE + MIS) or "RIS"
    light_candidates: int = 32
    bsdf_candidates: int = 1
    spatial_neighbors: int = 5
    spatial_radius: float = 30.0
    spatial_passes: int = 1
    bias_correction: str = "UNBIASED"  # spatial/temporal reuse: "NONE" (1/M) or "UNBIASED" (pairwise MIS)
    temporal_reuse: bool = True  # ReSTIR: pass 0 of a frame reuses pass 0 of the previous frame (history)
    confidence_cap: float = 20.0
    boiling_filter: bool = False  # bias_correction NONE only: drop reservoirs far above their block's mean
    boiling_threshold: float = 20.0  # x the 16x16 block's mean p̂·W (core.boiling)
    light_tiles: str = "AUTO"  # light candidates from presampled tiles: "AUTO" (when it pays), "ON", "OFF"
    light_tile_count: int = 128
    light_tile_size: int = 1024
    film_transparent: bool = False
    data_passes: bool = True  # Depth, Normal and Vector (one more ray per pixel and frame); off when not written
    tile_pixels: int = 16384


@dataclass
class FrameResult:
    """passes: name -> (h, w, c) float32 (bottom row first); samples_done; seconds; cancelled."""

    passes: dict
    samples_done: int
    seconds: float
    cancelled: bool = False
    stats: dict = field(default_factory=dict)
    history: object = None  # restir_di.TemporalHistory for the next frame (ReSTIR with temporal reuse)


def _tiles(w: int, h: int, tile_pixels: int):
    """Square-ish tiles (x, y, tw, th) covering a w x h window."""
    side = max(8, int(np.sqrt(max(tile_pixels, 64))))
    return [(x, y, min(side, w - x), min(side, h - y)) for y in range(0, h, side) for x in range(0, w, side)]


class FrameRenderer:
    """One frame's acceleration structures and light table, rendering sample passes into accumulators.

    ``render_frame`` drives it for final renders; the viewport keeps one alive between redraws and
    swaps the camera with :meth:`set_camera` (geometry and lights stay built).
    """

    def __init__(self, scene: Scene, settings: RenderSettings, history=None):
        if settings.integrator not in INTEGRATORS:
            raise ValueError(f"unknown integrator {settings.integrator!r}; available: {INTEGRATORS}")
        t0 = time.perf_counter()
        self.settings = settings
        self.di = None
        if settings.integrator == "RESTIR":
            if settings.direct_method not in restir_di.DIRECT_METHODS:
                raise ValueError(f"unknown direct method {settings.direct_method!r}; available: {restir_di.DIRECT_METHODS}")
            tiles = TileSettings(settings.light_tiles, settings.light_tile_count, settings.light_tile_size)
            if tiles.mode not in TILE_MODES:
                raise ValueError(f"unknown light tile mode {tiles.mode!r}; available: {TILE_MODES}")
            self.di = restir_di.DISettings(settings.direct_method, max(0, settings.light_candidates),
                                           max(0, settings.bsdf_candidates), tiles)
            if settings.bias_correction not in restir_di.BIAS_CORRECTIONS:
                raise ValueError(f"unknown bias correction {settings.bias_correction!r}")
            self.spatial = restir_di.SpatialSettings(max(0, settings.spatial_neighbors),
                                                     max(1.0, float(settings.spatial_radius)),
                                                     max(0, settings.spatial_passes), settings.bias_correction)
        self.ctx, self.context_reused = context_for(scene, settings.max_bounces, settings.film_transparent,
                                                    pathtracer.build_context)
        self.build_seconds = time.perf_counter() - t0
        self.set_camera(scene.camera)
        if history is not None and self._history_fits(history):
            self.prev_history = history.remapped(self.ctx.lights)  # from the previous frame (None: lights cannot map)

    def set_camera(self, camera) -> None:
        """Use another camera (same scene) and restart accumulation."""
        self.ctx.scene.camera = camera
        _x0, _y0, w, h = camera.window
        self.tiles = _tiles(w, h, self.settings.tile_pixels)
        self.acc = {"emit": np.zeros((h, w, 3), np.float64), "direct": np.zeros((h, w, 3), np.float64),
                    "indirect": np.zeros((h, w, 3), np.float64), "alpha": np.zeros((h, w), np.float64),
                    "res_m": np.zeros((h, w), np.float64), "res_w": np.zeros((h, w), np.float64)}
        self.samples_done = 0
        self.boiling_dropped = 0  # reservoirs the boiling filter emptied since the camera was set
        self._data = None
        # temporal reuse runs through the first sample pass of each frame: pass 0 reuses the previous
        # frame's pass 0 (prev_history) and becomes the next frame's (history); the other passes of a frame
        # are independent of each other (chaining them correlates the passes being averaged: measured 2x the
        # relMSE of independent passes at 4 and 16 spp on many_lights)
        self.prev_history = None
        self.history = None

    def data_passes(self):
        """Depth (h, w, 1), Normal (h, w, 3) and Vector (h, w, 4) at pixel centres (one ray per pixel: no
        mixing of depths at silhouettes, as Cycles)."""
        if self._data is None:
            x0, y0, w, h = self.ctx.scene.camera.window
            depth = np.empty((h, w, 1), np.float32)
            normal = np.empty((h, w, 3), np.float32)
            vector = np.empty((h, w, 4), np.float32)

            def gbuffer_tile(tile):
                tx, ty, tw, th = tile
                cy, cx = np.mgrid[0:th, 0:tw]
                dep, nrm, vec = pathtracer.gbuffer(self.ctx, (x0 + tx + cx.ravel() + 0.5).astype(np.float32),
                                                   (y0 + ty + cy.ravel() + 0.5).astype(np.float32))
                depth[ty:ty + th, tx:tx + tw] = dep.reshape(th, tw, 1)
                normal[ty:ty + th, tx:tx + tw] = nrm.reshape(th, tw, 3)
                vector[ty:ty + th, tx:tx + tw] = vec.reshape(th, tw, 4)

            list(pool().map(gbuffer_tile, self.tiles))
            self._data = (depth, normal, vector)
        return self._data

    def _run_tile(self, args):
        s, ti, (tx, ty, tw, th) = args
        st = self.settings
        x0, y0 = self.ctx.scene.camera.window[:2]
        cam_rng = rng(st.seed, st.frame, s, STREAM_CAMERA, ti)
        path_rng = rng(st.seed, st.frame, s, STREAM_PATH, ti)
        jy, jx = np.mgrid[0:th, 0:tw]
        j = cam_rng.random((th * tw, 2), dtype=np.float32)
        x = x0 + tx + jx.ravel().astype(np.float32) + j[:, 0]
        y = y0 + ty + jy.ravel().astype(np.float32) + j[:, 1]
        reservoir = None
        if self.di is not None and self.di.method == "RIS":
            reservoir = {"M": np.zeros(th * tw, np.float32), "W": np.zeros(th * tw, np.float32)}
        elif self.di is not None and self.di.method == "RESTIR":
            w = self.ctx.scene.camera.window[2]
            ly, lx = np.mgrid[ty:ty + th, tx:tx + tw]
            reservoir = {"rows": (ly * w + lx).ravel(), "gbuf": self._gbuf, "res": self._res}
        out = pathtracer.trace(self.ctx, x, y, path_rng, di=self.di_pass, reservoir=reservoir)
        return (tx, ty, tw, th), (*out, reservoir)

    def sample_pass(self, progress=None, should_stop=None) -> bool:
        """Render the next sample pass (one path per pixel) into the accumulators. Returns False, keeping
        the accumulators unchanged, when ``should_stop`` asked to stop part-way."""
        s = self.samples_done
        self.di_pass = self.di
        self.used_tiles = False
        if self.di is not None and self.di.method in ("RIS", "RESTIR") and self.ctx.lights.tri_alias is not None:
            _x0, _y0, w, h = self.ctx.scene.camera.window
            st = self.settings
            if self.di.tile_settings.wanted(w * h, self.di.light_candidates):
                tiles = LightTiles(self.ctx.lights, self.di.tile_settings, w, h, rng(st.seed, st.frame, s, STREAM_TILES))
                self.di_pass = dataclasses.replace(self.di, tiles=tiles)
                self.used_tiles = True
        spatial = self.di is not None and self.di.method == "RESTIR"
        if spatial:  # frame-wide primary hits and initial reservoirs, filled by the tiles
            _x0, _y0, w, h = self.ctx.scene.camera.window
            self._gbuf = restir_di.GBuffer(w * h, self.ctx.material_params)
            self._res = restir_di.Reservoirs.empty(w * h)
        futures = {pool().submit(self._run_tile, (s, ti, t)) for ti, t in enumerate(self.tiles)}
        results = []
        while futures:
            finished, futures = wait(futures, timeout=0.25, return_when=FIRST_COMPLETED)
            results.extend(f.result() for f in finished)
            if progress:
                progress(len(results) / len(self.tiles))
            if should_stop and should_stop():
                for f in futures:
                    f.cancel()
                wait(futures)
                return False
        if spatial:
            self._spatial_and_shade(results, s)
        for (tx, ty, tw, th), (emit, direct, indirect, alpha, reservoir) in results:
            sl = (slice(ty, ty + th), slice(tx, tx + tw))
            self.acc["emit"][sl] += emit.reshape(th, tw, 3)
            self.acc["direct"][sl] += direct.reshape(th, tw, 3)
            self.acc["indirect"][sl] += indirect.reshape(th, tw, 3)
            self.acc["alpha"][sl] += alpha.reshape(th, tw)
            if reservoir is not None and "M" in reservoir:
                self.acc["res_m"][sl] += reservoir["M"].reshape(th, tw)
                self.acc["res_w"][sl] += reservoir["W"].reshape(th, tw)
        self.samples_done += 1
        return True

    def _history_fits(self, hist) -> bool:
        cam = self.ctx.scene.camera
        return (hist.camera.window[2:] == cam.window[2:]
                and (hist.camera.width, hist.camera.height) == (cam.width, cam.height))

    def _spatial_and_shade(self, results, s: int):
        """Spatial passes over the frame's reservoirs, then one shadow ray per pixel; adds the direct light
        and the reservoir figures into each tile's outputs."""
        _x0, _y0, w, h = self.ctx.scene.camera.window
        st = self.settings
        res = self._res
        spans = [np.arange(a, min(w * h, a + st.tile_pixels)) for a in range(0, w * h, st.tile_pixels)]
        if st.temporal_reuse and s == 0 and self.prev_history is not None:
            hist = self.prev_history
            # object motion is known for the previous frame only; a history from another frame gets none
            motion = self.ctx.scene.motion if hist.frame == st.frame - 1 else None
            parts = list(pool().map(lambda a: (a[1], restir_di.temporal_reuse(
                self.ctx, self._gbuf, res, hist, w, a[1], st.confidence_cap, st.bias_correction, motion,
                rng(st.seed, st.frame, s, STREAM_TEMPORAL, a[0]))), enumerate(spans)))
            res = restir_di.Reservoirs.gather(parts, w * h)
        if st.boiling_filter and st.bias_correction == "NONE":  # biased by design: never in the unbiased mode
            self.boiling_dropped += int(boiling_filter(res, self._gbuf.valid, w, h, st.boiling_threshold).sum())
        for k in range(self.spatial.passes if self.spatial.neighbors else 0):
            points = FramePoints(self.ctx.lights, res.light, res.b1, res.b2)
            parts = list(pool().map(lambda a: (a[1], restir_di.spatial_reuse(
                self.ctx, self._gbuf, res, w, h, a[1], self.spatial,
                rng(st.seed, st.frame, s, STREAM_SPATIAL + k, a[0]), points)), enumerate(spans)))
            res = restir_di.Reservoirs.gather(parts, w * h)
        direct = np.zeros((w * h, 3), np.float32)

        def shade(a):
            ti, rows = a
            live = rows[self._gbuf.valid[rows]]
            if live.size:
                sub = restir_di._SurfaceRows(self._gbuf, live)
                part = restir_di.Reservoirs(res.light[live], res.b1[live], res.b2[live], res.M[live], res.W[live],
                                            res.p_hat[live])
                direct[live] = restir_di.shade(self.ctx, sub, part, rng(st.seed, st.frame, s, STREAM_SHADE, ti))

        list(pool().map(shade, enumerate(spans)))
        if s == 0:  # the next frame's history; confidence at most the cap, so no reused M ever exceeds it
            capped = restir_di.Reservoirs(res.light, res.b1, res.b2, np.minimum(res.M, st.confidence_cap), res.W,
                                          res.p_hat)
            lights = self.ctx.lights
            self.history = restir_di.TemporalHistory(self._gbuf, capped, self.ctx.scene.camera, lights.signature,
                                                     st.frame, lights.light_uid, lights.uid_space)
        for (tx, ty, tw, th), (_e, d, _i, _a, reservoir) in results:
            rows = reservoir["rows"]
            d += direct[rows]
            reservoir["M"] = res.M[rows]
            reservoir["W"] = res.W[rows]

    def combined(self) -> np.ndarray:
        """The running mean of Combined (h, w, 4) float32."""
        inv = 1.0 / max(1, self.samples_done)
        rgb = (self.acc["emit"] + self.acc["direct"] + self.acc["indirect"]) * inv
        out = np.concatenate([rgb, (self.acc["alpha"] * inv)[..., None]], axis=2).astype(np.float32)
        return np.where(np.isfinite(out), out, 0.0).astype(np.float32)

    def passes(self) -> dict:
        """All passes (see :class:`FrameResult`); finite everywhere."""
        inv = 1.0 / max(1, self.samples_done)
        out = {"Combined": self.combined(), "Direct": self.acc["direct"] * inv, "Indirect": self.acc["indirect"] * inv,
               "Emission": self.acc["emit"] * inv}
        if self.settings.data_passes:
            out["Depth"], out["Normal"], out["Vector"] = self.data_passes()
        if self.di is not None and self.di.method in ("RIS", "RESTIR"):
            out["Reservoir M"] = (self.acc["res_m"] * inv)[..., None]
            out["Reservoir UCW"] = (self.acc["res_w"] * inv)[..., None]
        return {k: np.where(np.isfinite(v), v, 0.0).astype(np.float32) for k, v in out.items()}


def render_frame(scene: Scene, settings: RenderSettings, progress=None, should_stop=None, history=None) -> FrameResult:
    """Render one frame with the chosen integrator.

    progress(fraction, message) is called after every tile; should_stop() is polled after every tile,
    and a stop keeps the sample passes already completed (raises :class:`Cancelled` if none).
    """
    t0 = time.perf_counter()
    fr = FrameRenderer(scene, settings, history)
    cancelled = False
    for s in range(settings.samples):
        report = None
        if progress:
            def report(f, s=s):
                progress((s + f) / settings.samples, f"Sample {s + 1}/{settings.samples}")
        if not fr.sample_pass(report, should_stop):
            cancelled = True
            break
    if fr.samples_done == 0:
        raise Cancelled("render cancelled before the first sample pass finished")
    passes = fr.passes()
    ctx = fr.ctx
    return FrameResult(passes, fr.samples_done, time.perf_counter() - t0, cancelled,
                       {"build_seconds": fr.build_seconds, "light_tiles": fr.used_tiles, "triangles": len(scene.geometry),
                        "light_triangles": ctx.lights.n_tri, "suns": ctx.lights.n_sun,
                        "boiling_dropped": fr.boiling_dropped, "context_reused": fr.context_reused}, fr.history)
