"""Initial stage of resampled direct light: the pass's light tiles (drawn once for the whole image) and each chunk's
target terms and initial RIS reservoirs (light, BSDF and world candidates; restir/di.py)."""
from __future__ import annotations

import dataclasses

import numpy as np

from ..lights.blocks import BlockLightTiles
from ..lights.tiles import LightTiles
from ..restir import di
from ..restir.target import ShadingTerms
from ..sampling import STREAM_INITIAL, STREAM_TILES
from .plan import PassPlan
from .work import Chunk, own


def with_light_tiles(ctx, plan: PassPlan, chunks: list[Chunk], sampler: str, team) -> di.CandidateSettings:
    """The plan's candidates with this pass's light tiles: per 16x16 block by the blocks' surface positions
    (``sampler`` "SPATIAL", lights/blocks.py; the team's processes write their chunks' positions) or by power
    alone ("POWER", lights/tiles.py)."""
    _x0, _y0, w, h = ctx.scene.camera.window
    r_tiles = plan.rng(STREAM_TILES)
    if sampler == "SPATIAL":
        pos = team.empty((3, w * h), np.float32)
        if plan.partial and team.leader:  # pixels adaptive sampling stopped: no surface this pass
            pos[...] = np.nan
        if plan.partial:
            team.barrier()
        for c in own(chunks, team):
            pos[:, c.pixels[:len(c.pixels) // c.batch]] = np.nan  # a chunk's pixels: its span (batch 1 here)
            pos[:, c.pixels[c.hits.rows]] = c.hits.surf.p
        team.barrier()
        tiles = BlockLightTiles(ctx.lights, pos.reshape(3, h, w), w, h, r_tiles, team=team)
    else:
        tiles = LightTiles(ctx.lights, plan.candidates.tile_settings, w, h, r_tiles)
    return dataclasses.replace(plan.candidates, tiles=tiles)


def initial(ctx, plan: PassPlan, candidates: di.CandidateSettings, terms: np.ndarray, c: Chunk) -> None:
    """Write the chunk's target terms into the frame's ``terms`` (WIDTH, surfaces) and fill ``c.res`` (and
    ``c.bsdf_ray``, the BSDF candidate's traced ray, where the path continuation takes it over)."""
    surf = c.hits.surf
    t = ShadingTerms.of_surfaces(surf, terms[:, c.surfaces])
    _x0, _y0, w, _h = ctx.scene.camera.window
    pix = c.pixels[c.hits.rows]
    c.res, c.bsdf_ray = di.initial_ris(ctx, surf, t, plan.rng(STREAM_INITIAL, c.index), candidates, pix % w,
                                       pix // w, keep_bsdf_ray=plan.continuing)
