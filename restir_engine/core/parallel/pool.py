"""The process-wide thread pool: NumPy and Embree release the GIL inside large calls, so chunks of one stage run
concurrently on it. Work submitted from inside a pool thread runs inline (no nested waits on the pool)."""
from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor

import numpy as np

_POOL: ThreadPoolExecutor | None = None


def thread_count() -> int:
    return max(1, os.cpu_count() or 1)


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
