"""A stage's tasks on the thread pool, with progress and cancellation.

A stage maps a function over its items (chunks of pixels or spans of surfaces); :func:`map_tasks` runs them on the
pool, reports progress as they finish and polls the stop request every STOP_POLL_SECONDS, raising :class:`Stopped`
when asked to stop part-way (the pass is then dropped whole)."""
from __future__ import annotations

from concurrent.futures import FIRST_COMPLETED, wait

from .pool import pool

STOP_POLL_SECONDS = 0.02  # how often a running stage asks should_stop (the viewport's latency to a new view)


class Stopped(Exception):
    """A stage was asked to stop part-way."""


class Progress:
    """Progress over the tasks of a sample pass (``total`` of them), and the stop request."""

    def __init__(self, progress, should_stop, total: int):
        self.progress, self.should_stop, self.total, self.done = progress, should_stop, max(1, total), 0

    def advance(self, k: int) -> None:
        self.done += k
        if self.progress:
            self.progress(min(1.0, self.done / self.total))


def map_tasks(fn, items, stop: Progress) -> list:
    """[fn(item) for item in items] on the pool (inline for one item); raises :class:`Stopped` when ``stop`` asks
    to stop part-way."""
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
            raise Stopped
        stop.advance(len(done))
    return out


BALANCE = 2  # a frame has a multiple of this many chunks (two threads finish together)
MIN_CHUNKS = 32  # a frame of at least MIN_CHUNKS * MIN_CHUNK_ITEMS items has at least this many chunks
MIN_CHUNK_ITEMS = 16384  # smaller chunks cost more per pixel: NumPy's per-call cost (x1.6 at 7200 px, 2 cores)


def chunk_size(n: int, target: int) -> int:
    """Items per chunk near ``target``, in a multiple of BALANCE chunks, so that the pool's threads finish together
    (7 chunks on 2 threads leave one core idle for the last one), and at least MIN_CHUNKS chunks where each still
    holds MIN_CHUNK_ITEMS (worker processes share a frame's chunks: 16 of them need more than 8 to share). The
    split depends on n and target alone, never on the thread or process count: each chunk draws from its own
    random stream, so the same seed gives the same image on any number of cores."""
    target = max(64, int(target))
    count = max(1, -(-n // target))
    if n >= MIN_CHUNKS * MIN_CHUNK_ITEMS:
        count = max(count, MIN_CHUNKS)
    count = -(-count // BALANCE) * BALANCE
    return max(64, -(-n // count))


def spans(n: int, target: int) -> list[slice]:
    """Chunks of n items (pixels or surfaces) as slices of about ``target`` items (:func:`chunk_size`)."""
    step = chunk_size(n, target)
    return [slice(a, min(n, a + step)) for a in range(0, n, step)]


def run_job(fn):
    """A task running ``fn(*args)`` for a (rows, args) job and returning (rows, result)."""
    return lambda job: (job[0], fn(*job[1]))
