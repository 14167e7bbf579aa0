"""How a sample pass runs its stages: the items this process owns as tasks on its pool with progress and
cancellation, spans of the frame's surfaces for the whole-image stages, the team it renders with, the stage clock."""
from __future__ import annotations

import time

from ..parallel.tasks import Progress, map_tasks, spans
from ..parallel.team import Solo
from .plan import PassPlan
from .work import frame_array, own


class PassRunner:
    """The plan of the pass being rendered, its progress/stop state, the frame's clock and chunk size, and the team
    (parallel/team.py) whose members share the pass's items."""

    def __init__(self, plan: PassPlan, stop: Progress, clock, tile_pixels: int, team=None):
        self.plan, self.stop, self.clock, self.tile_pixels = plan, stop, clock, tile_pixels
        self.team = team or Solo()

    def map(self, fn, items) -> list:
        """fn(item) for every item this process owns (item i: the team's member i mod size) on the pool, in item
        order (raises parallel.tasks.Stopped when asked to stop part-way)."""
        team = self.team
        mine = items if team.size == 1 else [it for i, it in enumerate(items) if team.owns(i)]
        return map_tasks(fn, mine, self.stop)

    def map_chunks(self, fn, chunks, segment: int) -> None:
        """fn(chunk) for every chunk this process owns (the team's assignment), its time recorded under
        ``segment`` (team.SEGMENTS) for the next pass's assignment."""
        team = self.team
        if team.size == 1:
            map_tasks(fn, chunks, self.stop)
            return

        def timed(c):
            t0 = time.perf_counter()
            fn(c)
            team.record(c.index, time.perf_counter() - t0, segment)

        map_tasks(timed, own(chunks, team), self.stop)

    def gather(self, kind, parts, n: int):
        """n reservoirs of ``kind`` from this process's (rows, Reservoirs) parts and every other member's: complete
        once the barrier passed."""
        out = frame_array(kind, n, self.team)
        for rows, part in parts:
            out.assign(rows, part)
        self.team.barrier()
        return out

    def per_span(self, res, make):
        """``make(part)`` of the reservoirs ``res`` as one set of the same kind, where ``make`` works reservoir by
        reservoir: at once alone, or on a team each member its spans into the team's shared buffers (complete once
        the barrier passed), so that no member computes the whole frame's."""
        if self.team.size == 1:
            return make(res)
        out = frame_array(type(res), len(res), self.team)
        self.map(lambda rows: out.assign(rows, make(res.take(rows))), self.spans(len(res)))
        self.team.barrier()
        return out

    def spans(self, n: int) -> list[slice]:
        """The frame's n surfaces (or pixels) in chunk-sized slices."""
        return spans(n, self.tile_pixels)

    def stage(self, name: str):
        return self.clock.stage(name)
