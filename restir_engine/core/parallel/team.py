"""The processes that render one sample pass together, as seen from inside one of them.

A frame's stages run in every member of a team in the same order (SPMD): each member computes the chunks of pixels
(and spans of surfaces) whose index it owns (index modulo the team's size) and writes their rows into whole-image
buffers that every member sees (shared memory); a barrier after each such stage makes the buffers complete before
the next stage reads other pixels. Random streams are keyed by chunk or span index, never by member, so the image is
the same for any team size. A process rendering alone uses :class:`Solo`, whose buffers are ordinary arrays and
whose barrier does nothing.

Buffers come from an :class:`Arena`: every member allocates the same sequence of shapes, so a bump allocator gives
each the same offsets without talking. A pass allocates from one of three slots: the first pass of a frame from slot
0 or 1 by turns (its G-buffer and reservoirs are the next frame's history, read while that frame's first pass
fills the other slot), the other passes from slot 2.
"""
from __future__ import annotations

import threading

import numpy as np

from .tasks import Stopped

ALIGN = 64  # bytes: each buffer starts on a cache line


class ArenaFull(MemoryError):
    """A pass needs more shared memory than its slot holds."""


class Solo:
    """A process rendering alone: it owns every item; buffers are private arrays."""

    rank, size = 0, 1
    leader = True

    def owns(self, index: int) -> bool:
        return True

    def barrier(self) -> None:
        pass

    def empty(self, shape, dtype) -> np.ndarray:
        return np.empty(shape, dtype)

    def begin_pass(self, first: bool) -> None:
        pass

    def table(self, rows: dict, n: int, k: int) -> np.ndarray:
        """(n, k) float64 from ``rows`` (item index -> k values) of every item."""
        out = np.zeros((n, k), np.float64)
        for i, v in rows.items():
            out[i] = v
        return out


class Arena:
    """A bump allocator over one writable buffer (a shared-memory segment's): offsets depend only on the sequence
    of allocations since the last :meth:`reset`."""

    def __init__(self, buffer, name: str = ""):
        self.buffer, self.name = buffer, name
        self.capacity = len(buffer)
        self.offset = 0
        self.high = 0  # the most bytes in use since creation

    def reset(self) -> None:
        self.offset = 0

    def empty(self, shape, dtype) -> np.ndarray:
        dtype = np.dtype(dtype)
        shape = (int(shape),) if np.isscalar(shape) else tuple(int(s) for s in shape)
        count = int(np.prod(shape, dtype=np.int64))
        start = -(-self.offset // ALIGN) * ALIGN
        end = start + count * dtype.itemsize
        if end > self.capacity:
            raise ArenaFull(f"shared buffer {self.name!r} of {self.capacity} bytes cannot hold {end} bytes")
        self.offset = end
        self.high = max(self.high, end)
        return np.frombuffer(self.buffer, dtype, count, start).reshape(shape)


class Team:
    """Member ``rank`` of ``size`` processes rendering a pass together. ``barrier`` is a multiprocessing.Barrier of
    ``size`` parties; ``slots`` three Arenas over the team's shared segments (see the module docstring); ``stop`` a
    shared flag (a ctypes value) set by the process that drives the team when the pass is to stop."""

    def __init__(self, rank: int, size: int, barrier, slots: list[Arena], stop):
        self.rank, self.size = int(rank), int(size)
        self.leader = self.rank == 0
        self._barrier, self.slots, self.stop = barrier, slots, stop
        self._turn = 0
        self.arena = slots[2]
        self._lock = threading.Lock()

    def owns(self, index: int) -> bool:
        return index % self.size == self.rank

    def stopping(self) -> bool:
        return bool(self.stop.value)

    def barrier(self) -> None:
        """Wait until every member arrives; a stop request (or a member that stopped) raises Stopped in all."""
        try:
            self._barrier.wait()
        except threading.BrokenBarrierError:
            raise Stopped from None

    def abort(self) -> None:
        """Release every member waiting at (or arriving at) the barrier with Stopped."""
        self._barrier.abort()

    def begin_pass(self, first: bool) -> None:
        """Allocate the coming pass's buffers from the next first-pass slot (``first``) or from the slot of the
        other passes."""
        if first:
            self.arena = self.slots[self._turn]
            self._turn = 1 - self._turn
        else:
            self.arena = self.slots[2]
        self.arena.reset()

    def empty(self, shape, dtype) -> np.ndarray:
        with self._lock:
            return self.arena.empty(shape, dtype)

    def table(self, rows: dict, n: int, k: int) -> np.ndarray:
        """(n, k) float64 of every item once each member wrote its own ``rows`` (item index -> k values)."""
        out = self.empty((n, k), np.float64)
        for i, v in rows.items():
            out[i] = v
        self.barrier()
        return out
