"""How many samples a sample pass renders at once.

A pass that keeps no per-pixel state between its stages (no reservoirs, no ReSTIR GI, no measurement) may render
several samples at once: its chunks then hold their pixel span once per sample, so every array of the pass is that
many times longer, and a pass that would be bound by NumPy's per-call cost (few pixels see a surface) fills its
chunks. Whether a pass may batch is the frame renderer's to say (FrameRenderer's ``_can_batch``); how many is
:class:`BatchChoice`'s.
"""
from __future__ import annotations

MAX_BATCH = 8  # samples one pass renders at most
ANY_BATCH = 1 << 30  # samples left when asking for the unbounded choice


class BatchChoice:
    """The batch of a frame's passes: the setting (``sample_batch`` > 0), else as many samples as bring a chunk to
    about ``tile_pixels`` surfaces, judged by the last pass (1 before any pass), at most MAX_BATCH; once the passes
    are independent (:meth:`settle`), the choice after the first such pass for the rest of the frame (or until
    :meth:`unsettle`), so that its later passes are the same whatever renders them."""

    def __init__(self, settings):
        self.settings = settings
        self.surfaces_per_chunk = None  # surfaces per chunk and sample in the last pass
        self.settled = None  # the batch of every later pass, once they are independent

    def measured(self, surfaces: int, chunks: int, batch: int) -> None:
        """The last pass placed ``surfaces`` surfaces in ``chunks`` chunks of ``batch`` samples."""
        self.surfaces_per_chunk = surfaces / (chunks * batch)

    def uncapped(self, remaining: int) -> int:
        """The batch of the next pass (at most ``remaining``) before adaptive sampling cuts it at its next check."""
        st = self.settings
        if self.settled is not None:
            return min(remaining, self.settled)
        if st.sample_batch > 0:
            return max(1, min(remaining, int(st.sample_batch)))
        if self.surfaces_per_chunk is None:
            return 1
        return max(1, min(remaining, MAX_BATCH, int(st.tile_pixels // max(self.surfaces_per_chunk, 1.0))))

    def settle(self, can_batch: bool) -> None:
        """The passes from here on are independent: fix their batch (1 where they cannot batch)."""
        if self.settled is None:
            self.settled = self.uncapped(ANY_BATCH) if can_batch else 1

    def unsettle(self) -> None:
        """What fills the chunks changed (adaptive sampling's check): choose again."""
        self.settled = None
