"""A render worker process's loop: it renders the frames it is sent as one member of a team (team.py), each sample
pass at the same time as the other workers, into the team's shared film.

Messages (tuples from the rendering process; each is answered with ("ok", pickled payload) or ("stopped", None) or
("error", text)):
  ("frame", frame)  build the frame's renderer: the scene (wire.pack), settings, the history token it may reuse,
                    the film's and the arena slots' segments; with ``frame["view"]`` (a viewport's edit) the last
                    renderer's newest history is carried into it, as the viewport does in one process; the leader's
                    payload: :meth:`_Worker.facts`
  ("view", view)    the viewport moved: the renderer renders from ``view["camera"]`` as frame ``view["frame"]`` into
                    the zero-filled film segment ``view["film"]`` (FrameRenderer.move_camera); payload: facts
  ("motion", m)     the scene's motion for the next pass's reprojection (FrameRenderer.set_motion)
  ("pass", left[, batch, cap])  render the next sample pass (``batch`` samples, None: at most ``left`` as
                    FrameRenderer.batch_size chooses; at most ``cap`` light candidates); payload: (the samples it
                    rendered, whether adaptive sampling stopped every pixel, the batch the next pass may render,
                    None or, where the frame's next passes are independent, the methods they render with and the
                    sample count of adaptive sampling's next check, which ends them)
  ("spread", first, count, batch, end)  render ``count`` independent passes at once, one per worker in turn
                    (:meth:`_Worker.spread`); payload: the worker's pass counts
  ("data",)         the leader's payload: the data passes (Depth, Normal, Vector) of the current view
  ("finish", token[, counts])  end the frame (the other workers' pass ``counts`` added to the leader's): keep
                    its history under ``token``; the leader's payload: the frame's stats, data
                    passes and whether the film has reservoir passes
  ("end",)          drop the renderer (a viewport session ends)
  ("ping",)         answer once started (the core imported)
  ("quit",)         exit
"""
from __future__ import annotations

import os
import traceback

import numpy as np

from ..parallel import timeline, wire
from ..parallel.pool import set_thread_count
from ..parallel.team import FAILED, Arena, Team, film_zeros
from .film import FILM_DTYPE
from .batches import ANY_BATCH
from .frame_stats import add_pass_counts, pass_counts

KEEP_SCENES = 3  # scene segments a worker keeps attached (a context may still refer to the last frames' arrays)
KEEP_HISTORIES = 1  # temporal histories a worker keeps by default: the last frame's (a banded frame: one per band)


class _Worker:
    def __init__(self, rank: int, size: int, conn, barrier, stop, progress, threads: int, order):
        self.rank, self.size, self.conn, self.barrier, self.stop = rank, size, conn, barrier, stop
        self.progress = progress  # the leader's fraction of the pass in flight (a shared double)
        # the order of passes rendered at once, one per worker (team.Independent), and its lock
        self.order_lock, self.order = order.get_lock(), np.frombuffer(order.get_obj(), np.int64)
        set_thread_count(max(1, int(threads)))
        self.team = None
        self.slot_names = None
        self.film_seg = None
        self.scenes: list = []     # attached scene segments, newest last
        self.fr = None
        self.scene = None
        self.clock = None
        self.histories: dict = {}  # token -> the temporal history of the frame (or band) it named
        self.keep_histories = KEEP_HISTORIES

    # -- segments --------------------------------------------------------------------------------------------
    def _slots(self, names, costs: str) -> bool:
        """Attach the arena slots and the costs segment; whether they changed (histories in the old ones are
        dropped)."""
        if self.slot_names == (names, costs):
            return False
        segs = [wire.attach_segment(n) for n in names + [costs]]
        self._drop(getattr(self, "slot_segs", []))
        self.slot_segs, self.slot_names = segs, (names, costs)
        self.team = Team(self.rank, self.size, self.barrier, [Arena(s.buf, s.name) for s in segs[:-1]], self.stop,
                         np.frombuffer(segs[-1].buf, np.float64))
        self.histories = {}  # they lived in the old slots
        return True

    def _film(self, name: str):
        if self.film_seg is None or self.film_seg.name != name:
            if self.film_seg is not None:
                self._drop([self.film_seg])
            self.film_seg = wire.attach_segment(name)
        return film_zeros(self.film_seg, FILM_DTYPE)

    def _drop(self, segs) -> None:
        for seg in segs:
            wire.release_segment(seg)

    # -- messages ----------------------------------------------------------------------------------------------
    def frame(self, frame: dict):
        from .frame import FrameRenderer
        from ..profile import StageClock
        old = self.fr
        carried = old.latest_history() if frame.get("view") and old is not None else None
        if old is not None:
            old.release()
            self.fr = None
        if self._slots(frame["slots"], frame["costs"]):
            carried = None
        zeros = self._film(frame["film"])
        scene = wire.unpack(frame["scene"], self.scenes)
        if len(self.scenes) > KEEP_SCENES:
            self._drop(self.scenes[:-KEEP_SCENES])
            del self.scenes[:-KEEP_SCENES]
        settings = wire.loads(frame["settings"], frame["sender"])
        history = self.histories.pop(frame["history"], None) if frame["history"] is not None else None
        self.keep_histories = max(KEEP_HISTORIES, int(frame.get("keep_histories", KEEP_HISTORIES)))
        self.team.keep = self.keep_histories
        self.clock = StageClock() if frame["clock"] and self.team.leader else None
        self.scene = scene
        self.fr = FrameRenderer(scene, settings, history, self.clock, team=self.team, film_zeros=zeros,
                                keep_history=frame.get("keep_history", True))
        if carried is not None and settings.temporal_reuse:
            self.fr.adopt_history(carried)
        return {"build_seconds": self.fr.build_seconds, **(self.facts() or {})}

    def facts(self) -> dict | None:
        """The leader's facts about its renderer that the rendering process shows or decides by: the direct method,
        whether it resamples, whether the next first pass reuses a history, the batch the next pass may render."""
        fr = self.fr
        if not self.team.leader:
            return None
        return {"method": fr.method, "resampled": fr.candidates is not None, "reuses": fr.reuses_history(),
                "batch": fr.batch_size(ANY_BATCH)}

    def view(self, view: dict):
        fr = self.fr
        fr.film_zeros = self._film(view["film"])
        fr.move_camera(view["camera"], view["frame"])
        return self.facts()

    def sample_pass(self, left: int, batch: int | None = None, cap: int | None = None):
        fr = self.fr
        batch = fr.batch_size(int(left)) if batch is None else int(batch)
        report = None
        if self.team.leader:
            self.progress.value = 0.0

            def report(fraction):
                self.progress.value = fraction
        if not fr.sample_pass(report, self.team.stopping, batch, cap):
            return None
        settled = {"method": fr.method, "gi": fr.gi_runs(), "until": fr.independent_until()} \
            if fr.passes_independent() else None
        return batch, fr.converged, fr.batch_size(ANY_BATCH), settled

    def spread(self, first: int, count: int, batch: int, end: int):
        """Render ``count`` independent passes of ``batch`` samples from sample ``first`` on (the last one ends at
        sample ``end`` at most) at the same time as the other workers: the ``j``-th pass by worker ``j`` mod team
        size, each whole and alone, added to the shared film in sample order (team.Independent). Payload: this
        worker's pass counts for the frame's stats (frame_stats.pass_counts); None when stopped."""
        from ..parallel.team import Independent
        fr = self.fr
        before = pass_counts(fr)
        report = None
        if self.team.leader:
            def report(fraction):
                self.progress.value = fraction
        for j in range(self.rank, count, self.size):
            s = first + j * batch
            member = Independent(j, self.order, self.order_lock, self.stop)
            if report is not None:
                report(0.0)
            if not fr.independent_pass(s, min(batch, end - s), member, self.team.stopping, report):
                return None
        fr.film.samples = min(end, first + count * batch)
        return {k: v - before[k] for k, v in pass_counts(fr).items()}

    def finish(self, token: int, counts: dict | None = None):
        from .frame_stats import frame_stats
        fr = self.fr
        out = None
        if self.team.leader:
            if counts:  # what the other workers' independent passes counted (spread)
                add_pass_counts(fr, counts)
            data = tuple(a for a in fr.data_passes()) if fr.settings.data_passes else None
            out = {"stats": frame_stats(fr, self.scene, self.clock), "data": data,
                   "reservoirs": fr.candidates is not None, "history": fr.history is not None}
        if fr.history is not None:
            self.histories[token] = fr.history
            for old in sorted(self.histories)[:-self.keep_histories]:
                del self.histories[old]
        fr.release()
        self.fr = self.scene = None
        return out

    def serve(self) -> None:
        try:
            self._serve()
        finally:  # quietly: arrays of the last frame may still view them
            self.fr = self.scene = self.team = None
            self.histories = {}
            self._drop(self.scenes + getattr(self, "slot_segs", []) + ([self.film_seg] if self.film_seg else []))

    def _serve(self) -> None:
        while True:
            try:
                msg = self.conn.recv()
            except EOFError:
                return
            kind = msg[0]
            if timeline.FOLDER is not None:
                timeline.mark("recv", kind)
            if kind == "quit":
                return
            try:
                if kind == "ping":
                    out = None
                elif kind == "frame":
                    out = self.frame(msg[1])
                elif kind == "view":
                    out = self.view(wire.loads(*msg[1]))
                elif kind == "motion":
                    self.fr.set_motion(wire.loads(*msg[1]))
                    out = None
                elif kind in ("pass", "spread"):
                    out = self.sample_pass(*msg[1:]) if kind == "pass" else self.spread(*msg[1:])
                    if out is None:
                        self.conn.send(("stopped", None))
                        continue
                elif kind == "data":
                    out = tuple(self.fr.data_passes()) if self.team.leader else None
                elif kind == "finish":
                    out = self.finish(*msg[1:])
                elif kind == "end":
                    if self.fr is not None:
                        self.fr.release()
                    self.fr = self.scene = None
                    out = None
                else:
                    raise ValueError(f"unknown message {kind!r}")
                self.conn.send(("ok", wire.dumps(out)))
                if timeline.FOLDER is not None:
                    timeline.mark("sent", kind)
            except Exception as exc:  # the others must not wait for this one at a barrier or for its turn
                self.stop.value = FAILED
                self.barrier.abort()
                self.conn.send(("error", f"{type(exc).__name__}: {exc}\n{traceback.format_exc()}"))


def serve(rank: int, size: int, conn, barrier, stop, progress, threads: int, order) -> None:
    worker = _Worker(rank, size, conn, barrier, stop, progress, threads, order)
    folder = os.environ.get(PROFILE_ENV)
    if not folder:
        try:
            worker.serve()
        finally:
            timeline.dump(f"worker{rank}")
        return
    import cProfile  # a measurement aid (scripts/benchmarks/scaling.py --profile): each worker's own profile
    profile = cProfile.Profile()
    profile.enable()
    try:
        worker.serve()
    finally:
        profile.disable()
        profile.dump_stats(os.path.join(folder, f"worker{rank}.prof"))


#: where workers write their cProfile statistics when set (a folder; unset: no profiling)
PROFILE_ENV = "RESTIR_PROFILE_WORKERS"
