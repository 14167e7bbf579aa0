"""The process-wide thread pool: NumPy and Embree release the GIL inside large calls, so chunks of one stage run
concurrently on it. Work submitted from inside a pool thread runs inline (no nested waits on the pool)."""
from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor

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
        _POOL = ThreadPoolExecutor(max_workers=thread_count(), thread_name_prefix="restir")
    return _POOL
