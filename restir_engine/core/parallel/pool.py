"""The process-wide thread pool: NumPy and Embree release the GIL inside large calls, so chunks of one stage run
concurrently on it. Work submitted from inside a pool thread runs inline (no nested waits on the pool)."""
from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np

_POOL: ThreadPoolExecutor | None = None
_THREADS: int | None = None  # set_thread_count's; None = every logical core


def thread_count() -> int:
    """Threads of the pool: the count set by :func:`set_thread_count`, else every logical core."""
    return max(1, _THREADS if _THREADS else (os.cpu_count() or 1))


def set_thread_count(threads: int | None) -> None:
    """Use ``threads`` threads from the next stage on (None or 0: every logical core, as Blender's Auto). The
    pool is replaced when its size changes; images do not depend on it (parallel/tasks.chunk_size). The old pool
    is left to finish what it was given, not shut down: a viewport worker may still be handing it a stage's
    tasks (its idle threads end with the interpreter)."""
    global _THREADS, _POOL
    _THREADS = int(threads) if threads else None
    if _POOL is not None and _POOL._max_workers != thread_count():
        _POOL = None


def in_worker() -> bool:
    """True inside a pool thread: nested work then runs inline instead of waiting on the pool."""
    return threading.current_thread().name.startswith("restir")


def run_chunks(fn, spans) -> None:
    """Run ``fn(span)`` for every span, on the pool unless already inside a worker."""
    if in_worker() or len(spans) == 1:
        for span in spans:
            fn(span)
    else:
        list(pool().map(fn, spans))


def pool() -> ThreadPoolExecutor:
    """The process-wide worker pool (one thread per core)."""
    global _POOL
    if _POOL is None:
        _POOL = ThreadPoolExecutor(max_workers=thread_count(), thread_name_prefix="restir",
                                   initializer=_quiet_thread)
    return _POOL


QUIET = dict(over="ignore", invalid="ignore", divide="ignore")


def quiet_float_errors():
    """A context in which NumPy's overflow, invalid and divide warnings stay silent: a frame's stages turn
    non-finite values into zeros themselves (sampling.finite, the film), and scenes with extreme values would
    otherwise fill stderr with one line per operation. The pool's threads run so always (NumPy's error state is
    per thread)."""
    return np.errstate(**QUIET)


def _quiet_thread() -> None:
    np.seterr(**QUIET)
