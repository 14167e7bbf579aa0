"""How a sample pass runs its stages: tasks on the pool with progress and cancellation, spans of the frame's
surfaces for the whole-image stages, the stage clock."""
from __future__ import annotations

from ..parallel.tasks import Progress, map_tasks, spans
from .plan import PassPlan


class PassRunner:
    """The plan of the pass being rendered, its progress/stop state, the frame's clock and chunk size."""

    def __init__(self, plan: PassPlan, stop: Progress, clock, tile_pixels: int):
        self.plan, self.stop, self.clock, self.tile_pixels = plan, stop, clock, tile_pixels

    def map(self, fn, items) -> list:
        """fn(item) for every item on the pool (raises parallel.tasks.Stopped when asked to stop part-way)."""
        return map_tasks(fn, items, self.stop)

    def spans(self, n: int) -> list[slice]:
        """The frame's n surfaces (or pixels) in chunk-sized slices."""
        return spans(n, self.tile_pixels)

    def stage(self, name: str):
        return self.clock.stage(name)
