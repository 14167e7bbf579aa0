"""Worker processes rendering each frame together, driven from the rendering process (Blender's, or the CLI's).

Python runs one thread of bytecode at a time, so threads stop scaling at a few cores; processes do not. A
:class:`WorkerTeam` is a persistent set of N spawned processes (spawn, as Windows and macOS need; inside Blender its
own Python): each imports only the core (boot/restir_worker_boot.py), builds its own Embree scenes and renders every
sample pass at the same time as the others, each computing the chunks it owns (team.py). They share, through
segments of shared memory that this process creates and unlinks: the exported scene (wire.pack, once per frame),
the arena slots of the whole-image buffers and the film, which this process reads the passes from.

Faults: a stop request sets a shared flag and breaks the team's barrier (every worker leaves its pass within a
stage's task); a worker that dies or fails ends the whole team with one error (:class:`WorkerFailed`), its
processes killed and its segments unlinked; the next render starts a new team. Worker processes also exit when
this process is gone (a watchdog thread in each).
"""
from __future__ import annotations

import atexit
import contextlib
import itertools
import multiprocessing as mp
import os
import sys
import threading
import time
from multiprocessing import connection

import numpy as np

from . import timeline, wire

CORE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BOOT_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "boot")
POLL_SECONDS = 0.02      # how often a waiting rendering process asks should_stop and checks its workers
START_TIMEOUT = 120.0    # seconds a new worker may take to import the core and answer
QUIT_SECONDS = 2.0       # a worker asked to quit is killed after this long
COST_ENTRIES = 1 << 16   # chunks whose costs the team keeps (more chunks: round-robin)

_IDS = itertools.count(1)


class WorkerFailed(RuntimeError):
    """A worker process died or raised: the frame is lost and the team is ended."""


class WorkerStartFailed(WorkerFailed):
    """Worker processes cannot start here (no shared memory, no Python to spawn, the core failing to import):
    this process renders alone for the rest of the session."""


@contextlib.contextmanager
def _plain_main():
    """Spawned children re-import the parent's ``__main__`` from its file or module name; Blender's (a text block,
    a script importing bpy) cannot be imported without bpy, and workers need nothing from it."""
    main = sys.modules.get("__main__")
    saved = {k: main.__dict__[k] for k in ("__file__", "__spec__") if main is not None and k in main.__dict__}
    try:
        if main is not None:
            main.__dict__.pop("__file__", None)
            main.__dict__["__spec__"] = None
        yield
    finally:
        if main is not None:
            main.__dict__.pop("__spec__", None)
            main.__dict__.update(saved)


class WorkerTeam:
    """``size`` worker processes of ``threads`` threads each, started now and kept until :meth:`close`."""

    def __init__(self, size: int, threads: int = 1):
        self.id = next(_IDS)
        self.size, self.threads = int(size), max(1, int(threads))
        ctx = mp.get_context("spawn")
        self.barrier = ctx.Barrier(self.size)
        self.stop = ctx.RawValue("b", 0)
        self.progress = ctx.RawValue("d", 0.0)  # the leader's fraction of the pass in flight
        # the order of the passes that workers render at the same time, one each (team.Independent)
        self.order = ctx.Array("q", 1 + COST_ENTRIES)
        self.closed = False
        self.slot_segs, self.slot_bytes = [], 0
        self.film_seg = None
        self.costs_seg = wire.create_segment(8 * COST_ENTRIES)  # the chunks' costs (team.Team.costs)
        self.tokens = itertools.count(1)
        self.lock = threading.Lock()  # one frame at a time
        if BOOT_DIR not in sys.path:
            sys.path.insert(0, BOOT_DIR)
        import restir_worker_boot
        self.conns, self.procs = [], []
        t0 = time.perf_counter()
        with _plain_main():
            for rank in range(self.size):
                mine, theirs = ctx.Pipe()
                p = ctx.Process(target=restir_worker_boot.main, name=f"restir-worker-{rank}", daemon=True,
                                args=(CORE_DIR, rank, self.size, theirs, self.barrier, self.stop, self.progress,
                                      self.threads, self.order))
                p.start()
                theirs.close()
                self.conns.append(mine)
                self.procs.append(p)
        self.start_seconds = time.perf_counter() - t0
        atexit.register(self.close)

    # -- shared segments ---------------------------------------------------------------------------------------
    def ensure_slots(self, nbytes: int, histories: int = 1) -> list[str]:
        """Names of the arena slots (parallel/team.py) for frames that keep ``histories`` temporal histories: one
        per history, one for the first pass that writes the next, one for the other passes; each at least ``nbytes``
        (new ones replace them where they are too small or too few; their pages are committed only where written)."""
        count = max(1, int(histories)) + 2
        if self.slot_bytes < nbytes or len(self.slot_segs) != count:
            wire.unlink_segments(self.slot_segs)
            self.slot_bytes = max(int(nbytes), self.slot_bytes if len(self.slot_segs) == count else 0)
            self.slot_segs = [wire.create_segment(self.slot_bytes) for _ in range(count)]
        return [s.name for s in self.slot_segs]

    def film(self, nbytes: int, dtype):
        """(segment name, zeros(shape) of ``dtype`` over it): the film's segment, zero-filled, at least
        ``nbytes``."""
        seg = self.film_seg
        if seg is None or seg.size < nbytes:
            wire.unlink_segments([seg] if seg is not None else [])
            seg = self.film_seg = wire.create_segment(nbytes)
        else:
            view = np.frombuffer(seg.buf, np.uint8, nbytes)
            view[:] = 0
            del view
        from .team import film_zeros
        return seg.name, film_zeros(seg, dtype)

    # -- messages ------------------------------------------------------------------------------------------------
    def run(self, msg, should_stop=None, timeout: float | None = None, on_poll=None):
        """Send ``msg`` to every worker and wait for all replies: the payloads (rank order), or None when the
        pass was stopped (``should_stop()`` turned true, which stops every worker); ``on_poll()`` is called every
        POLL_SECONDS while waiting. Raises WorkerFailed when a worker died or failed (the team is then
        closed)."""
        if self.closed:
            raise WorkerFailed("the render worker processes were shut down")
        if timeline.FOLDER is not None:
            timeline.mark("ask", msg[0])
        for i, c in enumerate(self.conns):
            try:
                c.send(msg)
            except OSError:  # the worker's end is gone (it died before this message): one clear error
                failure = self._died(i)
                self.close(kill=True)
                raise WorkerFailed(failure) from None
        replies = [None] * self.size
        pending = set(range(self.size))
        stopping, failure = False, None
        t0 = time.perf_counter()
        while pending:
            if on_poll is not None:
                on_poll()
            if not stopping and should_stop is not None and should_stop():
                stopping = True
                self.stop.value = 1
                self.barrier.abort()
            waits = [self.conns[i] for i in pending] + [self.procs[i].sentinel for i in pending]
            ready = connection.wait(waits, timeout=POLL_SECONDS)
            for i in list(pending):
                if self.conns[i] in ready or self.conns[i].poll():
                    try:
                        replies[i] = self.conns[i].recv()
                    except (EOFError, OSError):
                        failure = failure or self._died(i)
                    pending.discard(i)
                elif self.procs[i].sentinel in ready:
                    failure = failure or self._died(i)
                    pending.discard(i)
            if failure is not None:
                break
            if timeout is not None and time.perf_counter() - t0 > timeout:
                failure = f"the render worker processes did not answer within {timeout:.0f} s"
                break
        if failure is None:
            errors = [r[1] for r in replies if r[0] == "error"]
            if errors:
                failure = "a render worker process failed: " + errors[0]
        if failure is not None:
            self.close(kill=True)
            raise WorkerFailed(failure)
        if stopping or any(r[0] == "stopped" for r in replies):
            self.barrier.reset()
            self.stop.value = 0
            if any(r[0] == "stopped" for r in replies):
                return None
        out = [wire.loads(r[1], "restir_core") for r in replies]
        if timeline.FOLDER is not None:
            timeline.mark("answered", msg[0])
        return out

    def start_order(self) -> None:
        """Before the workers render passes at once, one each (team.Independent): none committed, no chunk added."""
        with self.order.get_lock():
            np.frombuffer(self.order.get_obj(), np.int64)[:] = 0

    def committed(self) -> int:
        """How many of the passes rendered at once are in the film (they are always the first ones)."""
        with self.order.get_lock():
            return int(self.order[0])

    def _died(self, i: int) -> str:
        p = self.procs[i]
        p.join(0.5)
        return f"render worker process {i} (pid {p.pid}) ended unexpectedly (exit code {p.exitcode})"

    def next_token(self) -> int:
        return next(self.tokens)

    def alive(self) -> bool:
        return not self.closed and all(p.is_alive() for p in self.procs)

    def close(self, kill: bool = False) -> None:
        """End the workers (asked to quit, then killed after QUIT_SECONDS; at once with ``kill``) and unlink every
        segment this team created."""
        if self.closed:
            return
        self.closed = True
        for c in self.conns:
            with contextlib.suppress(Exception):
                if not kill:
                    c.send(("quit",))
        deadline = time.perf_counter() + (0.0 if kill else QUIT_SECONDS)
        for p in self.procs:
            p.join(max(0.0, deadline - time.perf_counter()))
        for p in self.procs:
            if p.is_alive():
                p.kill()
                p.join(1.0)
        for c in self.conns:
            c.close()
        wire.unlink_segments(self.slot_segs + [self.costs_seg] + ([self.film_seg] if self.film_seg is not None else []))
        self.slot_segs, self.film_seg = [], None
        with contextlib.suppress(Exception):
            atexit.unregister(self.close)


_TEAM: WorkerTeam | None = None
_TEAM_LOCK = threading.Lock()
_PROCESSES: int | None = None  # set_process_count's: None = not set (this process alone), 0 = Auto


def set_process_count(processes: int | None) -> None:
    """Render with ``processes`` worker processes from the next frame on: 0 = Auto (see :func:`process_count`),
    1 or None = in the rendering process itself (the core's default; the add-on sets Render Properties >
    Performance > Processes)."""
    global _PROCESSES
    _PROCESSES = None if processes is None else max(0, int(processes))


def process_count(cores: int, chunks: int) -> int:
    """Worker processes for ``cores`` cores and a frame of ``chunks`` chunks: the count set, else (Auto) one per core
    from AUTO_MIN_CORES cores up; never more than the chunks; 1 renders in this process with every thread."""
    if _PROCESSES is None:
        return 1
    n = _PROCESSES if _PROCESSES > 0 else (cores if cores >= AUTO_MIN_CORES else 1)
    return max(1, min(n, chunks))


AUTO_MIN_CORES = 2  # Auto uses worker processes from this many cores up (2 already gain: docs/RESULTS.md)


def split(threads: int | None, processes: int, chunks: int | None = None) -> tuple[int, int]:
    """(processes, threads in each) for a Threads setting (None: every logical core), a Processes setting (0: Auto)
    and a frame of ``chunks`` chunks (None: any number): what F12 renders with."""
    cores = max(1, int(threads) if threads else (os.cpu_count() or 1))
    n = int(processes) if processes and processes > 0 else (cores if cores >= AUTO_MIN_CORES else 1)
    if chunks is not None:
        n = max(1, min(n, int(chunks)))
    return n, (max(1, cores // n) if n > 1 else cores)


_DISABLED: str | None = None  # why worker processes could not start in this session (None: they can)


def _start(size: int, threads: int) -> WorkerTeam:
    """A new team, started and answering (call with _TEAM_LOCK held). Raises WorkerStartFailed when workers cannot
    start here (then for the rest of the session)."""
    global _DISABLED
    if _DISABLED is not None:
        raise WorkerStartFailed(_DISABLED)
    try:
        started = WorkerTeam(size, threads)
        started.run(("ping",), timeout=START_TIMEOUT)
    except Exception as exc:  # noqa: BLE001 - any failure to start means: render in this process
        if "started" in locals():
            started.close(kill=True)
        _DISABLED = f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}"
        raise WorkerStartFailed(_DISABLED) from exc
    return started


def team(size: int, threads: int = 1) -> WorkerTeam:
    """The persistent team of ``size`` workers that final renders use (a new one when the size changed or the last
    one failed), started and answering. Raises WorkerStartFailed when workers cannot start here."""
    global _TEAM
    with _TEAM_LOCK:
        if _TEAM is not None and (_TEAM.size != size or _TEAM.threads != threads or not _TEAM.alive()):
            _TEAM.close(kill=not _TEAM.alive())
            _TEAM = None
        if _TEAM is None:
            _TEAM = _start(size, threads)
        return _TEAM


_IDLE: list[WorkerTeam] = []  # viewport teams given back, kept for the next session (at most IDLE_TEAMS)
IDLE_TEAMS = 1


def borrow(size: int, threads: int = 1) -> WorkerTeam:
    """A team of ``size`` workers for one user alone (a viewport session, whose renderer lives in its workers
    between passes while final renders use :func:`team`): an idle one of that shape, else a new one. Hand it back
    with :func:`give_back`. Raises WorkerStartFailed when workers cannot start here."""
    with _TEAM_LOCK:
        for t in list(_IDLE):
            _IDLE.remove(t)
            if t.size == size and t.threads == threads and t.alive():
                return t
            t.close(kill=not t.alive())
        return _start(size, threads)


def give_back(team: WorkerTeam) -> None:
    """A borrowed team is free again: kept idle for the next borrower (the newest IDLE_TEAMS), or ended."""
    with _TEAM_LOCK:
        if team.closed or not team.alive():
            team.close(kill=True)
            return
        with contextlib.suppress(Exception):
            team.run(("end",), timeout=QUIT_SECONDS)  # its workers drop the session's renderer
        if team.closed:
            return
        _IDLE.append(team)
        while len(_IDLE) > IDLE_TEAMS:
            _IDLE.pop(0).close()


def shutdown() -> None:
    """End the persistent team and the idle borrowed ones (add-on unregister, interpreter exit)."""
    global _TEAM
    with _TEAM_LOCK:
        if _TEAM is not None:
            _TEAM.close()
            _TEAM = None
        while _IDLE:
            _IDLE.pop().close()


def abandon() -> None:
    """Kill the team's workers at once and unlink its segments, without waiting for the team's lock (a render may
    hold it): for a process about to end itself in a signal handler (the CLI's Ctrl+C), so that no worker and no
    shared-memory segment outlives it."""
    global _TEAM
    teams = [t for t in [_TEAM] + _IDLE if t is not None]
    _TEAM = None
    del _IDLE[:]
    for t in teams:
        with contextlib.suppress(Exception):
            t.close(kill=True)
    # the team's semaphores (barrier, stop flag) are unlinked by multiprocessing's exit finalizers, which an
    # os._exit skips: run them now
    from multiprocessing import util
    with contextlib.suppress(Exception):
        util._run_finalizers(0)
