"""One frame from its settings to its result: in bands where memory asks for them (bands.py), on a team of worker
processes where that pays (shared_frame.py), else as the sample-pass loop of one FrameRenderer in this process. The
same seed gives the same image any of these ways."""
from __future__ import annotations

import time

from ..parallel.pool import thread_count
from ..parallel.tasks import spans
from ..restir.history import TemporalHistory
from ..scene import Scene
from .frame import Cancelled, FrameRenderer, FrameResult
from .frame_stats import frame_stats
from .settings import RenderSettings


def out_of_time(settings: RenderSettings, t0: float, done: int) -> bool:
    """Whether a frame begun at perf_counter ``t0`` has used its Time Limit (after one pass at least)."""
    return settings.time_limit > 0 and done > 0 and time.perf_counter() - t0 >= settings.time_limit


def render_frame(scene: Scene, settings: RenderSettings, progress=None, should_stop=None, history=None,
                 clock=None, processes: int | None = None, bands: int | None = None,
                 band_margin: int | None = None, keep_history: bool = True, history_slots: int = 1,
                 slot_pixels: int = 0) -> FrameResult:
    """Render one frame with the chosen integrator, in ``processes`` worker processes (None: the count that
    parallel.processes.process_count chooses for the thread count; 1: in this process), at most one per chunk of
    pixels. The same seed gives the same image either way.

    A Time Limit (settings.time_limit) stops the frame after the pass that reaches it (fewer samples; which ones
    is deterministic, how many depends on the machine).
    progress(fraction, message) is called as chunks finish; should_stop() is polled while they run,
    and a stop keeps the sample passes already completed (raises :class:`Cancelled` if none). ``history`` is the
    result's history of the previous frame (rendered the same way; another kind is not reused).

    ``keep_history``: whether the result carries the frame's temporal history (an animation's next frame needs it,
    a still's does not, and keeping it holds a second set of the G-buffer and reservoirs while the frame renders).
    ``bands``: horizontal bands the window is rendered in (bands.py; None: as many as keep one band's working set
    within memory.band_budget, 1 for most frames) with ``band_margin`` extra rows each side (None: bands.plan's, or
    the spatial radius where ``bands`` is given); ``history_slots``: histories worker processes keep (one per band
    of the banded frame this one belongs to) in buffers sized for at least ``slot_pixels`` pixels (its largest band).
    """
    from . import bands as bands_mod
    if bands is None:
        from . import memory
        bands, band_margin = bands_mod.plan(scene, settings, memory.available_memory(), keep_history)
    if bands > 1:
        def one(sc, st, report, stop, hist, clk, pixels):
            return render_frame(sc, st, report, stop, hist, clk, processes, bands=1, keep_history=keep_history,
                                history_slots=bands if keep_history else 1, slot_pixels=pixels)
        return bands_mod.render_in_bands(one, scene, settings, bands, progress, should_stop, history, clock,
                                         band_margin)
    team, note = _team(scene, settings, processes)
    if team is not None:
        from .shared_frame import render_frame_shared
        result = render_frame_shared(scene, settings, team, progress, should_stop, history, clock, history_slots,
                                     keep_history, slot_pixels)
    else:
        result = _render_here(scene, settings, progress, should_stop, history, clock, keep_history)
    if note:
        result.stats["processes_note"] = note
    return result


def team_size(scene: Scene, settings: RenderSettings, processes: int | None) -> tuple[int, str]:
    """(worker processes to render ``scene``'s camera window in, a note for the user where fewer than asked for
    render): ``processes`` (None: what parallel.processes.process_count chooses for the thread count), at most one
    per chunk, as many as fit in memory; 1: this process alone."""
    from ..parallel import processes as procs
    _x0, _y0, w, h = scene.camera.window
    chunks = len(spans(w * h, settings.tile_pixels))
    n = procs.process_count(thread_count(), chunks) if processes is None else min(int(processes), chunks)
    note = ""
    if n > 1:
        from . import memory
        free = memory.available_memory()
        fit = memory.processes_that_fit(n, memory.frame_estimate(scene, settings), len(scene.geometry), free)
        if fit < n:
            note = (f"{n} render processes would not fit in memory ({memory.size_text(free)} free, each needs its "
                    f"own copy of the scene's BVH): rendering with {fit}")
            n = fit
    return max(1, n), note


def _team(scene: Scene, settings: RenderSettings, processes: int | None):
    """(the worker team to render on or None for this process, a note for the user where fewer processes than
    asked for render)."""
    from ..parallel import processes as procs
    n, note = team_size(scene, settings, processes)
    if n <= 1:
        return None, note
    try:
        return procs.team(n, max(1, thread_count() // n)), note
    except procs.WorkerStartFailed as exc:
        return None, f"render worker processes could not start ({exc}): rendering in one process"


def _render_here(scene: Scene, settings: RenderSettings, progress, should_stop, history, clock,
                 keep_history: bool = True) -> FrameResult:
    """The frame's sample passes in this process, until its samples, adaptive convergence or Time Limit; the result
    carries the frame's temporal history where ``keep_history``."""
    if not isinstance(history, TemporalHistory):
        history = None
    t0 = time.perf_counter()
    fr = FrameRenderer(scene, settings, history, clock, keep_history=keep_history)
    cancelled = False
    while fr.samples_done < settings.samples and not fr.converged and not out_of_time(settings, t0, fr.samples_done):
        s = fr.samples_done
        batch = 1 if settings.time_limit > 0 else fr.batch_size(settings.samples - s)  # a limit: checked per sample
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
    samples_done = fr.samples_done
    fr.release()
    return FrameResult(passes, samples_done, time.perf_counter() - t0, cancelled, frame_stats(fr, scene, clock),
                       fr.history)
