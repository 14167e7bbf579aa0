"""Per-frame orchestration: a sample pass as named stages over the whole window, chunks on the thread pool.

Stages of a sample pass (each timed by a profile.StageClock when one is given):
  primary   camera rays (pass s of a pixel at Sobol point s, digitally shifted per pixel), emission seen directly, the
            G-buffer (every integrator); with pixel coverage
            (``coverage_samples`` > 1) the pixel is split into that many strata: the surface is shaded at the
            pass's ray (in whichever stratum it falls), the emission seen directly (and alpha) is averaged over one ray per stratum
            (both are unbiased estimates of the box-filtered pixel)
  initial   ReSTIR/RIS: light tiles, target terms and initial resampling (light + BSDF candidates)
  paths     the first vertex's BSDF ray and bounces 1..max_bounces (pathtracer.continue_paths); it needs no
            reservoir, so it runs before reuse and the first BSDF candidate's ray it takes over is freed early
  gbuffer   ReSTIR: the frame's G-buffer and reservoirs assembled from the chunks
  temporal  ReSTIR, first pass of a frame: merge with the previous frame's reservoirs
  boiling   ReSTIR biased mode with the boiling filter
  spatial   ReSTIR: spatial reuse passes
  shade     direct light: the reservoirs' samples with shadow rays (ReSTIR/RIS), or next-event estimation
  passes    accumulation into the running means
Images are (h, w, c) float32 with row 0 at the *bottom* (Blender's pass order), covering the camera window
(border) only. Pixels are row-major over the window; a chunk is a span of CHUNK_PIXELS pixels and its
random streams are keyed by (seed, frame, pass, stream, chunk), so images do not depend on scheduling.

Sample batches: a pass that keeps no per-pixel state between its stages' pixels (no reservoirs, no ReSTIR GI, no
measurement) may render several samples at once: its chunks then hold their pixel span once per sample
(``_Chunk.batch``), so every array of the pass is that many times longer. Where few pixels see a surface (the
default cube: 15 % of the image) a chunk otherwise holds a few thousand paths and the pass is bound by NumPy's
per-call cost, under the GIL, so the two threads gain nothing; ``FrameRenderer.batch_size`` sizes batches to about
CHUNK_PIXELS surfaces per chunk (measured: scripts/benchmark_default_cube.py).
"""
from __future__ import annotations

import dataclasses
import threading
import time
from concurrent.futures import FIRST_COMPLETED, wait
from dataclasses import dataclass, field

import numpy as np

from .geometry import camera as camera_mod
from .integrators import pathtracer
from .integrators.context_cache import context_for, fingerprint
from .integrators.method_choice import (
    GI_MIN_SHARE,
    WORLD_METHODS,
    choose_direct_method,
    choose_indirect_method,
    choose_world_method,
)
from .lights.blocks import BlockLightTiles
from .lights.tiles import TILE_MODES, LightTiles, TileSettings
from .materials.bsdf import denoising_albedo, luminance_rows
from .parallel.pool import in_worker, pool, thread_count
from .profile import NullClock
from .restir import di, gi, reuse
from .restir.boiling import THRESHOLD as BOILING_THRESHOLD
from .restir.boiling import boiling_filter
from .restir.gbuffer import GBuffer
from .restir.history import TemporalHistory
from .restir.target import WIDTH, ShadingTerms
from .sampling import (
    STREAM_CAMERA,
    STREAM_CHAIN,
    STREAM_GI_SPATIAL,
    STREAM_GI_TEMPORAL,
    STREAM_INITIAL,
    STREAM_PATH,
    STREAM_PIXEL_OFFSET,
    STREAM_PROBE,
    STREAM_SHADE,
    STREAM_SPATIAL,
    STREAM_TEMPORAL,
    STREAM_TILES,
    finite,
    pass_jitter,
    rng,
)
from .scene import Scene

INTEGRATORS = ("PATH", "RESTIR")
CHUNK_PIXELS = 32768  # pixels per chunk of work (measured: scripts/benchmark_stages.py --tile-sweep)
MAX_BATCH = 8  # samples one pass renders at most (FrameRenderer.batch_size)
STOP_POLL_SECONDS = 0.02  # how often a running stage asks should_stop (the viewport's latency to a new view)


class Cancelled(Exception):
    """Raised when ``should_stop`` asked to stop before any sample pass finished."""


@dataclass
class RenderSettings:
    """samples: sample passes averaged per frame; seed: noise seed; max_bounces: 0 = direct only;
    frame: frame number (keys the random streams). Stage defaults come from the stages' own settings
    (di.CandidateSettings, reuse.SpatialSettings, TileSettings)."""

    samples: int = 16
    seed: int = 0
    max_bounces: int = 4
    frame: int = 0
    integrator: str = "PATH"
    direct_method: str = "RIS"  # with integrator RESTIR: "AUTO", "LIGHT_SAMPLING" (NEE + MIS), "RIS" or "RESTIR"
    reservoir_passes: bool = False  # a reservoir pass is wanted (AUTO then resamples: method_choice)
    light_candidates: int = di.CandidateSettings.light_candidates
    bsdf_candidates: int = di.CandidateSettings.bsdf_candidates
    world_method: str = "AUTO"  # the world with resampled direct light: "AUTO", "RESAMPLED", "LIGHT_SAMPLED"
    world_candidates: int = di.CandidateSettings.world_candidates
    spatial_neighbors: int = reuse.SpatialSettings.neighbors
    spatial_radius: float = reuse.SpatialSettings.radius  # pixels; 0 = automatic (reuse.auto_radius)
    spatial_passes: int = reuse.SpatialSettings.passes
    bias_correction: str = reuse.SpatialSettings.bias_correction  # "NONE" (1/M) or "UNBIASED" (pairwise MIS)
    temporal_reuse: bool = True  # ReSTIR: pass 0 of a frame reuses pass 0 of the previous frame (history)
    confidence_cap: float = reuse.TemporalSettings.confidence_cap
    boiling_filter: bool = False  # bias_correction NONE only: drop reservoirs far above their block's mean
    boiling_threshold: float = BOILING_THRESHOLD  # x the 16x16 block's mean p̂·W (core.boiling)
    light_tiles: str = TileSettings.mode  # light candidates from presampled tiles: "AUTO", "ON", "OFF"
    light_tile_count: int = TileSettings.count
    light_tile_size: int = TileSettings.size
    light_sampler: str = "SPATIAL"  # light tiles: "SPATIAL" (per-block importance, light_blocks.py) or "POWER"
    film_transparent: bool = False
    data_passes: bool = True  # Depth, Normal and Vector (one more ray per pixel and frame); off when not written
    denoise_data: bool = False  # Denoising Albedo / Normal: first-hit albedo and camera-space normal, per sample
    tile_pixels: int = CHUNK_PIXELS  # pixels per chunk of work (smaller: finer progress and cancellation)
    sample_batch: int = 0  # samples a pass renders at once where it can (module docstring); 0 = automatic
    coverage_samples: int = 0  # camera rays per pixel for the emission seen directly: 1, 4, 9, 16 ...; 0 = automatic
    indirect_method: str = "PATH"  # with integrator RESTIR: "AUTO" (method_choice), "OFF" (no bounces), "PATH" or
    #                                "RESTIR_GI" (restir/gi.py)
    gi_reservoir_passes: bool = False  # a GI reservoir pass is wanted (AUTO then resamples the indirect light)
    gi_spatial_neighbors: int = gi.GISettings.neighbors
    gi_spatial_radius: float = gi.GISettings.radius  # pixels; 0 = automatic (GI_RADIUS_FACTOR x reuse.auto_radius)
    gi_spatial_passes: int = gi.GISettings.passes
    gi_confidence_cap: float = gi.GISettings.confidence_cap
    gi_max_age: int = gi.GISettings.max_age  # frames a GI sample may be reused for
    gi_roughness_threshold: float = gi.GISettings.roughness_threshold
    gi_target: str = "INTEGRAND"  # GI target function (gi.GI_TARGETS); the alternative is kept for measurements only


def coverage_samples(setting: int, lights, lamps, camera=None) -> tuple[int, str]:
    return _coverage(setting, lights, lamps, camera)[:2]


def _coverage(setting: int, lights, lamps, camera=None) -> tuple[int, str, np.ndarray | None]:
    """Strata per pixel for the emission seen directly (a square number) and why: ``setting`` rounded down to a
    square, or when 0 (automatic): 1 where the camera can see no emitter (none visible to camera rays, or, given
    the ``camera``, none inside its view); MANY_COVERAGE where it sees many emissive triangles (at least
    MANY_EMITTERS: small emitters partly covering many pixels), else AUTO_COVERAGE. Measured (docs/RESULTS.md,
    "Pixel coverage"; relMSE of Combined at equal time against 1 ray): many_lights 10k 2.5x (4 rays) and 3.6x
    (16), 1k 1.8x and 1.6x, the Cornell box 1.05x and 0.8x. The third value: the pixels that get the extra rays
    (coverage_pixels; None: all of them)."""
    if setting > 0:
        g = max(1, int(np.sqrt(setting + 1e-9)))
        return g * g, "set by the user", None
    lamps_seen = bool(len(lamps.tris) and lamps.camera_visible.any())
    if lights.n_geom >= MANY_EMITTERS:
        return MANY_COVERAGE, f"{lights.n_geom} emissive triangles: small emitters partly cover many pixels", None
    if lights.n_geom > 0 or lamps_seen:
        mask = None if camera is None else coverage_pixels(camera, lights, lamps)
        if mask is not None and not mask.any():
            return 1, "no emitter in view", None
        return AUTO_COVERAGE, "emitters can be seen directly", mask
    return 1, "no emitter can be seen directly", None


GEOMETRY_MASK_MAX = 0.9  # the share of the window above which masking camera rays by object boxes is not worth it


def _geometry_mask(ctx, camera) -> np.ndarray | None:
    """(window pixels,) bool: where a camera ray may meet geometry (the projected boxes of the instances,
    camera.box_pixels); elsewhere it sees only lamps and the world, and is not traced. None when it would mark
    most of the window anyway."""
    derived = ctx.geom_derived
    if derived is None or derived.boxes is None:
        return None
    mask = camera_mod.box_pixels(camera, *derived.boxes).ravel()
    return None if mask.mean() > GEOMETRY_MASK_MAX else mask


def _lamp_mask(ctx, camera) -> np.ndarray | None:
    """(window pixels,) bool: where a camera ray may see a lamp visible to camera rays (the projected boxes of their
    triangles and sphere proxies, camera.emitter_pixels); elsewhere lamps are not intersected. None when it would
    mark most of the window anyway."""
    lamps = ctx.scene.lamps
    if len(lamps.tris) == 0:
        return None
    vis = lamps.camera_visible
    mask = camera_mod.emitter_pixels(camera, lamps.tris.verts[vis], np.zeros((0, 3)), np.zeros(0)).ravel()
    return None if mask.mean() > GEOMETRY_MASK_MAX else mask


def _seen_lights(lights, lamps) -> np.ndarray:
    """(n_tri,) bool: the light entries camera rays can see (emissive triangles; lamps visible to the camera)."""
    seen = np.ones(lights.n_tri, bool)
    if len(lights.lamp_ids):
        seen[lights.n_geom:] = lamps.camera_visible[lights.lamp_ids]
    return seen


def coverage_pixels(camera, lights, lamps):
    """(h * w,) bool: the pixels near an emitter the camera can see, where the extra coverage rays pay (elsewhere
    the shaded ray's emission alone is the estimate: both unbiased); None (every pixel) from MANY_EMITTERS on."""
    if lights.n_geom >= MANY_EMITTERS:
        return None
    v = lights.tri_verts
    seen = _seen_lights(lights, lamps)
    sph = lights.sphere_r > 0
    tri = seen & ~sph
    return camera_mod.emitter_pixels(camera, v[tri], v[seen & sph, 0], lights.sphere_r[seen & sph] * 1.001).ravel()


AUTO_COVERAGE = 4
MEASURE_DECAY = 0.8  # AUTO indirect: weight of the earlier passes' measurements per pass (FrameRenderer)
PROBE_EVERY = 4  # AUTO indirect while path tracing: one chunk in this many measures (in a frame's first pass)
PROBE_FRAMES = 8  # ... in every this many frames (or views) of the same scene content
PROBE_PIXELS = 32  # a frame without a measurement first probes one pixel in this many (FrameRenderer._probe),
PROBE_BOUNCES = 2  # with paths of at most this many bounces (the split is decided at the first two vertices)
PROBE_MAX = 2048  # ... and at most this many paths (measured: 1800 separate the harness scenes' choices on every seed)
GI_RADIUS_FACTOR = 0.75  # the automatic GI spatial radius against DI's: 6 px at 640x360 (measured on interior_gi:
#                          relMSE 0.23 at 5 px, 0.29 at 8, 0.71 at 16 with 4 passes, 1 spp)
MANY_COVERAGE = 16
MANY_EMITTERS = 4096

@dataclass
class FrameResult:
    """passes: name -> (h, w, c) float32 (bottom row first); samples_done; seconds; cancelled; stats (with
    "stages" when a clock timed the frame); history for the next frame (ReSTIR with temporal reuse)."""

    passes: dict
    samples_done: int
    seconds: float
    cancelled: bool = False
    stats: dict = field(default_factory=dict)
    history: object = None


class _BufferPool:
    """Float64 accumulators kept between frames. A fresh array's pages are faulted in on first write, which
    in this machine's VM cost ~50 ms per 640x360 frame of 1-sample animation renders; reused arrays are only
    zeroed."""

    def __init__(self, keep: int = 12):
        self.free: list[np.ndarray] = []
        self.keep = keep
        self.lock = threading.Lock()

    def zeros(self, shape) -> np.ndarray:
        with self.lock:
            for i, a in enumerate(self.free):
                if a.shape == tuple(shape):
                    a = self.free.pop(i)
                    a.fill(0.0)
                    return a
        return np.zeros(shape, np.float64)

    def put(self, a: np.ndarray) -> None:
        with self.lock:
            self.free.append(a)
            del self.free[:-self.keep]


_BUFFERS = _BufferPool()


class _Stopped(Exception):
    pass


@dataclass
class _Chunk:
    """One span of window pixels through a sample pass: its primary hits and per-surface results."""

    index: int
    pixels: np.ndarray     # window pixel indices (row-major): the chunk's span, ``batch`` times over
    batch: int = 1         # samples of each pixel (sample s + b at pixels[b * span : (b + 1) * span])
    hits: object = None    # pathtracer.PrimaryHits (rows index ``pixels``)
    first: int = 0         # index of its first surface in the frame's G-buffer
    res: object = None     # di.DIReservoirs of its surfaces after initial resampling
    bsdf_ray: object = None
    direct: np.ndarray = None
    indirect: np.ndarray = None
    gi_res: object = None  # gi.GIReservoirs of its surfaces
    path_indirect: np.ndarray = None  # the path tracer's indirect light (used when a pass skips GI reuse)
    gi_share: tuple = (0.0, 0.0, 0.0, 0.0)  # over its pixels: luminance sums of the path-traced indirect light and
    #                                        of the part the reservoirs carry; sums of squares of the path-traced
    #                                        and of the part they do not carry
    glossy: np.ndarray = None  # (surfaces,) bool: GI resamples only the diffuse lobe there (gi.glossy_x1)
    chain: object = None   # pathtracer.SpecularChains: its surfaces seen through smooth glass (ReSTIR)

    @property
    def surfaces(self) -> slice:
        return slice(self.first, self.first + len(self.hits.rows))


class FrameRenderer:
    """One frame's acceleration structures and light table, rendering sample passes into accumulators.

    ``render_frame`` drives it for final renders; the viewport keeps one alive between redraws and
    swaps the camera with :meth:`set_camera` (geometry and lights stay built).
    """

    def __init__(self, scene: Scene, settings: RenderSettings, history=None, clock=None):
        if settings.integrator not in INTEGRATORS:
            raise ValueError(f"unknown integrator {settings.integrator!r}; available: {INTEGRATORS}")
        t0 = time.perf_counter()
        self.settings = settings
        self.clock = clock or NullClock()
        self.candidates = None  # di.CandidateSettings when the direct light is resampled
        self.light_candidate_cap = None  # at most this many light candidates in the next passes (viewport navigation)
        self.method = "PATH"
        self.method_reason = "path tracer"
        self.world_method, self.world_reason = "LIGHT_SAMPLED", "the direct light is not resampled"
        if settings.integrator == "RESTIR" and settings.direct_method not in di.DIRECT_METHODS:
            raise ValueError(f"unknown direct method {settings.direct_method!r}; available: {di.DIRECT_METHODS}")
        if settings.integrator == "RESTIR" and settings.indirect_method not in gi.INDIRECT_METHODS:
            raise ValueError(f"unknown indirect method {settings.indirect_method!r}; available: {gi.INDIRECT_METHODS}")
        bounces = settings.max_bounces
        if settings.integrator == "RESTIR" and settings.indirect_method == "OFF":
            bounces = 0
        self.ctx, self.context_reused = context_for(scene, bounces, settings.film_transparent,
                                                    pathtracer.build_context)
        self.gi = None  # gi.GISettings when the indirect light is resampled
        # the indirect method: AUTO measures on the first bounces of its passes (method_choice.choose_indirect_method)
        # and a pass follows what the passes before it measured: this frame's, or the previous frame's of the same
        # content (kept on the context, used only by frame f + 1, so rendering a frame again gives the same image).
        # Never its own samples, so the choice does not bias the pass.
        self.gi_auto = settings.integrator == "RESTIR" and settings.indirect_method == "AUTO" and bounces > 0 and \
            not settings.gi_reservoir_passes
        self._measure = (None, PROBE_FRAMES)  # AUTO: decayed measurement sums (or None), frames since the last probe
        self.indirect_method = "PATH" if bounces > 0 else "OFF"
        self.indirect_reason = "path tracer" if settings.integrator == "PATH" else "no bounces" if bounces == 0 else \
            "set by the user"
        if settings.integrator == "RESTIR" and bounces > 0 and settings.indirect_method != "PATH":
            self.indirect_method = "RESTIR_GI"
            if self.gi_auto:
                self.indirect_method, self.indirect_reason = "RESTIR_GI", "not measured yet: the first pass measures"
                rec = self.ctx.measured.get("auto_indirect")
                if rec is not None and rec["frame"] == settings.frame - 1:
                    self.indirect_method, self.indirect_reason = rec["choice"]
                    self._measure = (rec["sums"], rec["since"])
            elif settings.indirect_method == "AUTO":
                self.indirect_reason = "a GI reservoir pass is enabled"
        if settings.integrator == "RESTIR":
            tiles = TileSettings(settings.light_tiles, settings.light_tile_count, settings.light_tile_size)
            if tiles.mode not in TILE_MODES:
                raise ValueError(f"unknown light tile mode {tiles.mode!r}; available: {TILE_MODES}")
            if settings.bias_correction not in reuse.BIAS_CORRECTIONS:
                raise ValueError(f"unknown bias correction {settings.bias_correction!r}")
            self.tile_settings = tiles
            self._choose_direct(bounces)
            cam = scene.camera
            radius = float(settings.spatial_radius) if settings.spatial_radius > 0 else \
                reuse.auto_radius(cam.width, cam.height)
            self.spatial = reuse.SpatialSettings(max(0, settings.spatial_neighbors), max(1.0, radius),
                                                 max(0, settings.spatial_passes), settings.bias_correction)
            if settings.indirect_method in ("RESTIR_GI", "AUTO") and bounces > 0:
                gi_radius = float(settings.gi_spatial_radius) if settings.gi_spatial_radius > 0 else \
                    max(reuse.AUTO_RADIUS_MIN, GI_RADIUS_FACTOR * reuse.auto_radius(cam.width, cam.height))
                self.gi = gi.GISettings(max(0, int(settings.gi_spatial_neighbors)), max(1.0, gi_radius),
                                        max(0, int(settings.gi_spatial_passes)), float(settings.gi_confidence_cap),
                                        max(0, int(settings.gi_max_age)), float(settings.gi_roughness_threshold))
                self.gi_spatial = reuse.SpatialSettings(self.gi.neighbors, self.gi.radius, self.gi.passes,
                                                        settings.bias_correction)
                unbiased = settings.bias_correction == "UNBIASED"
                self.gi_space = gi.GISpace(self.ctx.geom_accel if unbiased else None, settings.gi_target)
                lights, lamps = self.ctx.lights, self.ctx.scene.lamps
                # any change of what emits light (a lamp moved, switched, re-coloured) drops the GI history:
                # its cached radiance would be stale
                self.gi_light_key = fingerprint(lights.tri_verts, lights.rows_le, lights.power, lamps.sun_dir,
                                                lamps.sun_irradiance, self.ctx.scene.world_radiance,
                                                getattr(self.ctx.scene, "world_image", None))
        self.space = di.LightSpace(self.ctx.lights)
        self.build_seconds = time.perf_counter() - t0
        self.set_camera(scene.camera)
        if history is not None and history.fits(scene.camera):
            self.adopt_history(history)

    def _choose_direct(self, bounces: int) -> None:
        """The direct method (AUTO: method_choice.choose_direct_method, knowing whether ReSTIR GI takes the
        indirect light) and its candidate settings."""
        st = self.settings
        self.method, self.method_reason = st.direct_method, "set by the user"
        if self.method == "AUTO":
            self.method, self.method_reason = choose_direct_method(self.ctx.lights, st.reservoir_passes, bounces,
                                                                    self.indirect_method == "RESTIR_GI")
        self.candidates = None
        self.world_method, self.world_reason = "LIGHT_SAMPLED", "the direct light is not resampled"
        if self.method in ("RIS", "RESTIR"):
            if st.world_method not in WORLD_METHODS:
                raise ValueError(f"unknown world method {st.world_method!r}; available: {WORLD_METHODS}")
            self.world_method, self.world_reason = choose_world_method(self.ctx.lights, st.world_method)
            if self.world_method == "RESAMPLED" and st.world_candidates <= 0:
                self.world_method, self.world_reason = "LIGHT_SAMPLED", "World Candidates is 0"
            self.candidates = di.CandidateSettings(
                self.method, max(0, st.light_candidates), max(0, st.bsdf_candidates), self.tile_settings,
                world_candidates=max(0, st.world_candidates) if self.world_method == "RESAMPLED" else 0)

    def adopt_history(self, history) -> None:
        """Reuse ``history`` (restir.history.TemporalHistory, from another frame or view of this scene or of an
        edited one) in the next first sample pass: its reservoirs are remapped to this light table (dropped
        when they cannot be) and its GI reservoirs dropped when anything that emits changed. Reprojection
        projects with the history's own camera, so its resolution may differ from this one's."""
        hist = history.remapped(self.ctx.lights)  # None: the lights cannot be mapped
        if hist is not None and hist.gi_res is not None and (self.gi is None or hist.gi_key != self.gi_light_key):
            hist = dataclasses.replace(hist, gi_res=None, gi_terms=None)
        self.prev_history = hist

    def latest_history(self):
        """The newest temporal history: the current view's first pass's, else the one that pass would reuse."""
        return self.history if self.history is not None else self.prev_history

    def move_camera(self, camera, frame: int) -> None:
        """Viewport navigation: render the same scene from ``camera`` (any resolution) as frame ``frame`` (keys
        the random streams, so a new view never repeats the last one's noise) and restart accumulation; the
        newest history is reprojected into the new view's first pass (temporal reuse, as between the frames
        of an animation with a moving camera)."""
        hist = self.latest_history()
        self.settings = dataclasses.replace(self.settings, frame=int(frame))
        self.set_camera(camera)
        if hist is not None and self.settings.temporal_reuse:
            self.prev_history = hist

    def set_camera(self, camera) -> None:
        """Use another camera (same scene) and restart accumulation."""
        self.ctx.scene.camera = camera
        # coverage_mask: the pixels that get the coverage rays (None: all)
        self.coverage, self.coverage_reason, self.coverage_mask = _coverage(
            self.settings.coverage_samples, self.ctx.lights, self.ctx.scene.lamps, camera)
        self.geometry_mask = _geometry_mask(self.ctx, camera)
        self.lamp_mask = _lamp_mask(self.ctx, camera)
        _x0, _y0, w, h = camera.window
        self.release()
        self.acc = {"emit": _BUFFERS.zeros((h, w, 3)), "direct": _BUFFERS.zeros((h, w, 3)),
                    "indirect": _BUFFERS.zeros((h, w, 3)), "alpha": _BUFFERS.zeros((h, w)),
                    "res_m": _BUFFERS.zeros((h, w)), "res_w": _BUFFERS.zeros((h, w))}
        if self.gi is not None:
            self.acc["gi_m"], self.acc["gi_w"] = _BUFFERS.zeros((h, w)), _BUFFERS.zeros((h, w))
        if self.settings.denoise_data:
            self.acc["albedo"], self.acc["dnormal"] = _BUFFERS.zeros((h, w, 3)), _BUFFERS.zeros((h, w, 3))
        self.samples_done = 0
        self._surfaces_per_chunk = None  # surfaces per chunk and sample in the last pass (batch_size)
        self.boiling_dropped = 0  # reservoirs the boiling filter emptied since the camera was set
        self.gi_skipped = 0  # samples whose pass kept path-traced indirect light (GI_MIN_SHARE)
        self.reuse_stats = {}  # the last pass's temporal acceptance and confidence (diagnostics)
        self.used_tiles = False
        self._data = None
        # temporal reuse runs through the first sample pass of each frame: pass 0 reuses the previous
        # frame's pass 0 (prev_history) and becomes the next frame's (history); the other passes of a frame
        # are independent of each other (chaining them correlates the passes being averaged: measured 2x the
        # relMSE of independent passes at 4 and 16 spp on many_lights)
        self.prev_history = None
        self.history = None

    def release(self) -> None:
        """Hand the accumulators back for the next frame's renderer (after :meth:`passes`; this renderer
        cannot accumulate any more)."""
        for a in getattr(self, "acc", {}).values():
            _BUFFERS.put(a)
        self.acc = {}

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

            list(pool().map(gbuffer_tile, _tiles(w, h, self.settings.tile_pixels)))
            self._data = (depth, normal, vector)
        return self._data

    # -- one sample pass ------------------------------------------------------------------------
    def _map(self, fn, items, stop):
        """fn(item) for every item on the pool; raises _Stopped when ``stop`` asks to stop part-way."""
        if len(items) <= 1:
            out = [fn(it) for it in items]
            stop.advance(len(items))
            return out
        futures = {pool().submit(fn, it): i for i, it in enumerate(items)}
        out = [None] * len(items)
        pending = set(futures)
        while pending:
            done, pending = wait(pending, timeout=STOP_POLL_SECONDS, return_when=FIRST_COMPLETED)
            for f in done:
                out[futures[f]] = f.result()
            if stop.should_stop and stop.should_stop():
                for f in pending:
                    f.cancel()
                wait(pending)
                raise _Stopped
            stop.advance(len(done))
        return out

    def sample_pass(self, progress=None, should_stop=None, batch: int = 1) -> bool:
        """Render the next sample pass (one path per pixel; ``batch`` per pixel where the pass can: module docstring)
        into the accumulators. Returns False, keeping the accumulators unchanged, when ``should_stop`` asked to stop
        part-way."""
        try:
            done = self._sample_pass(progress, should_stop, batch)
        except _Stopped:
            return False
        self.samples_done += done
        return True

    def batch_size(self, remaining: int) -> int:
        """Samples the next pass should render at once (at most ``remaining``): the setting, else as many as bring a
        chunk to about ``tile_pixels`` surfaces, judged by the last pass (1 before any pass), at most MAX_BATCH."""
        st = self.settings
        if not self._can_batch():
            return 1
        if st.sample_batch > 0:
            return max(1, min(remaining, int(st.sample_batch)))
        if self._surfaces_per_chunk is None:
            return 1
        return max(1, min(remaining, MAX_BATCH, int(st.tile_pixels // max(self._surfaces_per_chunk, 1.0))))

    def _can_batch(self) -> bool:
        """Whether the next pass may render several samples at once: it keeps no per-pixel state (no reservoirs, no
        ReSTIR GI) and measures nothing for Auto indirect (no probe; the first pass without a measurement probes)."""
        if self.candidates is not None or self._gi_runs():
            return False
        if self.gi is None or self.samples_done > 0:
            return True
        return self._measure[0] is not None and not self._periodic_probe_due()

    def _gi_runs(self) -> bool:
        """ReSTIR GI runs in the next pass (AUTO: while its last measurement says so)."""
        return self.gi is not None and (not self.gi_auto or self.indirect_method == "RESTIR_GI")

    def _periodic_probe_due(self) -> bool:
        """AUTO path-tracing: the first pass of this frame measures in some chunks (every PROBE_FRAMES-th frame)."""
        return self._measure[1] >= PROBE_FRAMES

    def _sample_pass(self, progress, should_stop, batch: int = 1) -> int:
        """One pass of ``batch`` samples (1 where the pass resamples or measures). Returns the samples rendered."""
        st = self.settings
        s = self.samples_done
        if not self._can_batch():
            batch = 1
        clock = self.clock
        x0, y0, w, h = self.ctx.scene.camera.window
        npix = w * h
        if self.gi_auto and s == 0 and self._measure[0] is None:
            with clock.stage("probe"):  # nothing measured yet (a still, a first frame): measure before choosing
                self._probe()
        resampled = self.candidates is not None
        reusing = self.method == "RESTIR"
        # ReSTIR GI runs in this pass (AUTO: while its last measurement says so); AUTO measures in every pass that
        # runs GI, and while it path-traces, in a quarter of the chunks of the first pass of every PROBE_FRAMES-th
        # frame of this content (``probe``: the first bounces' extra work costs about 12 % of such a frame)
        gi_on = self._gi_runs()
        probe = False
        if self.gi_auto and not gi_on and s == 0:
            sums, since = self._measure
            probe = self._periodic_probe_due()
            self._measure = (sums, 1 if probe else since + 1)
            self._remember()
        batch = max(1, int(batch))
        spans = self._spans(npix)
        chunks = [_Chunk(i, np.arange(sl.start, sl.stop) if batch == 1 else
                         np.tile(np.arange(sl.start, sl.stop), batch), batch) for i, sl in enumerate(spans)]
        # chunk tasks of the pass, for progress (reuse maps over about as many surface chunks per pass)
        chunk_stages = 4 + int(resampled) + (int(self.spatial.passes) + 1 if reusing else 0) + \
            (int(self.gi.passes) + 1 if gi_on else 0)
        stop = _Progress(progress, should_stop, len(chunks) * chunk_stages)
        ctx = self.ctx

        strata = self.coverage
        cover = self.coverage_mask
        may_hit, lamp_mask = self.geometry_mask, self.lamp_mask

        def primary(c: _Chunk):
            camera_rays(c)
            if st.integrator == "RESTIR" and ctx.has_glass and (resampled or gi_on):
                # camera rays that met glass continue to the surface behind it, where resampling runs (without
                # resampling, the path continuation handles glass as the path tracer does, at less cost)
                c.chain = pathtracer.follow_specular(ctx, c.hits, rng(st.seed, st.frame, s, STREAM_CHAIN, c.index))

        def camera_rays(c: _Chunk):
            r = rng(st.seed, st.frame, s, STREAM_CAMERA, c.index)
            # the pass's position in the pixel: Sobol point s, shifted per pixel (the shift keyed without the pass)
            span = len(c.pixels) // c.batch
            shift = rng(st.seed, st.frame, 0, STREAM_PIXEL_OFFSET, c.index).bit_generator.random_raw(span)
            shift = shift.view(np.uint32).reshape(-1, 2)
            j = pass_jitter(shift, s) if c.batch == 1 else \
                np.concatenate([pass_jitter(shift, s + b) for b in range(c.batch)])
            px = (x0 + c.pixels % w).astype(np.float32)
            py = (y0 + c.pixels // w).astype(np.float32)
            hit_mask = None if may_hit is None else may_hit[c.pixels]
            lamp_seen = None if lamp_mask is None else lamp_mask[c.pixels]
            if strata == 1:
                c.hits = pathtracer.primary(ctx, px + j[:, 0], py + j[:, 1], hit_mask, lamp_seen)
                return
            # the shaded ray where the pass puts it (uniform over the pixel, so uniform within the stratum it
            # falls in), one more ray in each other stratum, in the pixels near an emitter (coverage_mask)
            g = int(round(np.sqrt(strata)))
            c.hits = pathtracer.primary(ctx, px + j[:, 0], py + j[:, 1], hit_mask, lamp_seen)
            sel = slice(None) if cover is None else np.flatnonzero(cover[c.pixels])
            jx, jy, sx, sy = j[sel, 0], j[sel, 1], px[sel], py[sel]
            if len(jx) == 0:
                return
            k0 = np.minimum((jx * g).astype(np.int64), g - 1) + g * np.minimum((jy * g).astype(np.int64), g - 1)
            k = (k0[None, :] + np.arange(1, strata)[:, None]) % strata  # (strata - 1, n)
            jj = r.random((2,) + k.shape, dtype=np.float32)
            em, al = pathtracer.seen_emission(ctx, (sx + ((k % g).astype(np.float32) + jj[0]) / g).ravel(),
                                              (sy + ((k // g).astype(np.float32) + jj[1]) / g).ravel())
            inv = np.float32(1.0 / strata)
            c.hits.emitted[:, sel] = (c.hits.emitted[:, sel] + em.reshape(3, strata - 1, -1).sum(axis=1)) * inv
            c.hits.alpha[sel] = (c.hits.alpha[sel] + al.reshape(strata - 1, -1).sum(axis=0)) * inv

        with clock.stage("primary"):
            self._map(primary, chunks, stop)
            first = 0
            for c in chunks:
                c.first = first
                first += len(c.hits.rows)
            self._surfaces_per_chunk = first / (len(chunks) * batch)
        candidates = self.candidates
        cap = self.light_candidate_cap
        if resampled and cap is not None and candidates.light_candidates > cap:
            candidates = dataclasses.replace(candidates, light_candidates=cap)
        if resampled:
            self.reuse_stats["light_candidates"] = candidates.light_candidates
        if resampled and ctx.lights.tri_alias is not None and candidates.tile_settings.wanted(npix, candidates.light_candidates):
            with clock.stage("initial"):
                r_tiles = rng(st.seed, st.frame, s, STREAM_TILES)
                if st.light_sampler == "SPATIAL":
                    pos = np.full((3, npix), np.nan, np.float32)
                    for c in chunks:
                        pos[:, c.pixels[c.hits.rows]] = c.hits.surf.p
                    tiles = BlockLightTiles(ctx.lights, pos.reshape(3, h, w), w, h, r_tiles)
                else:
                    tiles = LightTiles(ctx.lights, candidates.tile_settings, w, h, r_tiles)
            candidates = dataclasses.replace(candidates, tiles=tiles)
            self.used_tiles = True
        # the world's points in the reservoirs (else the world is light-sampled where the reservoirs are shaded)
        world_resampled = resampled and candidates.world_resampled(ctx.lights)
        continuing = pathtracer.needs_continuation(ctx, resampled, world_resampled)
        # the frame's target terms, one (27, surfaces) block the chunks write into (reuse gathers from it)
        terms = np.empty((WIDTH, first), np.float32) if resampled else None
        # ReSTIR GI's target terms: the same, with the specular lobe off at glossy primary surfaces
        gi_terms = np.empty((WIDTH, first), np.float32) if gi_on or probe else None

        def initial(c: _Chunk):
            surf = c.hits.surf
            t = ShadingTerms.of_surfaces(surf, terms[:, c.surfaces])
            pix = c.pixels[c.hits.rows]
            c.res, c.bsdf_ray = di.initial_ris(ctx, surf, t, rng(st.seed, st.frame, s, STREAM_INITIAL, c.index),
                                               candidates, pix % w, pix // w, keep_bsdf_ray=continuing)

        if resampled:
            with clock.stage("initial"):
                self._map(initial, chunks, stop)

        def paths(c: _Chunk):
            """Before reuse: the continuation needs no reservoir, and its first ray is freed early. With ReSTIR GI
            the first bounces become the initial GI reservoirs."""
            if not continuing:
                c.direct, c.indirect = None, None
                return
            out = pathtracer.continue_paths(
                ctx, c.hits.surf, rng(st.seed, st.frame, s, STREAM_PATH, c.index), direct_resampled=resampled,
                first_ray=c.bsdf_ray, first_bounce=gi_on or (probe and c.index % PROBE_EVERY == 0),
                budget=None if c.chain is None else ctx.max_bounces - c.chain.depth, world_resampled=world_resampled)
            c.bsdf_ray = None
            c.direct, c.indirect = out[0], out[1]
            if len(out) > 2:  # the first bounces: GI's initial samples (and the AUTO measurement)
                block = gi_terms[:, c.surfaces]
                if resampled:
                    block[:] = terms[:, c.surfaces]
                c.path_indirect = c.indirect
                c.glossy, c.gi_res, c.indirect = self._gi_initial(c.hits.surf, out[2], block, filled=resampled)
                c.gi_share = _share_sums(c.path_indirect, c.indirect)

        with clock.stage("paths"):
            self._map(paths, chunks, stop)
        if gi_on or probe:
            # GI reuse only pays where its reservoirs carry the indirect light: a scene with no bounce light to
            # cache (the default cube: nothing for its rays to hit) keeps the path-traced indirect light as it is
            sums = np.sum([c.gi_share for c in chunks], axis=0)
            share = float(sums[1] / sums[0]) if sums[0] > 0 else 0.0
            uncached = float(sums[3] / sums[2]) if sums[2] > 0 else 1.0
            self.reuse_stats["gi_share"], self.reuse_stats["gi_uncached"] = share, uncached
            if self.gi_auto:
                self._measured_indirect(sums)  # for the next passes
            elif share < GI_MIN_SHARE:
                gi_on = False
            if not gi_on:
                for c in chunks:
                    if c.path_indirect is not None:
                        c.indirect, c.gi_res = c.path_indirect, None
            for c in chunks:
                c.path_indirect = None
        if self.gi is not None and not gi_on:
            self.gi_skipped += batch
        gb = res = gi_res = gb_gi = gi_history = None
        if reusing or gi_on:
            with clock.stage("gbuffer"):
                gb = self._gbuffer(chunks, terms if reusing else gi_terms)
        if reusing:
            with clock.stage("gbuffer"):
                res = di.DIReservoirs.empty(len(gb))
                for c in chunks:
                    res.assign(c.surfaces, c.res)
                    c.res = None  # the frame's array holds them now
            res = self._reuse(gb, res, s, stop)
            for c in chunks:
                c.res = res.take(c.surfaces)
        if gi_on:
            with clock.stage("gbuffer"):
                gb_gi = gb.with_terms(ShadingTerms(gi_terms))
                gi_res = gi.GIReservoirs.empty(len(gb))
                for c in chunks:
                    gi_res.assign(c.surfaces, c.gi_res)
                    c.gi_res = None
            gi_res, gi_history = self._reuse_gi(gb_gi, gi_res, s, stop)
            for c in chunks:
                c.gi_res = gi_res.take(c.surfaces)
        if s == 0 and gb is not None:  # the next frame's history; confidence at most the cap, so no reused M exceeds it
            lights = ctx.lights
            self.history = TemporalHistory(
                gb, None if res is None else res.replace(M=np.minimum(res.M, st.confidence_cap)), ctx.scene.camera,
                lights.signature, st.frame, lights.light_uid, lights.uid_space,
                gi_res=None if gi_history is None else gi.age_history(gi_history.replace(
                    M=np.minimum(gi_history.M, np.float32(self.gi.confidence_cap))), self.gi.max_age),
                gi_terms=None if gb_gi is None else gb_gi.terms, gi_key=self.gi_light_key if gi_on else None)

        def shade(c: _Chunk):
            r = rng(st.seed, st.frame, s, STREAM_SHADE, c.index)
            if resampled:  # the lights from the reservoirs, the world from them too or by its own light sample
                direct = di.shade(ctx, c.hits.surf, c.res, r)
                if ctx.world.sampled and not world_resampled:
                    direct = direct + pathtracer.world_event(ctx, c.hits.surf, r)
            else:
                direct = pathtracer.next_event(ctx, c.hits.surf, r)
            c.direct = direct if c.direct is None else c.direct + direct
            if gi_on:
                # the unbiased mode's reservoirs hold only samples their surface sees (gi.clear_occluded)
                c.indirect = c.indirect + gi.shade(ctx.geom_accel, c.hits.surf, c.gi_res, c.glossy,
                                                   verified=st.bias_correction == "UNBIASED")

        with clock.stage("shade"):
            self._map(shade, chunks, stop)
        with clock.stage("passes"):
            self._accumulate(chunks, resampled, stop)
        return batch

    def _gi_initial(self, surf, first, block: np.ndarray, filled: bool = False):
        """ReSTIR GI's initial reservoirs at surfaces ``surf`` from their first bounces (pathtracer.FirstBounce):
        (glossy x1 (n,) bool, gi.GIReservoirs, the path-traced indirect light they do not carry (3, n)). ``block``
        (WIDTH, n) receives the GI target terms (already holding the surfaces' target terms when ``filled``)."""
        if not filled:
            ShadingTerms.of_surfaces(surf, block)
        glossy = gi.glossy_x1(surf.params, self.gi.roughness_threshold)
        res, rest = gi.initial(first, gi.diffuse_only(ShadingTerms(block), glossy), len(surf), glossy, self.gi_space)
        return glossy, res, rest

    def _probe(self) -> None:
        """AUTO indirect without a measurement: camera paths of up to PROBE_BOUNCES bounces through one pixel in
        PROBE_PIXELS, at most PROBE_MAX of them (their own random stream, so the frame's passes are independent of
        it and the image is unbiased and deterministic), measure what the GI reservoirs would carry, and the
        frame's first pass follows that. (Tried: the probe's paths as those pixels' samples of the pass, which
        biases them by selection, and the probe run beside the pass's camera rays, which took longer.)"""
        st, ctx = self.settings, self.ctx
        x0, y0, w, h = ctx.scene.camera.window
        r = rng(st.seed, st.frame, 0, STREAM_PROBE)
        pix = r.integers(0, w * h, max(1, min((w * h) // PROBE_PIXELS, PROBE_MAX)))
        jit = r.random((2, len(pix)), dtype=np.float32)
        hits = pathtracer.primary(ctx, (x0 + pix % w).astype(np.float32) + jit[0],
                                  (y0 + pix // w).astype(np.float32) + jit[1],
                                  None if self.geometry_mask is None else self.geometry_mask[pix])
        surf = hits.surf
        sums = np.zeros(4)
        if len(surf):
            out = pathtracer.continue_paths(ctx, surf, r, direct_resampled=False, first_bounce=True,
                                            budget=np.full(len(surf), min(PROBE_BOUNCES, ctx.max_bounces)))
            _glossy, _res, rest = self._gi_initial(surf, out[2], np.empty((WIDTH, len(surf)), np.float32))
            sums = _share_sums(out[1], rest)
        self._measure = (None, 1)  # measured now: no periodic probe in this frame's first pass
        self._measured_indirect(sums)

    def _measured_indirect(self, sums: np.ndarray) -> None:
        """AUTO: the indirect method for this pass from the measured sums (_Chunk.gi_share) of the passes so far
        of this content (kept on the shared context, so frames and views carry them; older passes count less:
        MEASURE_DECAY per pass, a memory of about five passes). The AUTO direct method is chosen again when its
        premise (GI or not) changed; it applies from the next pass on."""
        acc, since = self._measure
        acc = sums if acc is None else acc * MEASURE_DECAY + sums
        self._measure = (acc, since)
        share = float(acc[1] / acc[0]) if acc[0] > 0 else 0.0
        uncached = float(acc[3] / acc[2]) if acc[2] > 0 else 1.0
        self.reuse_stats["gi_share_measured"], self.reuse_stats["gi_uncached_measured"] = share, uncached
        before = self.indirect_method
        self.indirect_method, self.indirect_reason = choose_indirect_method(share, uncached)
        self._remember()
        if self.indirect_method != before and self.settings.direct_method == "AUTO":
            self._choose_direct(self.ctx.max_bounces)

    def _remember(self) -> None:
        """Keep the AUTO indirect measurement on the context for the next frame (or view) of the same content."""
        self.ctx.measured["auto_indirect"] = {"frame": self.settings.frame, "choice": (self.indirect_method,
                                              self.indirect_reason), "sums": self._measure[0],
                                              "since": self._measure[1]}

    def _gbuffer(self, chunks, terms) -> GBuffer:
        """The frame's G-buffer from the chunks' primary hits (surfaces in chunk order)."""
        cam = self.ctx.scene.camera
        _x0, _y0, w, h = cam.window
        surfs = [c.hits.surf for c in chunks]
        rel = terms[0:3] - camera_mod.position(cam)[:, None]
        fwd = camera_mod.forward(cam)
        depth = fwd[0] * rel[0] + fwd[1] * rel[1] + fwd[2] * rel[2]  # planar depth along the camera axis
        inst = self.ctx.scene.geometry.instance
        prim = np.concatenate([sf.prim for sf in surfs])
        return GBuffer(np.concatenate([c.pixels[c.hits.rows] for c in chunks]), w, h, depth.astype(np.float32),
                       inst[prim] if inst is not None else np.zeros(len(prim), np.int32),
                       np.concatenate([sf.mat for sf in surfs]), ShadingTerms(terms))

    def _spans(self, n: int):
        """Chunks of n pixels or surfaces as slices (reuse reads a chunk's own data as views)."""
        step = _chunk_size(n, self.settings.tile_pixels)
        return [slice(a, min(n, a + step)) for a in range(0, n, step)]

    def _reuse(self, gb: GBuffer, res, s: int, stop):
        """Temporal (first pass of a frame, with a history), boiling filter, spatial passes; makes the next
        frame's history. Returns the frame's final reservoirs (raises _Stopped when asked to stop)."""
        st = self.settings
        clock = self.clock
        space = self.space
        ctx = self.ctx
        if st.temporal_reuse and s == 0 and self.prev_history is not None and self.prev_history.res is not None:
            hist = self.prev_history
            # object motion is known for the previous frame only; a history from another frame gets none
            motion = ctx.scene.motion if hist.frame == st.frame - 1 else None
            had = hist.had_light
            possible = None if had is None else (lambda rows, res=res: had[np.maximum(res.light[rows], 0)])
            res = self._temporal(space, gb, res, hist, motion, st.confidence_cap, STREAM_TEMPORAL, possible, s, stop,
                                 "temporal")
            # every fresh reservoir has M = 1 and a merged history adds at least 1: M > 1.5 = history accepted
            self.reuse_stats["temporal_accepted"] = float((res.M > 1.5).mean()) if len(res.M) else 0.0
            self.reuse_stats["temporal_mean_M"] = float(res.M.mean()) if len(res.M) else 0.0
        if st.boiling_filter and st.bias_correction == "NONE":  # biased by design: never in the unbiased mode
            with clock.stage("boiling"):
                self.boiling_dropped += int(boiling_filter(res, gb.pix, gb.width, gb.height,
                                                           st.boiling_threshold).sum())
        for k in range(self.spatial.passes if self.spatial.neighbors else 0):
            res = self._spatial(space, gb, res, self.spatial, STREAM_SPATIAL + k, s, stop, "spatial")
        if len(res.M):
            self.reuse_stats["final_M_p10_p50_p90"] = [float(v) for v in np.percentile(res.M, [10, 50, 90])]
        return res

    def _reuse_gi(self, gb: GBuffer, res, s: int, stop):
        """ReSTIR GI: temporal (first pass of a frame, with a GI history) and spatial passes, as :meth:`_reuse`.
        Returns (the final reservoirs, the reservoirs before the spatial passes: the next frame's history)."""
        st = self.settings
        hist = self.prev_history
        if st.temporal_reuse and s == 0 and hist is not None and hist.gi_res is not None:
            motion = self.ctx.scene.motion if hist.frame == st.frame - 1 else None
            view = dataclasses.replace(hist, gbuf=hist.gbuf.with_terms(hist.gi_terms), res=hist.gi_res)
            res = self._temporal(self.gi_space, gb, res, view, motion, self.gi.confidence_cap, STREAM_GI_TEMPORAL,
                                 None, s, stop, "gi_temporal")
            self.reuse_stats["gi_temporal_accepted"] = float((res.M > 1.5).mean()) if len(res.M) else 0.0
            res = self._gi_visible(gb, res, stop, "gi_temporal")
        # the next frame's history is taken before the spatial passes: on the regression room (4 frames, 4 passes)
        # the per-pixel variance is 0.34x the path tracer's this way against 0.57x when the spatially merged
        # reservoirs are fed back (their neighbours' samples are correlated with the next frame's spatial pass)
        history = res
        for k in range(self.gi.passes if self.gi.neighbors else 0):
            res = self._spatial(self.gi_space, gb, res, self.gi_spatial, STREAM_GI_SPATIAL + k, s, stop, "gi_spatial")
            res = self._gi_visible(gb, res, stop, "gi_spatial")
        if len(res.M):
            self.reuse_stats["gi_final_M_p10_p50_p90"] = [float(v) for v in np.percentile(res.M, [10, 50, 90])]
        return res, history

    def _gi_visible(self, gb, res, stop, stage):
        """Unbiased mode: empty the GI samples their surfaces cannot see (gi.clear_occluded), one ray per pixel.
        (The biased mode gains nothing from it: measured on the regression room, bias -8 % either way.)"""
        if self.settings.bias_correction != "UNBIASED":
            return res
        with self.clock.stage(stage):
            # slices: each task's reservoirs and terms are views, cleared in place
            self._map(lambda rows: gi.clear_occluded(self.ctx.geom_accel, gb.terms.take(rows), res.take(rows)),
                      self._spans(len(gb)), stop)
        return res

    def _temporal(self, space, gb, res, hist, motion, cap, stream, possible, s, stop, stage):
        """One temporal merge of every surface's reservoir with its previous frame's (reuse.temporal_reuse)."""
        st = self.settings
        with self.clock.stage(stage):
            prepared = space.prepare(hist.res)
            now = space.prepare(res) if st.bias_correction == "UNBIASED" else None
            jobs = [(rows, (space, gb, res, now, hist, prepared, rows, cap, st.bias_correction, motion,
                            rng(st.seed, st.frame, s, stream, i), possible))
                    for i, rows in enumerate(self._spans(len(gb)))]
            del prepared, now  # released with the jobs once merged
            parts = self._map(_run_job(reuse.temporal_reuse), jobs, stop)
            del jobs
            return space.kind.gather(parts, len(gb))

    def _spatial(self, space, gb, res, cfg, stream, s, stop, stage):
        """One spatial pass over every surface (reuse.spatial_reuse)."""
        st = self.settings
        with self.clock.stage(stage):
            prepared = space.prepare(res)
            jobs = [(rows, (space, gb, res, prepared, rows, cfg, rng(st.seed, st.frame, s, stream, i)))
                    for i, rows in enumerate(self._spans(len(gb)))]
            del prepared  # released with the jobs once merged
            parts = self._map(_run_job(reuse.spatial_reuse), jobs, stop)
            del jobs
            return space.kind.gather(parts, len(gb))

    def _accumulate(self, chunks, resampled: bool, stop) -> None:
        """Add the chunks' results to the running sums (chunks hold disjoint pixels: one pool task each)."""
        flat = {k: a.reshape(len(a) * a.shape[1], -1) if a.ndim == 3 else a.reshape(-1) for k, a in self.acc.items()}

        def add(c: _Chunk):
            if c.batch > 1:
                return add_batch(c)
            # the (3, k) results are transposed into contiguous (k, 3) copies first: adding a transposed view
            # to (k, 3) rows runs NumPy's inner loop over 3 elements (measured 60 ms per 640x360 frame)
            span = slice(int(c.pixels[0]), int(c.pixels[-1]) + 1)  # a chunk is a contiguous pixel range
            flat["emit"][span] += np.ascontiguousarray(c.hits.emitted.T)
            flat["alpha"][span] += c.hits.alpha
            hit = c.hits.rows
            pix = span if len(hit) == len(c.pixels) else c.pixels[hit]  # every pixel hit: a slice, no scatter
            chain = None if c.chain is None else c.chain.throughput  # what the glass in front passes
            for key, value in (("direct", c.direct), ("indirect", c.indirect)):
                if value is not None:
                    flat[key][pix] += np.ascontiguousarray((value if chain is None else value * chain).T)
            if resampled:
                flat["res_m"][pix] += c.res.M
                flat["res_w"][pix] += c.res.W
            if c.gi_res is not None:
                flat["gi_m"][pix] += c.gi_res.M
                flat["gi_w"][pix] += c.gi_res.W
            if "albedo" in flat and len(hit):
                surf = c.hits.surf
                albedo = denoising_albedo(surf)
                flat["albedo"][pix] += np.ascontiguousarray((albedo if chain is None else albedo * chain).T)
                flat["dnormal"][pix] += np.ascontiguousarray((world_to_cam @ surf.ns).T)

        def add_batch(c: _Chunk):
            """A chunk of ``batch`` samples per pixel (no reservoirs or glass chains: those passes do not batch):
            each result summed over the samples of its pixel."""
            n = len(c.pixels) // c.batch
            span = slice(int(c.pixels[0]), int(c.pixels[0]) + n)
            flat["emit"][span] += c.hits.emitted.reshape(3, c.batch, n).sum(axis=1).T
            flat["alpha"][span] += c.hits.alpha.reshape(c.batch, n).sum(axis=0)
            def add_rows(key, value):  # (3, hits) values of the hit rows, summed into their pixels
                dense = np.zeros((len(c.pixels), 3), np.float32)
                dense[c.hits.rows] = value.T
                flat[key][span] += dense.reshape(c.batch, n, 3).sum(axis=0)

            for key, value in (("direct", c.direct), ("indirect", c.indirect)):
                if value is not None:
                    add_rows(key, value)
            if "albedo" in flat and len(c.hits.rows):
                add_rows("albedo", denoising_albedo(c.hits.surf))
                add_rows("dnormal", world_to_cam @ c.hits.surf.ns)

        world_to_cam = np.ascontiguousarray(self.ctx.scene.camera.cam_to_world[:3, :3].T, dtype=np.float32)
        self._map(add, chunks, stop)

    def combined(self) -> np.ndarray:
        """The running mean of Combined (h, w, 4) float32."""
        inv = 1.0 / max(1, self.samples_done)
        h, w = self.acc["alpha"].shape
        out = np.empty((h, w, 4), np.float32)
        np.add(self.acc["emit"], self.acc["direct"], out=out[..., :3], casting="unsafe")
        out[..., :3] += self.acc["indirect"]
        out[..., :3] *= np.float32(inv)
        np.multiply(self.acc["alpha"], inv, out=out[..., 3], casting="unsafe")
        return finite(out)

    def mean(self, key: str) -> np.ndarray:
        """The running mean of accumulator ``key`` as (h, w, c) float32 (c = 1 for scalar ones), finite."""
        a = self.acc[key]
        out = np.multiply(a, np.float32(1.0 / max(1, self.samples_done)), out=np.empty(a.shape, np.float32),
                          casting="unsafe")
        return finite(out if out.ndim == 3 else out[..., None])

    def passes(self) -> dict:
        """All passes (see :class:`FrameResult`); float32, finite everywhere."""
        mean = self.mean
        jobs = {"Combined": self.combined, "Direct": lambda: mean("direct"), "Indirect": lambda: mean("indirect"),
                "Emission": lambda: mean("emit")}
        if self.candidates is not None:
            jobs["Reservoir M"] = lambda: mean("res_m")
            jobs["Reservoir UCW"] = lambda: mean("res_w")
        if self.gi is not None:
            jobs["GI Reservoir M"] = lambda: mean("gi_m")
            jobs["GI Reservoir UCW"] = lambda: mean("gi_w")
        if "albedo" in self.acc:
            jobs["Denoising Albedo"] = lambda: mean("albedo")
            jobs["Denoising Normal"] = lambda: mean("dnormal")
        run = map if in_worker() else pool().map  # one pass per pool task (inline inside a worker)
        out = dict(zip(jobs, run(lambda job: job(), jobs.values())))
        if self.settings.data_passes:
            out["Depth"], out["Normal"], out["Vector"] = (finite(a) for a in self.data_passes())
        return out


def _share_sums(indirect: np.ndarray, rest: np.ndarray) -> np.ndarray:
    """(4,) over surfaces: luminance sums of the path-traced indirect light (3, n) and of the part the GI reservoirs
    carry (indirect - rest); sums of squares of the indirect light and of ``rest``, the part they do not carry."""
    lum_all, lum_rest = luminance_rows(indirect), luminance_rows(rest)
    total = float(lum_all.sum())
    return np.array([total, total - float(lum_rest.sum()), float(np.dot(lum_all, lum_all)),
                     float(np.dot(lum_rest, lum_rest))])


def _chunk_size(n: int, target: int) -> int:
    """Items per chunk near ``target`` such that the chunk count is a multiple of the pool's threads (7 chunks
    on 2 threads leave one core idle for the last one)."""
    target = max(64, int(target))
    threads = thread_count()
    count = max(1, -(-n // target))
    count = -(-count // threads) * threads
    return max(64, -(-n // count))


def _run_job(fn):
    """A pool task running ``fn(*args)`` for a (rows, args) job and returning (rows, result)."""
    return lambda job: (job[0], fn(*job[1]))


class _Progress:
    """Progress over the chunk tasks of a sample pass, and the stop request."""

    def __init__(self, progress, should_stop, total: int):
        self.progress, self.should_stop, self.total, self.done = progress, should_stop, max(1, total), 0

    def advance(self, k: int) -> None:
        self.done += k
        if self.progress:
            self.progress(min(1.0, self.done / self.total))


def render_frame(scene: Scene, settings: RenderSettings, progress=None, should_stop=None, history=None,
                 clock=None) -> FrameResult:
    """Render one frame with the chosen integrator.

    progress(fraction, message) is called as chunks finish; should_stop() is polled while they run,
    and a stop keeps the sample passes already completed (raises :class:`Cancelled` if none).
    """
    t0 = time.perf_counter()
    fr = FrameRenderer(scene, settings, history, clock)
    cancelled = False
    while fr.samples_done < settings.samples:
        s = fr.samples_done
        batch = fr.batch_size(settings.samples - s)
        report = None
        if progress:
            def report(f, s=s, b=batch):
                label = f"Sample {s + 1}/{settings.samples}" if b == 1 else \
                    f"Samples {s + 1}-{s + b}/{settings.samples}"
                progress((s + f * b) / settings.samples, label)
        if not fr.sample_pass(report, should_stop, batch):
            cancelled = True
            break
    if fr.samples_done == 0:
        raise Cancelled("render cancelled before the first sample pass finished")
    with fr.clock.stage("passes"):
        passes = fr.passes()
    fr.release()
    ctx = fr.ctx
    stats = {"build_seconds": fr.build_seconds, "light_tiles": fr.used_tiles, "triangles": len(scene.geometry),
             "light_triangles": ctx.lights.n_tri, "suns": ctx.lights.n_sun, "boiling_dropped": fr.boiling_dropped,
             "context_reused": fr.context_reused, "coverage_samples": fr.coverage,
             "direct_method": fr.method, "direct_reason": fr.method_reason,
             "world_method": fr.world_method, "world_reason": fr.world_reason,
             "spatial_radius": fr.spatial.radius if fr.method == "RESTIR" else None, "reuse": dict(fr.reuse_stats),
             "coverage_reason": fr.coverage_reason,
             # AUTO: the latest choice; otherwise ReSTIR GI unless every pass kept the path-traced light
             "indirect_method": ("OFF" if ctx.max_bounces == 0 else "PATH" if fr.gi is None else fr.indirect_method
                                 if fr.gi_auto else "PATH" if fr.gi_skipped == fr.samples_done else "RESTIR_GI"),
             "indirect_reason": fr.indirect_reason,
             "gi_skipped_passes": fr.gi_skipped,
             "gi_spatial_radius": fr.gi.radius if fr.gi is not None else None}
    if clock is not None:
        stats["stages"] = clock.stages
    return FrameResult(passes, fr.samples_done, time.perf_counter() - t0, cancelled, stats, fr.history)


def _tiles(w: int, h: int, tile_pixels: int = CHUNK_PIXELS):
    """Square-ish tiles (x, y, tw, th) covering a w x h window (data passes)."""
    side = max(8, int(np.sqrt(max(tile_pixels, 64))))
    return [(x, y, min(side, w - x), min(side, h - y)) for y in range(0, h, side) for x in range(0, w, side)]
