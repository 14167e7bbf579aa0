"""A frame rendered by a team of worker processes (parallel/processes.py): the same passes, in the same order,
from the same random streams as :func:`frame_render.render_frame` in one process, so the same seed gives the same image.

This process sends the scene once (in shared memory), asks for one sample pass after another (polling the stop
request and the workers while they render) and reads the passes from the shared film. The temporal history stays
in the workers (in their arena slots); the frame's result carries a :class:`SharedHistory` that names it.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from ..parallel import timeline, wire
from ..parallel.processes import WorkerTeam
from ..sampling import finite
from . import memory, methods, spread
from .film import FILM_DTYPE, Film, film_keys
from .shadow_catcher import catcher_triangles, film_mode
from .frame import Cancelled, FrameResult
from .frame_render import out_of_time
from .settings import RenderSettings, validate

SURFACE_BYTES = 300  # per surface and pass: the target terms (DI's and GI's), the G-buffer, tables
DI_BYTES = 24 + 48   # one DI reservoir (restir.di.DIReservoirs) and its light point (target.FramePoints)
GI_BYTES = 44 + 44   # one GI reservoir (restir.gi.GIReservoirs) and its packed point
PIXEL_BYTES = 12 + 100  # the light tiles' surface positions; the block tiles (lights/blocks.py) per pixel
SLACK = 1.5          # alignment and margin (the pages of a slot are only committed where written)
FIXED_BYTES = 1 << 20


@dataclass(frozen=True)
class SharedHistory:
    """The temporal history a team's workers kept from a frame (``token``), and the view it was seen from."""

    team: int
    token: int
    size: tuple  # (window width, window height, camera width, camera height)

    def fits(self, camera) -> bool:
        return self.size == _view_size(camera)


def _view_size(camera) -> tuple:
    return (*camera.window[2:], camera.width, camera.height)


def slot_bytes(pixels: int, st: RenderSettings) -> int:
    """Bytes an arena slot needs for one pass of ``pixels`` window pixels: every whole-image buffer it allocates
    (parallel/team.py)."""
    per = SURFACE_BYTES + DI_BYTES * (4 + int(st.spatial_passes)) + GI_BYTES * (4 + int(st.gi_spatial_passes))
    return int((pixels * (per + PIXEL_BYTES)) * SLACK) + FIXED_BYTES


def film_bytes(w: int, h: int, gi: bool, denoise_data: bool, adaptive: bool = False, groups: int = 0,
               catchers: bool = False) -> int:
    from ..parallel.team import ALIGN
    size = np.dtype(FILM_DTYPE).itemsize
    return sum(-(-(w * h * c * size) // ALIGN) * ALIGN
               for _key, c in film_keys(gi, denoise_data, adaptive, groups, catchers)) + ALIGN


def shared_film(team: WorkerTeam, scene, settings: RenderSettings) -> tuple[str, Film]:
    """(segment name, Film) of ``scene``'s camera window over ``team``'s film segment, zero-filled: the
    accumulators each worker's FrameRenderer lays out in the same order over the same segment."""
    _x0, _y0, w, h = scene.camera.window
    gi = methods.gi_possible(settings)
    adaptive = settings.use_adaptive_sampling
    lg = getattr(scene, "light_groups", None)
    group_names = () if lg is None else tuple(lg.names)
    catchers = film_mode(settings, catcher_triangles(scene) is not None)
    name, zeros = team.film(film_bytes(w, h, gi, settings.denoise_data, adaptive, len(group_names),
                                       catchers is not None), FILM_DTYPE)
    return name, Film(w, h, gi, settings.denoise_data, zeros, adaptive, group_names, catchers)


def _spread(team: WorkerTeam, done: int, count: int, batch: int, end: int, counts: dict, progress,
            should_stop, samples: int) -> tuple[int, bool]:
    """(samples rendered, whether stopped) of ``count`` independent passes of ``batch`` samples from sample ``done``
    on (the last one ends at sample ``end`` at most; the frame has ``samples``), rendered at once, one per worker
    (spread.py); the workers' pass counts other than the leader's are added to ``counts``. A stop keeps the passes
    already in the film (the first ones)."""
    poll = None
    if progress:
        def poll():  # the passes in the film, and those in flight as far as the leader is through its own
            committed = team.committed()
            flying = min(team.size, count - committed) * team.progress.value
            k = done + min(end - done, committed * batch)
            progress(min(end, k + flying * batch) / samples, f"Sample {min(k + 1, samples)}/{samples}")
    team.start_order()
    replies = team.run(("spread", done, count, batch, end), should_stop, on_poll=poll)
    rendered = min(end, done + team.committed() * batch) - done
    if replies is None:
        return rendered, True
    for r in replies[1:]:
        for k, v in r.items():
            counts[k] = counts.get(k, 0) + v
    return rendered, False


def render_frame_shared(scene, settings: RenderSettings, team: WorkerTeam, progress=None, should_stop=None,
                        history=None, clock=None, keep_histories: int = 1, keep_history: bool = True,
                        slot_pixels: int = 0) -> FrameResult:
    """:func:`frame_render.render_frame` on ``team``'s workers (same arguments and result; ``history`` a SharedHistory
    of this team, anything else is not reused); the workers keep the newest ``keep_histories`` histories (one per
    band of a banded frame), and this frame's only where ``keep_history``."""
    validate(settings)
    t0 = time.perf_counter()
    with team.lock:
        cam = scene.camera
        _x0, _y0, w, h = cam.window
        film_name, film = shared_film(team, scene, settings)
        slots = team.ensure_slots(slot_bytes(max(w * h, int(slot_pixels)), settings), keep_histories)
        usable = isinstance(history, SharedHistory) and history.team == team.id and history.fits(cam)
        if timeline.FOLDER is not None:
            timeline.mark("main", "film and slots")
        seg, packed = wire.pack(scene)
        if timeline.FOLDER is not None:
            timeline.mark("main", "scene packed")
        try:
            team.run(("frame", {"scene": packed, "settings": wire.dumps(settings), "sender": wire.core_name(),
                                "history": history.token if usable else None, "film": film_name, "slots": slots,
                                "keep_histories": int(keep_histories), "keep_history": bool(keep_history),
                                "costs": team.costs_seg.name, "clock": clock is not None}))
        finally:  # every worker attached (or the team is gone): the name is no longer needed
            wire.unlink_segments([seg])
        done, cancelled, counts, settled, at_once = 0, False, {}, None, 0
        while done < settings.samples and not out_of_time(settings, t0, done):
            if settled is not None and settings.time_limit <= 0:
                left = spread.samples_at_once(settings.samples - done, done, batch, settled["until"])
                count = spread.passes_at_once(left, batch, team.size)
                if count and spread.fits(scene, settings, settled["method"], settled["gi"], team.size,
                                         memory.available_memory()):
                    rendered, stopped = _spread(team, done, count, batch, done + left, counts, progress,
                                                should_stop, settings.samples)
                    done += rendered
                    at_once += -(-rendered // batch)
                    if stopped:
                        cancelled = True
                        break
                    settled = None  # the rest (fewer passes than workers) shared out pass by pass
                    continue
            poll = None
            if progress:
                label = f"Sample {done + 1}/{settings.samples}"
                progress(done / settings.samples, label)
                team.progress.value = 0.0

                def poll(done=done, label=label):  # the leader's share of its pass: one sample's worth
                    progress((done + team.progress.value) / settings.samples, label)
            # with a time limit, one sample at a time: the limit is checked between passes
            ask = 1 if settings.time_limit > 0 else settings.samples - done
            replies = team.run(("pass", ask), should_stop, on_poll=poll)
            if replies is None:
                cancelled = True
                break
            rendered, converged, batch, settled = replies[0][:4]
            done += int(rendered)
            if converged:  # adaptive sampling stopped every pixel
                break
        token = team.next_token()
        out = team.run(("finish", token, counts))[0]
        if done == 0:
            raise Cancelled("render cancelled before the first sample pass finished")
        film.samples = done
        passes = film.passes(out["reservoirs"])
        if out["data"] is not None:
            passes["Depth"], passes["Normal"], passes["Vector"] = (finite(a) for a in out["data"])
        film.release()
        if timeline.FOLDER is not None:
            timeline.mark("main", "film read")
        stats = out["stats"]
        stats["processes"] = team.size
        stats["passes_one_per_process"] = at_once  # rendered whole by one worker each, at the same time
        if clock is not None and "stages" in stats:  # the leader's stages, added to the frame's other bands'
            for name, rec in stats["stages"].items():
                mine = clock.stages.setdefault(name, {k: 0 for k in rec})
                for k, v in rec.items():
                    mine[k] = mine.get(k, 0) + v
        hist = SharedHistory(team.id, token, _view_size(cam)) if out["history"] else None
        return FrameResult(passes, done, time.perf_counter() - t0, cancelled, stats, hist)
