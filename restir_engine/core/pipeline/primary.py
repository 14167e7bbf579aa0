"""Primary stage: camera rays through a chunk's pixels, the emission seen directly, glass chains; and the frame's
G-buffer assembled from the chunks' primary hits.

The pass's position in a pixel is Sobol point s, digitally shifted per pixel (the shift keyed without the pass).
With pixel coverage (``plan.strata`` > 1) the pixel is split into that many strata: the surface is shaded at the
pass's ray (in whichever stratum it falls), the emission seen directly (and alpha) is averaged over one ray per
stratum, both unbiased estimates of the box-filtered pixel.
"""
from __future__ import annotations

import numpy as np

from ..geometry import camera as camera_mod
from ..integrators import camera_paths
from ..restir.gbuffer import GBuffer
from ..restir.target import ShadingTerms
from ..sampling import STREAM_CAMERA, STREAM_CHAIN, STREAM_LENS, STREAM_PIXEL_OFFSET, cols, pass_jitter
from .plan import PassPlan
from .work import Chunk, own


class CameraMasks:
    """Which camera rays trace what (coverage.py): ``coverage`` (window pixels,) bool or None, the pixels that get
    the coverage rays; ``may_hit`` where a ray may meet geometry; ``lamps`` where it may see a lamp."""

    def __init__(self, coverage_mask, may_hit, lamps):
        self.coverage, self.may_hit, self.lamps = coverage_mask, may_hit, lamps


def primary(ctx, plan: PassPlan, masks: CameraMasks, c: Chunk, catchers=None) -> None:
    """Fill ``c.hits`` (and ``c.chain`` where camera rays continue through glass or coloured transparent surfaces;
    ``c.catcher`` and what the catchers hide where camera rays meet shadow catchers: shadow_catcher.Catchers)."""
    camera_rays(ctx, plan, masks, c)
    if plan.glass_chains and ctx.has_glass:
        # camera rays that met glass continue to the surface behind it, where resampling runs (without
        # resampling, the path continuation handles glass as the path tracer does, at less cost)
        c.chain = camera_paths.follow_specular(ctx, c.hits, plan.rng(STREAM_CHAIN, c.index))
    if c.chain is None and c.hits.tint is not None:  # coloured transparent surfaces in front: a chain of no glass
        c.chain = camera_paths.SpecularChains(c.hits.tint, np.zeros(len(c.hits.rows), np.int64))
        c.hits.tint = None
    if catchers is not None:
        hits = c.hits
        c.catcher = catchers.hits(hits.surf, c.chain)
        pix = hits.rows[c.catcher]  # the matte: black and transparent there (shadow_catcher.py)
        hits.emitted[:, pix] = 0.0
        hits.alpha[pix] = 0.0
        if hits.emitted_g is not None:
            hits.emitted_g[:, :, pix] = 0.0
        c.sc_behind = ctx.world.radiance(-cols(hits.surf.wo, c.catcher), camera=True)


def camera_rays(ctx, plan: PassPlan, masks: CameraMasks, c: Chunk) -> None:
    x0, y0, w, _h = ctx.scene.camera.window
    s = plan.sample
    r = plan.rng(STREAM_CAMERA, c.index)
    span = len(c.pixels) // c.batch
    shift = pixel_shifts(plan, c.pixels[:span])
    j = pass_jitter(shift, s) if c.batch == 1 else np.concatenate([pass_jitter(shift, s + b) for b in range(c.batch)])
    px = (x0 + c.pixels % w).astype(np.float32)
    py = (y0 + c.pixels // w).astype(np.float32)
    land = camera_mod.filter_offsets(ctx.scene.camera)  # uniform in the pixel -> the film filter's offsets
    hit_mask = None if masks.may_hit is None else masks.may_hit[c.pixels]
    lamp_seen = None if masks.lamps is None else masks.lamps[c.pixels]
    lens = plan.rng(STREAM_LENS, c.index) if camera_mod.has_lens(ctx.scene.camera) else None
    lens_uv = None if lens is None else lens.random((2, len(px)), dtype=np.float32)
    c.hits = camera_paths.primary(ctx, px + land(j[:, 0]), py + land(j[:, 1]), hit_mask, lamp_seen, lens_uv)
    strata = plan.strata
    if strata == 1:
        return
    # one more ray in each other stratum than the shaded ray's, in the pixels near an emitter (masks.coverage)
    g = int(round(np.sqrt(strata)))
    sel = slice(None) if masks.coverage is None else np.flatnonzero(masks.coverage[c.pixels])
    jx, jy, sx, sy = j[sel, 0], j[sel, 1], px[sel], py[sel]
    if len(jx) == 0:
        return
    k0 = np.minimum((jx * g).astype(np.int64), g - 1) + g * np.minimum((jy * g).astype(np.int64), g - 1)
    k = (k0[None, :] + np.arange(1, strata)[:, None]) % strata  # (strata - 1, n)
    jj = r.random((2,) + k.shape, dtype=np.float32)
    em, al, em_g = camera_paths.seen_emission(ctx, (sx + land(((k % g).astype(np.float32) + jj[0]) / g)).ravel(),
                                      (sy + land(((k // g).astype(np.float32) + jj[1]) / g)).ravel(),
                                      None if lens is None else lens.random((2, k.size), dtype=np.float32))
    inv = np.float32(1.0 / strata)
    c.hits.emitted[:, sel] = (c.hits.emitted[:, sel] + em.reshape(3, strata - 1, -1).sum(axis=1)) * inv
    c.hits.alpha[sel] = (c.hits.alpha[sel] + al.reshape(strata - 1, -1).sum(axis=0)) * inv
    if em_g is not None:
        gsum = em_g.reshape(len(em_g), 3, strata - 1, -1).sum(axis=2)
        c.hits.emitted_g[:, :, sel] = (c.hits.emitted_g[:, :, sel] + gsum) * inv


def pixel_shifts(plan: PassPlan, pixels: np.ndarray) -> np.ndarray:
    """(n, 2) uint32: the digital shifts of window ``pixels`` (increasing), the same in every pass whatever chunk a
    pixel falls in: drawn per chunk of the frame's whole-window layout (plan.window_step pixels each, in pixel
    order), which a pass of every pixel uses, and looked up from there by a pass of fewer (adaptive sampling)."""
    step = plan.window_step
    assert step > 0, "the plan names its whole-window chunk size"
    first, last = int(pixels[0]) // step, int(pixels[-1]) // step
    if first == last and int(pixels[-1]) - int(pixels[0]) + 1 == len(pixels) and int(pixels[0]) % step == 0:
        raw = plan.rng(STREAM_PIXEL_OFFSET, first, sample=0).bit_generator.random_raw(len(pixels))
        return raw.view(np.uint32).reshape(-1, 2)
    out = np.empty(len(pixels), np.uint64)
    owner = pixels // step
    for u in np.unique(owner):  # the few layout chunks the pixels fall in
        sel = np.flatnonzero(owner == u)
        local = pixels[sel] - int(u) * step
        raw = plan.rng(STREAM_PIXEL_OFFSET, int(u), sample=0).bit_generator.random_raw(int(local[-1]) + 1)
        out[sel] = raw[local]
    return out.view(np.uint32).reshape(-1, 2)


def gbuffer(ctx, chunks: list[Chunk], terms: np.ndarray, team) -> GBuffer:
    """The frame's G-buffer from the chunks' primary hits (surfaces in chunk order) over the target terms
    ``terms`` (WIDTH, surfaces), whose rows 0-2 are the surfaces' positions: each process writes the rows of the
    chunks it owns into the team's buffers (complete after its barrier)."""
    cam = ctx.scene.camera
    _x0, _y0, w, h = cam.window
    n = terms.shape[1]
    pix, depth = team.empty(n, np.int64), team.empty(n, np.float32)
    inst, mat = team.empty(n, np.int32), team.empty(n, np.int32)
    instance = ctx.scene.geometry.instance
    for c in own(chunks, team):
        sl, surf = c.surfaces, c.hits.surf
        depth[sl] = camera_mod.view_depth(cam, terms[0:3, sl])  # along the camera axis (a panorama: distance)
        pix[sl] = c.pixels[c.hits.rows]
        inst[sl] = instance[surf.prim] if instance is not None else 0
        mat[sl] = surf.mat
    team.barrier()
    return GBuffer(pix, w, h, depth, inst, mat, ShadingTerms(terms))
