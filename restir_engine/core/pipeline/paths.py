"""Paths stage: the first vertex's BSDF ray and bounces 1..max_bounces (integrators/pathtracer.continue_paths).

It needs no reservoir, so it runs before reuse, and the BSDF candidate's ray it takes over is freed early. Where GI
runs (or Auto measures), the first bounces become GI's initial reservoirs, and the chunk keeps the path-traced
indirect light too, for a pass that finds GI carries too little of it.
"""
from __future__ import annotations

import numpy as np

from ..integrators import pathtracer
from ..restir import gi
from ..restir.target import ShadingTerms
from ..sampling import STREAM_PATH
from ..integrators.method_choice import GI_MIN_SHARE
from .indirect_choice import PROBE_EVERY, ratios, share_sums
from .plan import PassPlan
from .work import Chunk, own


def gi_initial(settings: gi.GISettings, space, surf, first, block: np.ndarray, filled: bool = False):
    """ReSTIR GI's initial reservoirs at surfaces ``surf`` from their first bounces (pathtracer.FirstBounce):
    (glossy x1 (n,) bool, gi.GIReservoirs, the path-traced indirect light they do not carry (3, n), and that by
    light group (G, 3, n) or None). ``block`` (WIDTH, n) receives the GI target terms (already holding the surfaces'
    target terms when ``filled``)."""
    if not filled:
        ShadingTerms.of_surfaces(surf, block)
    glossy = gi.glossy_x1(surf.params, settings.roughness_threshold)
    res, rest, rest_g = gi.initial(first, gi.diffuse_only(ShadingTerms(block), glossy), len(surf), glossy, space)
    return glossy, res, rest, rest_g


def paths(ctx, plan: PassPlan, terms, gi_terms, make_gi, c: Chunk) -> None:
    """Fill ``c.direct`` / ``c.indirect`` (None when nothing continues); where the chunk measures or GI runs, its
    GI reservoirs and target terms (``gi_terms``, copied from ``terms`` where DI filled them), ``c.glossy``,
    ``c.gi_share`` and the path-traced indirect light in ``c.path_indirect``. ``make_gi(surf, first, block,
    filled)`` is :func:`gi_initial` bound to the frame's GI settings."""
    if not plan.continuing:
        c.direct, c.indirect = None, None
        c.direct_g = c.indirect_g = None
        return
    out = pathtracer.continue_paths(
        ctx, c.hits.surf, plan.rng(STREAM_PATH, c.index), direct_resampled=plan.resampled, first_ray=c.bsdf_ray,
        first_bounce=plan.gi or (plan.probe and c.index % PROBE_EVERY == 0),
        budget=None if c.chain is None else ctx.max_bounces - c.chain.depth, world_resampled=plan.world_resampled)
    c.bsdf_ray = None
    c.direct, c.indirect = out.direct, out.indirect
    c.direct_g, c.indirect_g = out.direct_g, out.indirect_g
    if out.first is not None:  # the first bounces: GI's initial samples (and the Auto measurement)
        block = gi_terms[:, c.surfaces]
        if plan.resampled:
            block[:] = terms[:, c.surfaces]
        c.path_indirect, c.path_indirect_g = c.indirect, c.indirect_g
        c.glossy, c.gi_res, c.indirect, rest_g = make_gi(c.hits.surf, out.first, block, filled=plan.resampled)
        if rest_g is not None:
            c.indirect_g = rest_g
        out.add_walked_indirect(c.indirect, c.indirect_g)  # the subsurface walks' light is not GI's to carry
        c.gi_share = share_sums(c.path_indirect, c.indirect)


def keep_path_traced(chunks: list[Chunk]) -> None:
    """A pass that does not reuse GI: each chunk's indirect light is the path-traced one again, no GI reservoirs."""
    for c in chunks:
        if c.path_indirect is not None:
            c.indirect, c.indirect_g, c.gi_res = c.path_indirect, c.path_indirect_g, None


def gi_outcome(plan: PassPlan, chunks, team, reuse_stats: dict, measured=None) -> bool:
    """After the paths stage: whether this pass reuses GI. GI reuse only pays where its reservoirs carry the indirect
    light: a scene with no bounce light to cache (the default cube) keeps the path-traced indirect light as it is
    (GI_MIN_SHARE); with Auto, ``measured(sums)`` takes the measurement for the next passes instead. The share
    measured goes into ``reuse_stats``; the chunks' path-traced indirect light is dropped (or kept as their
    indirect light where GI does not run)."""
    gi_on = plan.gi
    if not (plan.gi or plan.probe):
        return gi_on
    sums = team.table({c.index: c.gi_share for c in own(chunks, team)}, len(chunks), 4).sum(axis=0)
    share, uncached = ratios(sums)
    reuse_stats["gi_share"], reuse_stats["gi_uncached"] = share, uncached
    if measured is not None:
        measured(sums)  # for the next passes
    elif share < GI_MIN_SHARE:
        gi_on = False
    if not gi_on:
        keep_path_traced(own(chunks, team))
    for c in chunks:
        c.path_indirect = c.path_indirect_g = None
    return gi_on
