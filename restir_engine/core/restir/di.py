"""ReSTIR DI: reservoirs over light points, initial resampling and shading.

Initial resampling (streaming RIS, Talbot et al. 2005; Bitterli et al. 2020 §3-4) combines candidates of two
strategies by the balance heuristic:
  light candidates: ``light_candidates`` points from the power alias table over surface lights (through
                    light tiles when they pay), pdf p_l = p_select / A (area measure); with the spatial light
                    sampler from the pixel's block tile (light_blocks.py), p_l = q_block(light) / A
  BSDF candidates:  ``bsdf_candidates`` BSDF-sampled rays; a ray yields the first emissive surface and the
                    first lamp along it, occluders ignored (each generated with p_b, so the technique's density
                    is p_b at every light point, as the MIS weights assume), a ray that meets none is a null
                    candidate (it still counts in M_b, never re-drawn); with the world in the reservoirs every
                    ray also yields the world's point in its direction
  world candidates: ``world_candidates`` points of the world (world_points.py: the world on a far sphere, so its
                    samples are area-measure points too) drawn by the world's own distribution, pdf p_e (area)
Everything is in AREA measure on the lights, so a sample (a point on a light) and its weight W mean the same
at every pixel and are reused across pixels without a Jacobian:
  target p̂(y) = luminance(f(ωo, ωi) · Le(y)) · G(x, y), G = |cos θ_s| |cos θ_l| / d²  (target.py)
  BSDF pdf in area measure p_b(y) = p_b,ω · |cos θ_l| / d²
Resampling weight of candidate y: w = p̂(y) / (M_l p_l(y) + M_e p_e(y) + M_b p_b(y)) (p_l = 0 on the world,
p_e = 0 on lights); W = Σw / p̂(y_selected) (m²).
Shading traces one shadow ray: L_direct = f · Le · G · V · W. Suns are not resampled: one light-sampled sun
per pixel is added; with ``world_candidates`` 0 the world is light-sampled at the shaded point
(pathtracer.world_event) instead of resampled.

Reservoir memory per pixel: light index (int32), barycentrics b1, b2, M, W, p̂ (float32) = 24 bytes.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.accel import shadow_rays
from ..integrators.pathtracer import sample_rays
from ..integrators.ray_emission import lamp_hits
from ..lights import groups as light_groups
from ..lights.tiles import PackedPoints, TileSettings, light_points, sample_points
from ..materials.bsdf import eval_view, view_terms
from ..materials.params import luminance_rows
from ..modes import DirectMethod, values
from ..sampling import cols, dot, finite, to_local, uniform_ints, vmax
from .reservoir import Reservoirs, Stream
from .target import FramePoints, with_spots

DIRECT_METHODS = values(DirectMethod)  # AUTO: core/integrators/method_choice.py
CANDIDATE_BLOCK = 65536  # candidate x surface elements evaluated per pass over memory (256 kB per float32 array)


class DIReservoirs(Reservoirs):
    """light int32 (-1 = empty), barycentrics b1, b2 of the point on that triangle light; M, W (m²), p̂."""

    SAMPLE = {"light": np.int32, "b1": np.float32, "b2": np.float32}


@dataclass
class CandidateSettings:
    """Initial resampling: method (DIRECT_METHODS), candidates per strategy, light tiles (settings, and the
    sample pass's light_tiles.LightTiles or None)."""

    method: str = "RESTIR"
    light_candidates: int = 32
    bsdf_candidates: int = 1
    tile_settings: TileSettings = None
    tiles: object = None
    world_candidates: int = 1  # > 0: the world's points enter the reservoirs (world_points.py), drawn this many
    #                            times per surface by the world's own distribution; 0: the world is light-sampled
    #                            at the shaded surface instead (pathtracer.world_event)

    def world_resampled(self, lights) -> bool:
        """Whether the reservoirs hold the world's points (a sampled world is attached to ``lights``)."""
        return self.world_candidates > 0 and lights.env is not None


class LightSpace:
    """DI samples for the generic reuse code (reuse.py): light points, target p̂ of target.py."""

    kind = DIReservoirs

    def __init__(self, lights):
        self.lights = lights

    def prepare(self, res: DIReservoirs, spans=None, team=None) -> FramePoints:
        """The reservoirs' light points (by ``team``'s processes, span by span, where given)."""
        if team is not None and team.size > 1:
            return FramePoints.shared(self.lights, res.light, res.b1, res.b2, spans, team)
        return FramePoints(self.lights, res.light, res.b1, res.b2)

    @staticmethod
    def gather(prepared: FramePoints, idx):
        """The samples ``idx`` of ``prepared``, to be evaluated at any surfaces (spot cones applied then)."""
        return prepared.points(idx), (None if prepared.spot_tri is None else prepared.spot_tri[idx])

    def evaluate(self, terms, gathered) -> np.ndarray:
        """p̂ (n,) of gathered samples at surfaces ``terms``."""
        pts, spot_tri = gathered
        if spot_tri is not None:
            pts = with_spots(pts, spot_tri, self.lights.scene.lamps, terms.p)
        return terms.evaluate(pts, want_pdf=False)[0]


def _light_candidates(ctx, terms, rng, tiles, m_l: int, m_b: int, px, py):
    """Weights and targets (m_l, n) of the light candidates (from ``tiles`` or the power table), the light
    points they index and the index of each candidate."""
    n = len(terms)
    lights = ctx.lights
    if tiles is not None:
        points, block = tiles.points, tiles.rows
        pick = uniform_ints(rng, tiles.size, (m_l, n))
        pick += tiles.tile_base(px, py)[None, :]
    else:
        points = sample_points(lights, rng.random((m_l * n, 4), dtype=np.float32))
        block = points.packed()
        pick = np.arange(m_l * n).reshape(m_l, n)
    spot_tri = points.spot_tri if points.has_spots else None
    w = np.empty((m_l, n), np.float32)
    p_hats = np.empty((m_l, n), np.float32)
    group = max(1, CANDIDATE_BLOCK // max(n, 1))
    for k0 in range(0, m_l, group):
        k1 = min(m_l, k0 + group)
        idx = pick[k0:k1]
        pts = PackedPoints.of(np.take(block, idx, axis=1))
        if spot_tri is not None:  # spot cones need the lamp of each candidate and the receiver
            pts = with_spots(pts, spot_tri[idx], ctx.scene.lamps, terms.p[:, None, :])
        p_hat, p_b = terms.evaluate(pts, want_pdf=m_b > 0)
        den = m_l * pts.pdf if p_b is None else m_l * pts.pdf + m_b * p_b
        np.maximum(den, np.float32(1e-30), out=den)
        wk = np.divide(p_hat, den, out=den)
        if not np.isfinite(wk).all():  # a light point on the surface itself: p̂ overflows
            wk[~np.isfinite(wk)] = 0.0
        w[k0:k1] = wk
        p_hats[k0:k1] = p_hat
    return w, p_hats, points, pick


def initial_ris(ctx, surf, terms, rng: np.random.Generator, cfg: CandidateSettings, px=None, py=None,
                keep_bsdf_ray: bool = False):
    """One reservoir per surface (n) from M_l light and M_b BSDF candidates (see module docstring).

    ``terms``: target.ShadingTerms of the surfaces; ``px``, ``py``: their window pixels (pick the light tile).
    All light candidates are weighed first and one is selected per surface in proportion to its weight (the
    same distribution as streaming them one at a time). Returns (DIReservoirs, pathtracer.BsdfRay or None): the
    first BSDF candidate's traced ray when ``keep_bsdf_ray`` (the path's first bounce: the same distribution
    as a fresh BSDF sample)."""
    n = len(surf)
    lights = ctx.lights
    m_l = cfg.light_candidates if lights.tri_alias is not None else 0
    env = lights.env if cfg.world_resampled(lights) else None
    m_e = cfg.world_candidates if env is not None else 0
    m_b = cfg.bsdf_candidates if lights.n_tri or m_e else 0
    stream = Stream(DIReservoirs, n, rng)
    res = stream.res
    tiles = cfg.tiles if px is not None else None
    if m_l and n:
        w, p_hats, points, pick = _light_candidates(ctx, terms, rng, tiles, m_l, m_b, px, py)
        # select candidate k with probability w_k / Σw: the number of prefix sums at or below u·Σw
        total = w.sum(axis=0)
        target = rng.random(n, dtype=np.float32) * total
        cum = np.zeros(n, np.float32)
        k_sel = np.zeros(n, np.int64)
        for k in range(m_l - 1):  # a loop over candidates (not pixels): np.cumsum over axis 0 is 3x slower
            cum += w[k]
            k_sel += cum <= target
        take = np.flatnonzero(total > 0)
        flat = pick[k_sel[take], take]
        res.light[take] = points.light[flat]
        res.b1[take] = points.b1[flat]
        res.b2[take] = points.b2[flat]
        res.p_hat[take] = p_hats[k_sel[take], take]
        stream.w_sum[:] = total
    for _ in range(m_e if n else 0):  # world candidates: directions from the world's distribution at the surface
        u = rng.random((2, n), dtype=np.float32)
        b1, b2 = env.sample(surf.p, (surf.ns, surf.t, surf.bt), u[0], u[1])
        cand = DIReservoirs(light=np.full(n, lights.env_index, np.int32), b1=b1, b2=b2, M=None, W=None, p_hat=None)
        lp = light_points(lights, cand.light, b1, b2)
        p_hat, pb = terms.evaluate(PackedPoints.of(lp.packed()), want_pdf=m_b > 0)
        den = m_e * env.pdf_area(surf.p, surf.ns, lp.pos)
        if pb is not None:
            den += m_b * pb
        stream.add(p_hat / np.maximum(den, np.float32(1e-30)), p_hat, cand)
    first_ray = None
    lamps = ctx.scene.lamps
    for j in range(max(m_b, 1 if keep_bsdf_ray else 0)):
        ray = sample_rays(surf, rng.random((3, n), dtype=np.float32))
        live, o, d = ray.rows, ray.o, ray.d
        if j == 0 and keep_bsdf_ray:  # the path's first bounce: its geometry hit
            ray.hits = ctx.geom_accel.intersect(o, d)
            first_ray = ray
        if j >= m_b or live.size == 0:
            continue
        # the emitters along the ray whatever occludes them (the first emissive triangle, every lamp the ray
        # crosses first): the BSDF technique's density of a light point is then p_b wherever the MIS weights use
        # it. Only emitter hits would give it density 0 behind an occluder, and a sample reused from a pixel that
        # sees its light occluded to one that sees it would be underweighted (a floor seen through slats under a
        # large emitter read 6.5 % dark: tests/restir/test_restir_stability.py). Shading tests visibility.
        candidates = []
        if ctx.emit_accel is not None:
            eh = ctx.emit_accel.intersect(o, d)
            candidates.append((eh.prim, eh.u, eh.v, False))
        if m_e:
            # every ray yields the world's point in its direction, occluded or not: the BSDF technique's density of
            # world points is then p_b everywhere, as the MIS weights assume. (Taking only the rays that escape
            # would give it density 0 behind geometry: a sample reused from a pixel that sees it occluded to one
            # that sees it would be underweighted, 1.5 % dark in tests/core/test_world_light.py.) Shading tests
            # visibility as for any light point.
            eb1, eb2 = env.exit_coords(o, d)
            candidates.append((np.full(len(live), lights.env_index), eb1, eb2, True))
        if len(lamps.tris):
            lh = lamp_hits(ctx, o, d, np.full(len(live), np.inf, np.float32))
            lamp_ok = lh.prim >= 0
            candidates.append((np.where(lamp_ok, lights.lamp_to_light[np.maximum(lh.prim, 0)], -1), lh.u, lh.v,
                               False))
        for light, cu, cv, world in candidates:
            sel = np.flatnonzero(light >= 0)
            if sel.size == 0:
                continue
            r = live[sel]
            lp = light_points(lights, light[sel], cu[sel], cv[sel])
            here = terms.take(r)
            pts = PackedPoints.of(lp.packed())
            if lp.has_spots:
                pts = with_spots(pts, lp.spot_tri, lamps, here.p)
            p_hat, pb = here.evaluate(pts)
            if world:  # the world candidates' pdf of the point
                other = m_e * env.pdf_area(here.p, here.ns, lp.pos)
            else:  # the light candidates' pdf of this point at this pixel (tiles: per block, or the power table's)
                other = m_l * (pts.pdf if tiles is None else tiles.pdf_area(lp.light, px[r], py[r]))
            cand = DIReservoirs(light=lp.light, b1=lp.b1, b2=lp.b2, M=None, W=None, p_hat=None)
            stream.add(p_hat / np.maximum(other + m_b * pb, 1e-30), p_hat, cand, rows=r)
    return stream.finish(1.0), first_ray


def shading_value(surf, wi: np.ndarray, le: np.ndarray, dist: np.ndarray, cos_l: np.ndarray):
    """Target p̂ (n,), f (3, n), geometry term G (n,) and the BSDF pdf in area measure (n,) of light points
    in directions wi (3, n) (world) at distances dist (the exact RGB model of bsdf.py)."""
    wi_l = to_local(wi, surf.ns, surf.t, surf.bt)
    f, pdf_b = eval_view(view_terms(surf), surf.wo_l, wi_l)
    ok = (dot(wi, surf.ng) > 0) & (dist > 0)
    to_area = np.abs(cos_l) / np.maximum(dist * dist, 1e-30)
    g = np.abs(wi_l[2]) * to_area
    p_hat = (luminance_rows(f * le) * g * ok).astype(np.float32, copy=False)
    return p_hat, f, np.where(ok, g, 0.0).astype(np.float32), np.where(ok, pdf_b * to_area, 0.0).astype(np.float32)


def shade(ctx, surf, res: DIReservoirs, rng: np.random.Generator, sums=None) -> np.ndarray:
    """Direct radiance (3, n) at the surfaces: each reservoir's sample with one shadow ray, plus one
    light-sampled sun; with light groups also added to ``sums`` (G, 3, n) by the group of each sample's light."""
    n = len(surf)
    groups = ctx.groups if sums is not None else None
    out = np.zeros((3, n), np.float32)
    lights = ctx.lights
    live = res.has_sample() & (res.W > 0)
    rays = []  # (rows, contributions, groups, bounce, origins, directions, tmax): one Embree call for both kinds
    if live.any():  # every row at once (empty reservoirs contribute zero): no row subsets to copy
        q, wi, dist, cos_l, le = lights.point_towards(np.maximum(res.light, 0), res.b1, res.b2, surf.p)
        _p, f, g, _pb = shading_value(surf, wi, le, dist, cos_l)
        contrib = f * le
        contrib *= g * res.W * live
        go = np.flatnonzero(vmax(np.abs(contrib)) > 0)
        if go.size:
            group = None if groups is None else groups.of_lights(res.light[go], reservoirs=True)
            bounce = np.zeros(go.size, bool)  # world points whose light passes cut-outs as bouncing rays do
            if ctx.world.lit_by_bounces:
                bounce[lights.env_rows(res.light[go])] = True
            rays.append((go, cols(contrib, go), group, bounce, *shadow_rays(cols(surf.p, go), cols(surf.ng, go),
                                                                            cols(q, go), cols(wi, go), dist[go])))
    if lights.sun_alias is not None:
        ls = lights.sample_suns(n, rng.random((4, n), dtype=np.float32))
        wi_l = to_local(ls.wi, surf.ns, surf.t, surf.bt)
        f, _pb = eval_view(surf.view, surf.wo_l, wi_l)
        ok = (dot(ls.wi, surf.ng) > 0) & (ls.pdf > 0)
        contrib = f * ls.le
        contrib *= np.abs(wi_l[2]) / np.maximum(ls.pdf, 1e-30) * ok
        go = np.flatnonzero(vmax(np.abs(contrib)) > 0)
        if go.size:
            group = None if groups is None else groups.of_lights(ls.light[go])
            rays.append((go, cols(contrib, go), group, np.zeros(go.size, bool),
                         *shadow_rays(cols(surf.p, go), cols(surf.ng, go), cols(ls.pos, go), cols(ls.wi, go),
                                      ls.dist[go])))
    if rays:
        o = np.concatenate([r[4] for r in rays], axis=1)
        d = np.concatenate([r[5] for r in rays], axis=1)
        far = np.concatenate([r[6] for r in rays])
        keep, tr = ctx.geom_accel.passed(o, d, far, np.concatenate([r[3] for r in rays]))
        visible = np.zeros(len(far), bool)
        visible[keep] = True
        if tr is not None:  # coloured transparent surfaces on the way: the light they let through
            through = np.ones((3, len(far)), np.float32)
            through[:, keep] = tr
        start = 0
        for rows, contrib, group, *_ in rays:  # rows are unique within each kind
            vis = visible[start:start + len(rows)]
            c = contrib[:, vis] if tr is None else contrib[:, vis] * through[:, start:start + len(rows)][:, vis]
            out[:, rows[vis]] += c
            if group is not None:
                light_groups.add(sums, rows[vis], group[vis], finite(c))
            start += len(rows)
    return finite(out)
