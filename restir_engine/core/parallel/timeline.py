"""A measurement aid: when each process of a team arrives at and leaves each barrier, and when messages pass between
the rendering process and its workers.

Recorded only where the environment variable RESTIR_TIMELINE names a folder (workers inherit it); each process then
writes its events to ``<folder>/<name>.json`` when it ends. Times are ``time.perf_counter()`` seconds, which on
Linux is CLOCK_MONOTONIC, one clock for every process of the machine, so the records line up.
``scripts/bench.py team_timeline FOLDER`` reads them.
"""
from __future__ import annotations

import json
import os
import sys
import time

ENV = "RESTIR_TIMELINE"
FOLDER = os.environ.get(ENV) or None
_events: list = []


def mark(kind: str, label: str = "") -> None:
    """Record event ``kind`` (with ``label``) now, with the CPU seconds this process has used so far (a worker whose
    wall time between two events exceeds its CPU time was waiting or not scheduled)."""
    _events.append((time.perf_counter(), kind, label, time.process_time()))


def caller(depth: int) -> str:
    """``file:line:function`` of the frame ``depth`` levels above the caller, and of the one above it where that
    is a Team method passing a barrier on (commit, table)."""
    frame = sys._getframe(depth + 1)
    out = f"{os.path.basename(frame.f_code.co_filename)}:{frame.f_lineno}:{frame.f_code.co_name}"
    if frame.f_code.co_name in ("commit", "table") and frame.f_back is not None:
        up = frame.f_back
        out += f"<{os.path.basename(up.f_code.co_filename)}:{up.f_lineno}:{up.f_code.co_name}"
    return out


def dump(name: str) -> None:
    """Write this process's events to ``<folder>/<name>.json`` (nothing where no folder is named)."""
    if FOLDER is None:
        return
    with open(os.path.join(FOLDER, f"{name}.json"), "w") as fh:
        json.dump(_events, fh)
