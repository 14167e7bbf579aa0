"""Shade stage: each chunk's direct light from its reservoirs' samples with shadow rays (RIS/ReSTIR; the world by
its own light sample where the reservoirs do not hold it) or by next-event estimation, and GI's shading of its
reservoirs (one visibility ray each, skipped where the unbiased mode already verified them)."""
from __future__ import annotations

from ..integrators import pathtracer
from ..lights import groups as light_groups
from ..lights.groups import Tap
from ..restir import di, gi
from ..sampling import STREAM_CATCHER, STREAM_SHADE
from .plan import PassPlan
from .shadow_catcher import matte
from .work import Chunk


def shade(ctx, plan: PassPlan, gi_reused: bool, unbiased: bool, c: Chunk, catchers=None) -> None:
    r = plan.rng(STREAM_SHADE, c.index)
    sums = light_groups.zeros(ctx.groups, len(c.hits.surf))  # this stage's light by light group, or None
    taps = () if sums is None else (Tap(sums),)
    if plan.resampled:
        direct = di.shade(ctx, c.hits.surf, c.res, r, sums)
        if ctx.world.sampled and not plan.world_resampled:
            direct = direct + pathtracer.world_event(ctx, c.hits.surf, r, taps=taps)
    else:
        direct = pathtracer.next_event(ctx, c.hits.surf, r, taps=taps)
    c.direct = direct if c.direct is None else c.direct + direct
    if sums is not None:
        c.direct_g = sums if c.direct_g is None else c.direct_g + sums
    if gi_reused:
        # the unbiased mode's reservoirs hold only samples their surface sees (gi.clear_occluded)
        c.indirect = c.indirect + gi.shade(ctx.geom_accel, c.hits.surf, c.gi_res, c.glossy, verified=unbiased,
                                           sums=c.indirect_g)
    if catchers is not None and c.catcher is not None:  # the catchers' light with and without the other objects
        matte(c, c.catcher)
        c.sc_with, c.sc_without = catchers.light_pair(ctx, c.hits.surf.take(c.catcher),
                                                      lambda: plan.rng(STREAM_CATCHER, c.index))
