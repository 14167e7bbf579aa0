"""Rendered viewport shading: a worker thread renders sample passes of the 3D view; the UI thread only draws.

The session is driven from Blender's thread by three calls that never wait for the worker:
``set_scene`` (a new or edited scene, from ``view_update``), ``set_view`` (the view's camera, from
``view_draw``) and ``set_pass`` (the pass to show). The worker:

- renders the pass after a view change (a navigation pass) at a reduced resolution, 1/divider of the view's,
  the divider chosen from the measured cost per pixel so that the pass fits the time budget; a navigation pass
  is not interrupted by further view changes (else fast navigation would never show an image), it picks up
  the newest view when it ends;
- when no new view arrived during that pass, doubles the resolution pass by pass up to full resolution and
  accumulates samples there (refinement passes, interrupted at once by a view change, a scene edit or a stop);
- carries temporal history across views: each view's first pass reprojects the reservoirs (ReSTIR DI and GI) of
  the last view that finished one, through the previous view's camera (any resolution), with the disocclusion
  tests of the final render; a new view is a new "frame" for the random streams;
- renders on worker processes of its own (core.parallel.processes.borrow) where F12 would for the view's size
  (the Processes and Threads settings, at most one per chunk of the full-resolution view, as many as fit in
  memory), else in Blender's process with every thread: the same views give the same images either way.

Images handed to the UI are (h, w, 4) float32 in scene-linear (Combined and the light passes) or display
values (the false-colour and data passes, see :func:`pass_image`).
"""
from __future__ import annotations

import dataclasses
import threading
import time
from dataclasses import dataclass, field

import numpy as np

from .core.parallel import processes as procs
from .core.parallel.pool import thread_count
from .core.pipeline.frame_render import team_size
from .core.pipeline.shared_view import SharedViewRenderer
from .core.renderer import FrameRenderer, RenderSettings
from .core.scene import Camera, Motion
from .viewport_passes import (DATA_PASSES, GI_RESERVOIR_PASSES, RESERVOIR_PASSES,  # noqa: F401 (the engine's)
                              VIEWPORT_PASSES, pass_image)

MAX_VIEWPORT_SAMPLES = 1024
HALF_FLOAT_MAX = 65504.0  # RGBA16F textures turn larger values into inf (black viewport)
DIVIDERS = (1, 2, 4, 8)   # resolution dividers of a navigation pass
DEFAULT_BUDGET = 0.15     # seconds a navigation pass may take (the first image after a move)
# light candidates of a navigation pass at most: the history reprojected from the last view lets fewer suffice
# (many_lights 1k 10-view pan, 6 seeds: 8 candidates with reuse 0.337 relMSE in 52 ms, 32 after a restart 0.353 in
# 71 ms; docs/RESULTS.md "Viewport"); the passes that refine a still view use the setting
NAVIGATION_CANDIDATES = 8
COST_SMOOTHING = 0.5      # weight of the newest pass in the running cost-per-pixel estimate

def view_camera(region_data, width: int, height: int, clip_start: float, clip_end: float, pixel_filter=None,
                lens=None) -> Camera:
    """Core camera of a 3D view: view_matrix is world->view, window_matrix the projection; the film's
    ``pixel_filter`` and, looking through the scene camera, its ``lens`` (depth of field)."""
    view = np.array(region_data.view_matrix, np.float64)
    proj = np.array(region_data.window_matrix, np.float64)
    return Camera(cam_to_world=np.linalg.inv(view), ndc_to_cam=np.linalg.inv(proj), width=width, height=height,
                  window=(0, 0, width, height), ortho=not region_data.is_perspective,
                  clip_start=clip_start, clip_end=clip_end, pixel_filter=pixel_filter, lens=lens)


def scaled_camera(camera: Camera, divider: int) -> Camera:
    """The same view at 1/divider of its resolution (the projection is in NDC, so only the raster changes)."""
    w, h = max(1, camera.width // divider), max(1, camera.height // divider)
    return dataclasses.replace(camera, width=w, height=h, window=(0, 0, w, h))


def choose_divider(seconds_per_pixel: float | None, pixels: int, budget: float) -> int:
    """The smallest divider whose pass is predicted to fit ``budget`` seconds (cost ∝ pixels); the largest when
    none does. Without a measurement yet: the largest (the first image comes fast, then the estimate exists).
    A budget of 0: always full resolution."""
    if budget <= 0:
        return 1
    if seconds_per_pixel is None:
        return DIVIDERS[-1]
    for d in DIVIDERS:
        if seconds_per_pixel * pixels / (d * d) <= budget:
            return d
    return DIVIDERS[-1]


@dataclass
class ViewportStats:
    """What the header shows: samples of the current view, the last pass's seconds, the divider, mean M."""

    samples: int = 0
    pass_seconds: float = 0.0
    divider: int = 1
    width: int = 0
    height: int = 0
    mean_m: float | None = None     # mean ReSTIR DI confidence over the pixels with a surface (None: no DI reservoirs)
    gi_mean_m: float | None = None  # the same for ReSTIR GI
    navigation_passes: int = 0    # passes rendered right after a view change
    processes: int = 1            # processes rendering the passes (1: Blender's own)
    extra: dict = field(default_factory=dict)  # the shown pass's mapping facts (pass_image): range, missing

    def text(self) -> str:
        s = f"Viewport | {self.samples} samples | {self.width}x{self.height}"
        if self.divider > 1:
            s += f" (1/{self.divider})"
        s += f" | {1000 * self.pass_seconds:.0f} ms/pass"
        if self.processes > 1:
            s += f" | {self.processes} processes"
        if self.mean_m is not None:
            s += f" | mean M {self.mean_m:.1f}"
        if self.gi_mean_m is not None:
            s += f" | GI mean M {self.gi_mean_m:.1f}"
        if "range" in self.extra:
            lo, hi = self.extra["range"]
            s += f" | range {lo:.3g} to {hi:.3g}"
        if "missing" in self.extra:
            s += f" | {self.extra['missing']}"
        if "note" in self.extra:
            s += f" | {self.extra['note']}"
        return s


class ViewportSession:
    """One viewport engine instance's worker: owns the renderer (a FrameRenderer, or a SharedViewRenderer on worker
    processes) and renders what the UI asked for last. ``processes``: worker processes to render on (None: as F12
    would choose, core.pipeline.frame_render.team_size; 1: Blender's process)."""

    def __init__(self, redraw, budget: float = DEFAULT_BUDGET, max_samples: int = MAX_VIEWPORT_SAMPLES,
                 clock=time.perf_counter, processes: int | None = None):
        self.redraw = redraw
        self.budget = float(budget)
        self.max_samples = int(max_samples)
        self.time_limit = 0.0  # seconds a still view refines (0 = until max_samples)
        self._refine_t0 = None  # when the current still view's refinement began (clock)
        self.clock = clock
        self.renderer: FrameRenderer | SharedViewRenderer | None = None
        self.processes = processes
        self._team = None            # the worker processes borrowed for this session (None: this process renders)
        self.note = ""               # why fewer processes render than asked for (shown in the header)
        self.stats = ViewportStats()
        self.pass_name = "COMBINED"
        self._cv = threading.Condition()
        self._scene = None           # (Scene, RenderSettings) waiting for the worker
        self._view = None            # (Camera at full resolution, key), the newest asked for
        self._key = None             # the key of the view being rendered
        self._divider = 1
        self._frame = 0              # views rendered so far: keys the random streams of each view
        self._cost = None            # running estimate of seconds per pixel of a one-sample pass
        self._interrupt = False      # the running refinement pass must stop
        self._navigating = False     # the running pass is a navigation pass (view changes do not stop it)
        self._closed = False
        self._republish = False
        self._image = None
        self._image_pass = None
        self._thread: threading.Thread | None = None
        self.last_error: str | None = None
        # (core.pipeline.denoiser.Denoiser, DenoiseSettings) denoising the Combined image shown, or None
        self.denoise = None
        self._denoised = None        # ((view key, divider), samples, image): the last denoised Combined

    # -- called from Blender's thread (never waits for a pass) -----------------------------------
    def set_scene(self, scene, settings: RenderSettings) -> None:
        """Render ``scene`` from now on (the view is kept; history is carried over where the lights map)."""
        with self._cv:
            self._scene = (scene, settings)
            self.last_error = None  # a new scene starts the worker again
            self._interrupt = True
            self._closed = False
            self._cv.notify_all()
        self._ensure_thread()

    def set_view(self, camera: Camera, key) -> None:
        """The view's camera at full resolution; a changed ``key`` (matrices, size) starts a new view."""
        with self._cv:
            if self._view is not None and self._view[1] == key:
                return
            self._view = (camera, key)
            if not self._navigating:  # a refinement pass (any resolution) stops for the new view
                self._interrupt = True
            self._cv.notify_all()
        self._ensure_thread()

    def set_pass(self, name: str) -> None:
        """Show another pass (recomputed from the running sums; nothing is re-rendered)."""
        if name not in {p[0] for p in VIEWPORT_PASSES}:
            raise ValueError(f"unknown viewport pass {name!r}")
        with self._cv:
            if name != self.pass_name:
                self.pass_name = name
                self._republish = True
                self._cv.notify_all()

    @property
    def image_pass(self) -> str | None:
        """The pass the newest image shows."""
        return self._image_pass

    def latest(self):
        """(image or None, samples of the current view)."""
        with self._cv:
            return self._image, self.stats.samples

    def halt(self, timeout: float = 5.0) -> None:
        """Stop the worker (leaving Rendered mode, freeing the engine); returns when it has ended."""
        with self._cv:
            self._closed = True
            self._interrupt = True
            self._cv.notify_all()
        t = self._thread
        if t is not None and t is not threading.current_thread():
            t.join(timeout)
        if t is None or not t.is_alive():  # else the worker gives its processes back as it ends
            self._return_team()
        self._thread = None

    @property
    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def _ensure_thread(self) -> None:
        if self._thread is None or not self._thread.is_alive():
            # not named "restir...": those are the pool's threads, which run nested work inline
            self._thread = threading.Thread(target=self._run, name="viewport-worker", daemon=True)
            self._thread.start()

    # -- the worker -------------------------------------------------------------------------------
    def _has_work(self) -> bool:
        if self._scene is not None or self._republish:
            return True
        if self.renderer is None or self._view is None:
            return False
        if self._view[1] != self._key or self._divider > 1:
            return True
        if self.renderer.samples_done == 0:
            self._refine_t0 = None
        elif self._out_of_time():
            return False
        return self.renderer.samples_done < self.max_samples and not self.renderer.converged

    def _run(self) -> None:
        try:
            self._loop()
        except Exception as exc:  # noqa: BLE001 - reported in the header instead of killing Blender's draw
            import traceback
            traceback.print_exc()
            self.last_error = f"{type(exc).__name__}: {exc}"
            if isinstance(self.renderer, SharedViewRenderer):  # its workers are gone (or went on failing)
                self.renderer = None
            self.redraw()
        finally:
            if self._closed:
                self._return_team()

    def _return_team(self) -> None:
        """Give the borrowed worker processes back (kept idle for the next session)."""
        team, self._team = self._team, None
        if isinstance(self.renderer, SharedViewRenderer):
            self.renderer.release()
            self.renderer = None
        if team is not None:
            procs.give_back(team)

    def _loop(self) -> None:
        while True:
            with self._cv:
                while not self._closed and not self._has_work():
                    self._cv.wait()
                if self._closed:
                    return
                job, self._scene = self._scene, None
                view = self._view
                republish, self._republish = self._republish, False
                self._interrupt = False
            if job is not None:
                self._adopt_scene(*job)
            if self.renderer is None or view is None:
                continue
            camera, key = view
            navigation = key != self._key
            if navigation:
                self._divider = choose_divider(self._cost, camera.width * camera.height, self.budget)
                self._move(camera, key)
            elif self._divider > 1:  # the view stayed: refine, doubling the resolution up to full (each step
                self._divider //= 2   # reprojects the last one's reservoirs, as a camera move does)
                self._move(camera, key)
            elif republish and self.renderer.samples_done > 0:
                self._publish()
                continue
            if self.renderer.samples_done >= self.max_samples or self.renderer.converged:
                continue
            self._pass(navigation)

    def _adopt_scene(self, scene, settings: RenderSettings) -> None:
        old = self.renderer
        full = scene.camera if self._view is None else self._view[0]
        scene.camera = full
        scene.light_groups = None  # the viewport shows Combined alone: no estimate split by light group
        team = self._team_for(scene, settings)
        scene.camera = full if self._view is None else scaled_camera(full, self._divider)
        settings = dataclasses.replace(settings, frame=self._frame)
        if team is not None:
            # the workers' last renderer hands its history over where this session's renderer was theirs
            carry = isinstance(old, SharedViewRenderer) and old.team is team
            _x0, _y0, w, h = full.window
            self.renderer = SharedViewRenderer(team, scene, settings, w * h, carry=carry)
        else:
            hist = old.latest_history() if isinstance(old, FrameRenderer) else None
            self.renderer = FrameRenderer(scene, settings)
            if hist is not None and settings.temporal_reuse:
                self.renderer.adopt_history(hist)
        if old is not None:
            old.release()
        self._key = None  # the next pass is a navigation pass: an edit's first image comes as fast as a move's

    def _team_for(self, scene, settings: RenderSettings):
        """The worker processes to render ``scene`` (its camera: the full-resolution view) on, or None for this
        process: the session's team where its shape still fits, else a newly borrowed one."""
        n, self.note = team_size(scene, settings, self.processes)
        threads = max(1, thread_count() // n)
        team = self._team
        if team is not None and (n <= 1 or team.size != n or team.threads != threads or team.closed):
            self._return_team()
            team = None
        if n > 1 and team is None:
            try:
                team = self._team = procs.borrow(n, threads)
            except procs.WorkerStartFailed as exc:
                self.note = f"render worker processes could not start ({exc}): rendering in Blender's process"
        return team

    def _move(self, camera: Camera, key) -> None:
        """Point the renderer at the view (at the current divider); the scene's motion holds the previous view
        (for the Motion pass: objects do not move between views)."""
        r = self.renderer
        prev = r.camera
        cam = scaled_camera(camera, self._divider)
        self._frame += 1
        r.move_camera(cam, self._frame)
        mats = r.instance_matrices
        if mats is None:
            mats = np.zeros((0, 4, 4))
        r.set_motion(Motion(current=mats, prev=mats, next=mats,
                                    camera_prev=dataclasses.replace(prev, width=cam.width, height=cam.height,
                                                                    window=cam.window)))
        self._key = key

    def _pass(self, navigation: bool) -> None:
        r = self.renderer
        t0 = self.clock()

        def should_stop():
            return self._closed or (self._interrupt and not navigation) or self._scene is not None

        with self._cv:
            self._navigating = navigation
            if not navigation and self._view is not None and self._view[1] != self._key:
                return  # the view moved while this pass was being set up: render the new view first
        # a navigation pass that reuses the last view's reservoirs needs fewer candidates (the first pass of a scene
        # has no history and renders as F12 does)
        cap = NAVIGATION_CANDIDATES if navigation and r.reuses_history() else None
        # full-resolution refinement renders several samples per pass where F12 would (renderer.batch_size); a
        # navigation pass, and the reduced-resolution steps after it, one: they are meant to show an image soon
        batch = 1 if navigation or self._divider > 1 else r.batch_size(self.max_samples - r.samples_done)
        before = r.samples_done
        try:
            done = r.sample_pass(should_stop=should_stop, batch=batch, light_candidate_cap=cap)
        finally:
            self._navigating = False
        seconds = self.clock() - t0
        if not done:
            return
        if navigation or self._divider > 1:
            self._refine_t0 = None  # the view moved: its refinement starts again
        elif self._refine_t0 is None:
            self._refine_t0 = t0
        _x0, _y0, w, h = r.camera.window
        if r.samples_done - before == 1:
            # the estimate sizes navigation passes, which render one sample: a batched refinement pass costs less per
            # sample (fuller chunks) and would make the next navigation pass overrun its budget
            per_pixel = seconds / max(1, w * h)
            self._cost = per_pixel if self._cost is None else \
                COST_SMOOTHING * per_pixel + (1 - COST_SMOOTHING) * self._cost
        self._publish(seconds, int(navigation))

    def _publish(self, seconds: float | None = None, navigation: int = 0) -> None:
        """Hand the pass shown to the UI, with the stats (one replacement: a reader never sees half of them)."""
        r = self.renderer
        image, info = pass_image(r, self.pass_name)
        if self.pass_name == "COMBINED":
            if self.denoise is not None:
                image = self._denoised_combined(r, image)
            image = np.minimum(image, HALF_FLOAT_MAX)
        _x0, _y0, w, h = r.camera.window
        info = dict(info, note=self.note) if self.note else info
        with self._cv:
            self._image = image
            self._image_pass = self.pass_name
            self.stats = dataclasses.replace(self.stats, samples=r.samples_done, divider=self._divider,
                                             width=w, height=h, extra=info,
                                             navigation_passes=self.stats.navigation_passes + navigation,
                                             pass_seconds=self.stats.pass_seconds if seconds is None else seconds,
                                             processes=1 if self._team is None else self._team.size,
                                             mean_m=_mean_confidence(r, "res_m") if r.resamples_direct else None,
                                             gi_mean_m=_mean_confidence(r, "gi_m"))
        self.redraw()

    def _out_of_time(self) -> bool:
        """Whether the still view's refinement has used the Time Limit."""
        return self.time_limit > 0 and self._refine_t0 is not None and \
            self.clock() - self._refine_t0 >= self.time_limit

    def _finished(self, samples: int) -> bool:
        """Whether the current view refines no further (its samples, adaptive convergence or its time limit)."""
        return samples >= self.max_samples or self.renderer.converged or self._out_of_time()

    def _denoised_combined(self, r: FrameRenderer, image: np.ndarray) -> np.ndarray:
        """The Combined image denoised: afresh for a new view or resolution, when the samples have doubled since the
        last denoised image and when the view stops refining; in between, the last denoised image of this view (so a
        denoiser slower than a sample pass does not hold refinement back)."""
        tag, n = (self._key, self._divider), r.samples_done
        last = self._denoised
        if last is not None and last[0] == tag and (n < 2 * last[1] and not (self._finished(n) and n > last[1])
                                                    or n == last[1]):
            return last[2]
        denoiser, settings = self.denoise
        albedo = r.mean("albedo") if r.has_pass_data("albedo") else None
        normal = r.mean("dnormal") if r.has_pass_data("dnormal") else None
        out = denoiser.denoise_rgba(image, albedo, normal, settings)
        self._denoised = (tag, n, out)
        return out


def _mean_confidence(renderer: FrameRenderer, key: str) -> float | None:
    """Mean reservoir confidence M per sample over the pixels that have one (None: no such reservoirs)."""
    m = renderer.sums(key)
    if m is None or not renderer.samples_done:
        return None
    hit = m > 0
    return float(m[hit].mean() / renderer.samples_done) if hit.any() else 0.0
