"""Per-stage timing of a frame: wall seconds, CPU utilisation and the time spent inside Embree.

A :class:`StageClock` is handed to the renderer; each named stage of a sample pass (primary rays, initial
RIS, temporal, spatial, shading, path continuation, writing passes) runs inside ``clock.stage(name)``.
Figures per stage: wall seconds (the stage's elapsed time in the orchestrating thread), CPU seconds of the
whole process (all threads) and Embree thread-seconds (the sum over threads of the time spent in
``EmbreeScene.run``). Utilisation = CPU / (wall x cores); Embree share = Embree / (wall x cores).
"""
from __future__ import annotations

import threading
import time
from contextlib import contextmanager

_EMBREE_LOCK = threading.Lock()
_EMBREE_SECONDS = 0.0


def add_embree_seconds(seconds: float) -> None:
    """Called by accel.py after every Embree call (thread-seconds, summed over threads)."""
    global _EMBREE_SECONDS
    with _EMBREE_LOCK:
        _EMBREE_SECONDS += seconds


def embree_seconds() -> float:
    """Embree thread-seconds since the process started."""
    return _EMBREE_SECONDS


class StageClock:
    """Accumulates {stage: {"wall", "cpu", "embree", "calls"}} over the stages it times."""

    def __init__(self):
        self.stages: dict[str, dict] = {}

    @contextmanager
    def stage(self, name: str):
        w0, c0, e0 = time.perf_counter(), time.process_time(), embree_seconds()
        try:
            yield
        finally:
            rec = self.stages.setdefault(name, {"wall": 0.0, "cpu": 0.0, "embree": 0.0, "calls": 0})
            rec["wall"] += time.perf_counter() - w0
            rec["cpu"] += time.process_time() - c0
            rec["embree"] += embree_seconds() - e0
            rec["calls"] += 1


class NullClock(StageClock):
    """A clock that times nothing (the default)."""

    @contextmanager
    def stage(self, name: str):
        yield
