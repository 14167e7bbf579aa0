"""The processes that render one sample pass together, as seen from inside one of them.

A frame's stages run in every member of a team in the same order (SPMD): each member computes the chunks of pixels
(and spans of surfaces) whose index it owns (index modulo the team's size) and writes their rows into whole-image
buffers that every member sees (shared memory); a barrier after each such stage makes the buffers complete before
the next stage reads other pixels. Random streams are keyed by chunk or span index, never by member, so the image is
the same for any team size. A process rendering alone uses :class:`Solo`, whose buffers are ordinary arrays and
whose barrier does nothing.

Buffers come from an :class:`Arena`: every member allocates the same sequence of shapes, so a bump allocator gives
each the same offsets without talking. A pass allocates from one of the slots: the other passes of a frame from the
last slot, the first pass from one of the others that holds no history in use. A first pass's G-buffer and
reservoirs may be kept as a temporal history (:meth:`Team.kept`), read by a later first pass while it fills another
slot; the team holds the newest ``keep`` of them (one per band of a banded frame, else one), so with ``keep`` + 2
slots a first pass always finds a free one, and one that keeps nothing (a still, a pass stopped before it kept its
history) leaves its slot free for the next.
"""
from __future__ import annotations

import threading
import time

import numpy as np

from . import timeline
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

    def owns_chunk(self, index: int) -> bool:
        return True

    def record(self, index: int, seconds: float, segment: int = 0) -> None:
        pass

    def publish_costs(self) -> None:
        pass

    def barrier(self) -> None:
        pass

    def commit(self) -> None:
        """The pass is rendered: from here on it adds to the film whole (nothing to wait for alone)."""

    def in_order(self, add):
        """``add(chunk)`` as the film's accumulation calls it (alone: as it is)."""
        return add

    def empty(self, shape, dtype) -> np.ndarray:
        return np.empty(shape, dtype)

    def begin_pass(self, first: bool, chunks: int = 0) -> None:
        pass

    def kept(self) -> None:
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


def film_zeros(segment, dtype):
    """zeros(shape) of a film (pipeline/film.Film) over a zero-filled shared segment: ``dtype`` arrays in the order
    asked, so the rendering process and every worker see the same accumulators."""
    arena = Arena(segment.buf, segment.name)
    return lambda shape: arena.empty(shape, dtype)


class Team:
    """Member ``rank`` of ``size`` processes rendering a pass together. ``barrier`` is a multiprocessing.Barrier of
    ``size`` parties; ``slots`` three Arenas over the team's shared segments (see the module docstring); ``costs``
    a shared float64 array (the chunks' measured seconds, for the assignment); ``stop`` a shared flag (a ctypes
    value) set by the process that drives the team when the pass is to stop.

    Spans of surfaces (the reuse stages) go round-robin: span i to member i mod size. Chunks of pixels go by their
    costs in the last pass that measured them (:func:`assign`), round-robin before any measurement: every member
    reads the same costs, so all agree on the assignment, and who computes a chunk never changes its result."""

    def __init__(self, rank: int, size: int, barrier, slots: list[Arena], stop, costs: np.ndarray | None = None):
        self.rank, self.size = int(rank), int(size)
        self.leader = self.rank == 0
        self._barrier, self.slots, self.stop = barrier, slots, stop
        self.keep = max(1, len(slots) - 2)  # histories held at most (the worker sets it per frame)
        self._held: list[int] = []  # the slots holding the kept histories, oldest first
        self._first_slot = 0  # the slot of the last first pass
        self.arena = slots[-1]
        self._lock = threading.Lock()
        self.costs = costs  # [0]: the chunk count n they were measured for; [1 + s * n + i]: chunk i's seconds
        #                     in segment s (the stages between two barriers: SEGMENTS)
        self.chunk_owner = np.zeros(0, np.int64)
        self._spent: dict = {}

    def owns(self, index: int) -> bool:
        return index % self.size == self.rank

    def owns_chunk(self, index: int) -> bool:
        return self.chunk_owner[index] == self.rank

    def stopping(self) -> bool:
        return bool(self.stop.value)

    def barrier(self) -> None:
        """Wait until every member arrives; a stop request (or a member that stopped) raises Stopped in all."""
        if timeline.FOLDER is not None:
            timeline.mark("arrive", timeline.caller(1))
        try:
            self._barrier.wait()
        except threading.BrokenBarrierError:
            raise Stopped from None
        if timeline.FOLDER is not None:
            timeline.mark("leave")

    def abort(self) -> None:
        """Release every member waiting at (or arriving at) the barrier with Stopped."""
        self._barrier.abort()

    def commit(self) -> None:
        """The pass is rendered: every member shaded its chunks (a barrier), so the film takes all of the pass."""
        self.barrier()

    def in_order(self, add):
        """``add(chunk)`` as the film's accumulation calls it: the members add disjoint chunks of the same pass."""
        return add

    def begin_pass(self, first: bool, chunks: int = 0) -> None:
        """Allocate the coming pass's buffers from the next first-pass slot (``first``) or from the slot of the
        other passes, and assign its ``chunks`` chunks."""
        if first:
            free = [i for i in range(len(self.slots) - 1) if i not in self._held]
            if not free:
                raise ArenaFull(f"all {len(self.slots) - 1} first-pass slots hold a history in use")
            self._first_slot = free[0]
            self.arena = self.slots[self._first_slot]
        else:
            self.arena = self.slots[-1]
        self.arena.reset()
        self.chunk_owner = assign(chunks, self.size, self._measured(chunks))
        self._spent = {}

    def kept(self) -> None:
        """The first pass's buffers are now a temporal history, held until ``keep`` newer ones are kept."""
        self._held = [i for i in self._held if i != self._first_slot] + [self._first_slot]
        del self._held[:-max(1, self.keep)]

    def _measured(self, chunks: int):
        c = self.costs
        if c is None or SEGMENTS * chunks + 1 > len(c) or int(c[0]) != chunks:
            return None
        cost = np.array(c[1:SEGMENTS * chunks + 1]).reshape(SEGMENTS, chunks)
        return cost if (cost.sum(axis=0) > 0).all() else None

    def record(self, index: int, seconds: float, segment: int = 0) -> None:
        """Time spent on chunk ``index`` in this pass by the stages of ``segment`` (0 <= segment < SEGMENTS)."""
        with self._lock:
            key = (segment, index)
            self._spent[key] = self._spent.get(key, 0.0) + seconds

    def publish_costs(self) -> None:
        """Write this member's chunk costs for the next pass's assignment (before the pass's last barrier, so that
        every member reads them complete)."""
        c, n = self.costs, len(self.chunk_owner)
        if c is None or SEGMENTS * n + 1 > len(c):
            return
        for i in np.flatnonzero(self.chunk_owner == self.rank):
            for seg in range(SEGMENTS):
                c[1 + seg * n + i] = self._spent.get((seg, int(i)), 0.0)
        if self.leader:
            c[0] = n

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


SEGMENTS = 3  # stages of a chunk between barriers: primary | initial and paths | shade


def assign(chunks: int, size: int, cost: np.ndarray | None) -> np.ndarray:
    """The member of each chunk: round-robin without costs; else, as LPT scheduling over several resources, the
    chunks by decreasing total cost, each to the member whose busiest segment (load relative to that segment's
    fair share) grows least, since the members wait for each other at the barrier after each segment. ``cost``:
    (SEGMENTS, chunks) seconds. Ties go to the lower chunk index first and to the lower rank."""
    if cost is None or size == 1:
        return np.arange(chunks, dtype=np.int64) % max(1, size)
    share = cost.sum(axis=1) / size
    scale = np.where(share > 0, 1.0 / np.maximum(share, 1e-300), 0.0)[None, :]  # (1, SEGMENTS)
    owner = np.empty(chunks, np.int64)
    load = np.zeros((size, cost.shape[0]), np.float64)
    for i in np.argsort(-cost.sum(axis=0), kind="stable"):  # chunks (tens to a few thousand), not pixels
        m = int(np.argmin(((load + cost[:, i][None, :]) * scale).max(axis=1)))
        owner[i] = m
        load[m] += cost[:, i]
    return owner


WAIT_SECONDS = 0.0005  # how often a pass waiting for its turn at the film looks again
FAILED = 2  # the stop flag's value when a member failed (1: a stop request)


class Independent(Solo):
    """A process rendering a whole sample pass alone while other processes of its team render other passes of the
    same frame (passes that no earlier pass changes: pipeline/spread.py). Its buffers are private arrays. Its pass is
    the ``ordinal``-th of those rendered at once (0 first), and adds to the shared film only after the ones before
    it, so every pixel's sum is added in sample order, as one process adds it (the same image, bit for bit).

    ``order``: a shared int64 array behind ``lock`` (a multiprocessing lock, whose acquire and release also order
    the film's memory between processes): [0] the passes committed so far, [1 + i] the passes the film's chunk i
    holds. A pass commits (:meth:`commit`) once every earlier pass has committed, unless a stop request (``stop``, a
    shared flag) comes first, so the committed passes are always the first ones and each adds all of its chunks;
    then each chunk is added once the earlier passes added theirs (:meth:`in_order`). A member that fails sets
    ``stop`` to FAILED, which ends every wait."""

    def __init__(self, ordinal: int, order: np.ndarray, lock, stop):
        self.ordinal, self.order, self.lock, self.stop = int(ordinal), order, lock, stop

    def _wait(self, index: int, stoppable: bool) -> None:
        """Until ``order[index]`` counts this pass's ordinal; then (``index`` 0) count it in. A stop request while
        ``stoppable`` raises Stopped."""
        while True:
            with self.lock:
                if self.order[index] == self.ordinal:
                    if index == 0:
                        self.order[0] = self.ordinal + 1
                    return
            if self.stop.value == FAILED or (stoppable and self.stop.value):
                raise Stopped  # a member failed: the frame is lost, nothing waits for its turn
            time.sleep(WAIT_SECONDS)

    def commit(self) -> None:
        self._wait(0, stoppable=True)

    def in_order(self, add):
        def in_turn(chunk):
            self._wait(1 + chunk.index, stoppable=False)
            add(chunk)
            with self.lock:
                self.order[1 + chunk.index] = self.ordinal + 1
        return in_turn
