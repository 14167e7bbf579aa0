"""Independent sample passes of a frame rendered at the same time on a team of worker processes, one whole pass per
worker, instead of every worker taking a share of each pass.

Once the first pass has chosen the frame's methods, a still's later passes change nothing for each other
(FrameRenderer.passes_independent): each can be rendered by one worker alone, with no barrier between its stages and
none of the per-pass work that the members of a team each repeat. The film still receives every pixel's samples in
sample order (parallel/team.Independent), so the image is the one a single process renders, bit for bit. What it
costs: each worker holds a whole pass's working set, and a round of passes takes as long as one pass on one worker,
so a round that leaves workers idle can be slower than sharing its passes out.
"""
from __future__ import annotations

import dataclasses

from ..modes import DirectMethod, IndirectMethod, Integrator
from . import memory

FILL = 0.75  # a last, partial round of passes is rendered one per worker only where it keeps this share busy
MEMORY_SHARE = 0.75  # of the memory available, the share the workers' own pass working sets may take


def samples_at_once(left: int, done: int, batch: int, until: int | None) -> int:
    """Of the ``left`` samples after the ``done`` ones, those whose passes (``batch`` samples each) may render at
    once: all of them, or with adaptive sampling's next check after sample ``until``, the whole passes that end
    before the pass that reaches it (that one renders with the check, its batch cut to end there)."""
    if until is None:
        return int(left)
    return max(0, min(int(left), (int(until) - 1 - int(done)) // max(1, int(batch)) * int(batch)))


def passes_at_once(left: int, batch: int, workers: int) -> int:
    """How many of the passes that render the ``left`` samples (``batch`` each, the last one fewer) to render at
    once, one per worker in turn: whole rounds of ``workers`` passes, and a last partial round where it fills at
    least FILL of the workers (the rest are shared out pass by pass); 0 where that leaves fewer than two."""
    passes = -(-int(left) // max(1, int(batch)))
    rounds, rest = divmod(passes, max(1, int(workers)))
    count = rounds * workers + (rest if rest >= FILL * workers else 0)
    return count if count >= 2 else 0


def working_set(scene, settings, method: str, gi_runs: bool) -> int:
    """Bytes one worker holds while it renders a whole pass of ``scene``'s camera window alone, with the direct
    ``method`` and (``gi_runs``) ReSTIR GI that the frame's first pass chose (pipeline/memory.py's per-pixel
    figures; a still keeps no history)."""
    st = settings
    if st.integrator == Integrator.RESTIR:
        direct = method if method in DirectMethod.__members__ else DirectMethod.LIGHT_SAMPLING
        st = dataclasses.replace(st, direct_method=DirectMethod(direct),
                                 indirect_method=IndirectMethod.RESTIR_GI if gi_runs else IndirectMethod.PATH)
    low, _high = memory.per_pixel_range(st, False, memory.target_extension_rows(scene))
    _x0, _y0, w, h = scene.camera.window
    return low * int(w) * int(h)


def fits(scene, settings, method: str, gi_runs: bool, workers: int, free: int | None) -> bool:
    """Whether ``workers`` whole-pass working sets (:func:`working_set`) fit in MEMORY_SHARE of ``free`` bytes
    (None: unknown, taken to fit)."""
    if free is None:
        return True
    return workers * working_set(scene, settings, method, gi_runs) <= MEMORY_SHARE * free
