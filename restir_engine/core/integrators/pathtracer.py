"""The unbiased reference path tracer (also the indirect light of every integrator).

Estimator per pixel sample (wavefront form, vectorized over the rays of a chunk):
  L = Le(x0) + Σ_k T_k [ f·|cos|·Le / p_light · w_light  (next-event estimation at x_k)
                          + f·|cos|/p_bsdf · Le(x_{k+1}) · w_bsdf ]   (BSDF sampling)
with power-heuristic MIS weights w = p²/(p_light² + p_bsdf²), both pdfs in solid angle.
``max_bounces`` = 0 is direct light only (as in Cycles); Russian roulette from bounce ``rr_start``.
Lamps (Blender Light objects) emit but do not occlude; a ray collects the nearest lamp in front
of its geometry hit and continues. The world (core/lights/world.py: a constant colour or an environment image) is a
light too: next-event estimation samples it besides the lights (:func:`world_event`, its own shadow ray) and
escaping BSDF rays collect it MIS-weighted against that. Suns are light-sampled only. What the rays meet:
ray_emission.py; subsurface walks: subsurface.py.

The path is split in three calls so that another direct-light estimator can take the place of the first
vertex's next-event estimation: camera_paths.primary (camera rays, emission seen directly), :func:`next_event`
(NEE at a set of surfaces) and :func:`continue_paths` (the BSDF half of the first vertex's direct light,
then bounces 1..max_bounces). With ``direct_resampled`` the first BSDF ray's emitter hits are left to the
resampled estimator (ReSTIR DI) and the ray may be the one that estimator already traced.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.accel import offset_origin, shadow_rays
from ..lights import groups as light_groups
from ..lights.groups import Tap, tap_add
from ..materials.bsdf import diffuse_f, eval_view, sample_bsdf
from ..materials import glass as glass_mod
from ..materials.glass import DELTA_PDF, sample_glass
from ..materials.params import SurfaceParams
from ..materials.surface import Surface
from ..materials import volume
from ..sampling import cols, dot, finite, norm, to_local, to_world, vfinite, vmax
from . import path_state
from .ray_emission import _emission_on_rays, power_heuristic
from .subsurface import subsurface_light, vertex_walks, with_exit_rays
from .trace_context import TraceContext


def _light_terms(s: Surface, wi_l: np.ndarray, wi: np.ndarray):
    """f (3, n) and the BSDF sampling pdf (n,) of surfaces ``s`` toward light directions ``wi`` (world; ``wi_l``
    local), and where a light sample may count ((n,) bool: above the geometric surface, or on either side of rough
    glass, whose lobe (glass.eval_rough) covers both)."""
    f, pdf_b = eval_view(s.view, s.wo_l, wi_l)
    side = dot(wi, s.ng) > 0
    rough = glass_mod.rough_rows(s)
    if rough.size:
        f[:, rough], pdf_b[rough] = glass_mod.eval_rough(s, rough, np.take(wi, rough, axis=1))
        side[rough] = True
    return f, pdf_b, side


def next_event(ctx: TraceContext, s: Surface, rng: np.random.Generator, throughput=None, diffuse: bool = False,
               taps=(), taps_d=()):
    """Next-event estimation at surfaces s (n): one light sample each, MIS-weighted against BSDF sampling
    (delta lights weight 1), one shadow ray. Radiance (3, n), times ``throughput`` (3, n) if given. With
    ``diffuse`` also the part reflected by the diffuse lobe alone: (radiance, diffuse part). Light groups
    (lights/groups.py): each row's radiance also goes into ``taps``, its diffuse part into ``taps_d``."""
    n = len(s)
    if ctx.world.sampled and n:
        w_out = world_event(ctx, s, rng, throughput, diffuse, taps, taps_d)
    else:
        w_out = None
    out = np.zeros((3, n), np.float32)
    if ctx.lights.empty or n == 0:
        if w_out is not None:
            return w_out
        return (out, out.copy()) if diffuse else out
    ls = ctx.lights.sample(s.p, rng.random((4, n), dtype=np.float32))
    wi_l = to_local(ls.wi, s.ns, s.t, s.bt)
    f, pdf_b, side = _light_terms(s, wi_l, ls.wi)
    w = np.where(ls.delta, np.float32(1.0), power_heuristic(ls.pdf, pdf_b))
    contrib = f * ls.le
    contrib *= np.abs(wi_l[2]) * w / np.maximum(ls.pdf, np.float32(1e-30))
    if throughput is not None:
        contrib *= throughput
    live = np.flatnonzero(side & (ls.pdf > 0) & (vmax(np.abs(contrib)) > 0))
    lv = live
    if live.size:
        so, sd, far = shadow_rays(cols(s.p, live), cols(s.ng, live), cols(ls.pos, live), cols(ls.wi, live),
                                  ls.dist[live])
        keep, tr = ctx.geom_accel.passed(so, sd, far)
        lv = live[keep]
        out[:, lv] = finite(cols(contrib, lv) if tr is None else cols(contrib, lv) * tr)
    group = ctx.groups.of_lights(ls.light[lv]) if (taps or taps_d) and lv.size else None
    if group is not None:
        tap_add(taps, lv, group, cols(out, lv))
    if not diffuse:
        return out if w_out is None else out + w_out
    out_d = np.zeros((3, n), np.float32)
    if lv.size:
        kd = diffuse_f(s.view, cols(wi_l, lv), lv)
        out_d[:, lv] = finite(kd * cols(ls.le, lv) * (np.abs(wi_l[2, lv]) * w[lv] /
                                                       np.maximum(ls.pdf[lv], np.float32(1e-30))))
        if tr is not None:
            out_d[:, lv] *= tr
        if group is not None:
            tap_add(taps_d, lv, group, cols(out_d, lv))
    if w_out is not None:
        return out + w_out[0], out_d + w_out[1]
    return out, out_d


def world_event(ctx: TraceContext, s: Surface, rng: np.random.Generator, throughput=None, diffuse: bool = False,
                taps=(), taps_d=()):
    """Next-event estimation of the world at surfaces s (n): one direction sampled from the world's distribution,
    MIS-weighted against BSDF sampling, one shadow ray to infinity. Radiance (3, n) (times ``throughput``), and
    with ``diffuse`` also the part the diffuse lobe alone reflects; both also into the light groups' ``taps`` and
    ``taps_d`` (as :func:`next_event`)."""
    n = len(s)
    u = rng.random((2, n), dtype=np.float32)
    wi, pdf, le = ctx.world.sample(u[0], u[1], (s.ns, s.t, s.bt))
    wi_l = to_local(wi, s.ns, s.t, s.bt)
    f, pdf_b, side = _light_terms(s, wi_l, wi)
    w = power_heuristic(pdf, pdf_b)
    scale = np.abs(wi_l[2]) * w / np.maximum(pdf, np.float32(1e-30))
    contrib = f * le * scale
    if throughput is not None:
        contrib *= throughput
    out = np.zeros((3, n), np.float32)
    live = np.flatnonzero(side & (pdf > 0) & (vmax(np.abs(contrib)) > 0))
    if live.size:
        so, sd, far = shadow_rays(cols(s.p, live), cols(s.ng, live), np.zeros((3, live.size), np.float32),
                                  cols(wi, live), np.full(live.size, np.inf, np.float32))
        keep, tr = ctx.geom_accel.passed(so, sd, far, np.full(live.size, ctx.world.lit_by_bounces))
        live = live[keep]
        out[:, live] = finite(cols(contrib, live) if tr is None else cols(contrib, live) * tr)
    grouped = bool(taps or taps_d) and live.size > 0
    if grouped:
        tap_add(taps, live, ctx.groups.world, cols(out, live))
    if not diffuse:
        return out
    out_d = np.zeros((3, n), np.float32)
    if live.size:
        out_d[:, live] = finite(diffuse_f(s.view, cols(wi_l, live), live) * cols(le, live) * scale[live])
        if tr is not None:
            out_d[:, live] *= tr
        if grouped:
            tap_add(taps_d, live, ctx.groups.world, cols(out_d, live))
    return out, out_d


@dataclass
class BsdfRay:
    """BSDF-sampled rays leaving surfaces (k of n): the rows of the surfaces whose sample leaves above the
    geometric surface, local direction (3, k), f (3, k), pdf (k,) (solid angle), offset origins and world
    directions (3, k), and their closest geometry hits once traced (accel.Hits, or None)."""

    rows: np.ndarray
    wi_l: np.ndarray
    f: np.ndarray
    pdf: np.ndarray
    o: np.ndarray
    d: np.ndarray
    hits: object = None
    delta: np.ndarray | None = None  # (k,) bool: a delta sample (smooth glass): f is its weight, pdf DELTA_PDF
    kinds: tuple | None = None  # (diffuse, singular, transmit) (k,) bool each: the Light Path type (path_state.py)
    walked: np.ndarray | None = None    # (k,) bool: a ray from a subsurface walk's exit (subsurface.with_exit_rays)
    origin_n: np.ndarray | None = None  # (3, k): the normals at the rays' origins where not all are the rows'


def sample_rays(s: Surface, u: np.ndarray) -> BsdfRay:
    """One BSDF sample per surface of s from uniforms u (3, n), kept where it leaves above the surface (or, from
    smooth glass, on the side its delta sample goes to)."""
    wi_l, f, pdf = sample_bsdf(s.params, s.wo_l, u[0], u[1], u[2], view=s.view)
    wi = to_world(wi_l, s.ns, s.t, s.bt)
    wi /= np.maximum(norm(wi), np.float32(1e-12))
    ok = (pdf > 0) & (dot(wi, s.ng) > 0)
    delta = None
    if s.glass is not None:
        g = np.flatnonzero(s.glass)
        wg, weight, valid = sample_glass(cols(s.wo, g), cols(s.ns, g), cols(s.ng, g), s.glass_front[g],
                                         s.glass_ior[g], cols(s.glass_reflect, g), cols(s.glass_refract, g), u[0, g],
                                         s.glass_alpha[g], u[1, g], u[2, g], s.glass_ms[g],
                                         None if s.glass_fresnel is None else s.glass_fresnel[g],
                                         None if s.glass_beckmann is None else s.glass_beckmann[g])
        wi[:, g] = wg
        wi_l[:, g] = 0.0
        wi_l[2, g] = 1.0  # unused for glass rows (their throughput is the weight)
        f[:, g] = weight
        pdf[g] = DELTA_PDF
        rough = glass_mod.rough_rows(s)
        if rough.size:  # rough glass is light-sampled too: its rays' emission takes MIS weights by their pdf
            pdf[rough] = glass_mod.eval_rough(s, rough, np.take(wi, rough, axis=1))[1]
        ok[g] = valid
        delta = s.glass
    rows = np.flatnonzero(ok)
    d = cols(wi, rows)
    kinds = tuple(k[rows] for k in path_state.ray_kinds(s, u[0], wi)) if getattr(s, "reads_path", False) else None
    return BsdfRay(rows, cols(wi_l, rows), cols(f, rows), pdf[rows], offset_origin(cols(s.p, rows), cols(s.ng, rows), d),
                   d, delta=None if delta is None else delta[rows], kinds=kinds)


def needs_continuation(ctx: TraceContext, direct_resampled: bool, world_resampled: bool = False) -> bool:
    """Whether :func:`continue_paths` has anything to add: bounces, or the first BSDF ray's emitter hits (when
    the direct light is not resampled) or the world it escapes to."""
    return ctx.max_bounces > 0 or not direct_resampled or ctx.world.sampled and not world_resampled \
        or ctx.has_subsurface


@dataclass
class FirstBounce:
    """Where the first BSDF rays of primary surfaces (n) went, for ReSTIR GI: ``rows`` (k,) the surfaces whose
    ray hit geometry at x2; ``throughput`` (3, k) f·|cos θ|/p of that ray (p: ``pdf`` (k,), solid angle);
    x2 ``p`` (3, k), its geometric normal ``n2`` (3, k) turned toward the primary surface, its BSDF parameters
    ``params`` (params.SurfaceParams, k) and ``lo`` (3, k) the radiance leaving x2 toward the primary surface
    estimated by the rest of the path (next-event estimation at x2 and bounces 2..max_bounces; not x2's own
    emission, which is the primary surface's direct light), ``lo_d`` (3, k) the part of it x2's diffuse lobe
    reflects (the same light samples weighed by the diffuse lobe alone). The path tracer's indirect light is
    throughput · lo. With light groups, ``lo_g`` and ``lo_d_g`` (G, 3, k): lo and lo_d by the group of their lights
    (lights/groups.py). ``tint`` (3, k) or None: the colour the ray kept through the transparent surfaces it passed
    on its way to x2 (in ``throughput`` too)."""

    rows: np.ndarray
    throughput: np.ndarray
    pdf: np.ndarray
    p: np.ndarray
    n2: np.ndarray
    params: SurfaceParams
    lo: np.ndarray
    lo_d: np.ndarray = None
    lo_g: np.ndarray = None
    lo_d_g: np.ndarray = None
    tint: np.ndarray = None


@dataclass
class PathResult:
    """What :func:`continue_paths` found for primary surfaces (n): ``direct`` (3, n) the first BSDF ray's emitter
    hits (MIS-weighted) and the world it escapes to; ``indirect`` (3, n) bounces 1..max_bounces; ``first`` the
    :class:`FirstBounce` when asked for (indirect is then its throughput · lo), else None. Radiance, scene-linear.
    With light groups ``direct_g`` and ``indirect_g`` (G, 3, n): the same by the group of their lights.
    ``walked`` (subsurface.SubsurfaceLight or None): what the surfaces' subsurface walks brought, already in direct
    and indirect (its indirect part is not in ``first``: a stage that replaces the indirect light by the first
    bounces' adds it again)."""

    direct: np.ndarray
    indirect: np.ndarray
    first: FirstBounce | None = None
    direct_g: np.ndarray | None = None
    indirect_g: np.ndarray | None = None
    walked: object = None

    def add_walked_indirect(self, indirect: np.ndarray, indirect_g: np.ndarray | None) -> None:
        """Add the subsurface walks' indirect light (and by light group) to ``indirect`` (3, n) in place."""
        w = self.walked
        if w is None:
            return
        indirect[:, w.rows] += w.indirect
        if indirect_g is not None and w.indirect_g is not None:
            indirect_g[:, :, w.rows] += w.indirect_g


def _adder(target, idx, throughput, dthr, first, target_g=None):
    """add(sel, le, group): radiance ``le`` (3, k) arriving along the rays ``sel`` into their paths' estimates
    ``target`` (rows ``idx``, weighted by ``throughput``), and through x2's diffuse lobe (``dthr``) into
    ``first.lo_d``; with light groups also into ``target_g`` (and ``first.lo_d_g``) by the lights' ``group``."""
    def add(sel, le, group=None):
        v = finite(cols(throughput, sel) * le)
        target[:, idx[sel]] += v
        if target_g is not None and group is not None:
            light_groups.add(target_g, idx[sel], group, v)
        if dthr is not None:
            vd = finite(cols(dthr, sel) * le)
            first.lo_d[:, idx[sel]] += vd
            if target_g is not None and group is not None:
                light_groups.add(first.lo_d_g, idx[sel], group, vd)
    return add


def _vertex_light(ctx: TraceContext, s: Surface, rng, target, idx, throughput, first, dthr, at_x2: bool,
                  target_g=None) -> None:
    """Next-event estimation at a path vertex after the first, into ``target`` (and, past a first bounce, the
    diffuse part ``first.lo_d``): at x2 split by lobe (throughput is 1 there), after it weighted by the throughput
    and by the throughput through x2's diffuse lobe ``dthr``; with light groups also into ``target_g`` (and
    ``first.lo_d_g``)."""
    g = target_g is not None
    if at_x2:
        ne, ne_d = next_event(ctx, s, rng, None, diffuse=True, taps=(Tap(target_g, idx),) if g else (),
                              taps_d=(Tap(first.lo_d_g, idx),) if g else ())
        target[:, idx] += ne
        first.lo_d[:, idx] += ne_d
    elif dthr is not None:
        ne = next_event(ctx, s, rng, None, taps=(Tap(target_g, idx, throughput), Tap(first.lo_d_g, idx, dthr))
                        if g else ())
        target[:, idx] += ne * throughput
        first.lo_d[:, idx] += ne * dthr
    else:
        target[:, idx] += next_event(ctx, s, rng, throughput, taps=(Tap(target_g, idx),) if g else ())


def _exit_light(ctx: TraceContext, walks, rng, target, idx, throughput, first, dthr, at_x2: bool,
                target_g=None) -> None:
    """Next-event estimation at the exits of a vertex's subsurface walks (subsurface.VertexWalks), weighed by the
    walks, into ``target`` and, past a first bounce, wholly into ``first.lo_d`` (a walk is x2's diffuse light)."""
    ex = walks.exits
    if ex is None:
        return
    rows = walks.rows[ex.at]
    col = idx[rows]
    thr = ex.weight if at_x2 else cols(throughput, rows) * ex.weight
    d_thr = None if first is None else ex.weight if at_x2 else None if dthr is None else cols(dthr, rows) * ex.weight
    taps = ()
    if target_g is not None:
        taps = (Tap(target_g, col, thr),) + (() if d_thr is None else (Tap(first.lo_d_g, col, d_thr),))
    ne = next_event(ctx, ex.surf, rng, None, taps=taps)
    target[:, col] += ne * thr
    if d_thr is not None:
        first.lo_d[:, col] += ne * d_thr


def _no_first_bounce(ctx: TraceContext) -> FirstBounce:
    """A FirstBounce of no rays (no path reached a second vertex)."""
    z3 = np.zeros((3, 0), np.float32)
    return FirstBounce(np.zeros(0, np.int64), z3, np.zeros(0, np.float32), z3.copy(), z3.copy(),
                       ctx.material_params.take(np.zeros(0, np.intp)), z3.copy(), z3.copy(),
                       light_groups.zeros(ctx.groups, 0), light_groups.zeros(ctx.groups, 0))


def _walked_light(ctx: TraceContext, s: Surface, rng, budget):
    """The paths' accumulators (direct, indirect (3, n) each, their light-group splits or None) with the direct light
    of the subsurface walks from s already in, and the walks' result (subsurface.subsurface_light) or None."""
    n = len(s)
    direct = np.zeros((3, n), np.float32)
    indirect = np.zeros((3, n), np.float32)
    direct_g, indirect_g = light_groups.zeros(ctx.groups, n), light_groups.zeros(ctx.groups, n)
    walked = subsurface_light(ctx, s, rng, continue_paths, budget) if ctx.has_subsurface else None
    if walked is not None:
        direct[:, walked.rows] += walked.direct
        if direct_g is not None:
            direct_g[:, :, walked.rows] += walked.direct_g
    return direct, indirect, direct_g, indirect_g, walked


def continue_paths(ctx: TraceContext, s: Surface, rng: np.random.Generator, direct_resampled: bool = False,
                   first_ray=None, first_bounce: bool = False, budget: np.ndarray | None = None,
                   world_resampled: bool = False) -> PathResult:
    """Continue paths from primary surfaces s (n) (:class:`PathResult`). With ``direct_resampled`` the direct part
    leaves out the emitters resampling reaches, with ``world_resampled`` the world too (the reservoirs hold the
    world's points, world_points.py). ``first_ray`` (a traced :class:`BsdfRay` from s, e.g. ReSTIR's BSDF candidate)
    is used as the first ray instead of drawing a new one. ``first_bounce`` asks for the :class:`FirstBounce`.
    ``budget`` (n,) (optional): the bounces each path may still take (fewer than max_bounces behind a specular
    chain)."""
    n = len(s)
    direct, indirect, direct_g, indirect_g, walked = _walked_light(ctx, s, rng, budget)
    idx = np.arange(n)
    throughput = np.ones((3, n), np.float32)
    world_on = ctx.world.sampled or bool((ctx.world.mean > 0).any())
    first = None
    dthr = None  # with first_bounce, after x2's BSDF sample: the throughput through x2's diffuse lobe alone
    # the Light Path state of the vertices s (path_state.py), where some program reads it
    state = None if not ctx.reads_path else (s.path if s.path is not None else path_state.at_camera(len(idx)))
    for bounce in range(ctx.max_bounces + 1):
        target = direct if bounce == 0 else (indirect if first is None else first.lo)
        target_g = direct_g if bounce == 0 else (indirect_g if first is None else first.lo_g)
        if bounce > 0:
            _vertex_light(ctx, s, rng, target, idx, throughput, first, dthr, at_x2=bounce == 1 and first is not None,
                          target_g=target_g)
        # --- BSDF sampling (its emission hit still belongs to this bounce's direct light) -------
        ray = first_ray if bounce == 0 and first_ray is not None else \
            sample_rays(s, rng.random((3, len(idx)), dtype=np.float32))
        walks = vertex_walks(ctx, s, rng) if bounce > 0 and ctx.has_subsurface else None
        if walks is not None:  # the vertices that chose their subsurface lobe: lit at the exits, rays from there
            _exit_light(ctx, walks, rng, target, idx, throughput, first, dthr, bounce == 1 and first is not None,
                        target_g)
            ray = with_exit_rays(ray, s, walks, rng.random((2, len(walks.rows)), dtype=np.float32))
        rows, pdf, o, d, hits = ray.rows, ray.pdf, ray.o, ray.d, ray.hits
        thr, dthr, ok = _ray_throughput(ray, s, throughput, dthr, bounce == 1 and first is not None,
                                        bounce + 1 >= ctx.rr_start, rng)
        keep = np.flatnonzero(ok)
        if keep.size == 0:
            break
        ray_state = None if state is None else path_state.unknown(keep.size) if ray.kinds is None else \
            path_state.take(path_state.after_bounce(state, rows, *ray.kinds), keep)
        if ctx.world.sampled:  # the receivers' normals, for a constant world's light-sample pdf
            origin_n = cols(s.ns, rows[keep]) if ray.origin_n is None else cols(ray.origin_n, keep)
        idx, throughput, prev_pdf = idx[rows[keep]], cols(thr, keep), pdf[keep]
        if dthr is not None:
            dthr = cols(dthr, keep)
        o, d = cols(o, keep), cols(d, keep)
        if hits is None:
            hits = ctx.geom_accel.intersect(o, d)
        else:
            hits = hits.take(keep)
        absorbed = _kept(ctx, hits, d)
        if absorbed is not None:
            throughput = throughput * absorbed
            if dthr is not None:
                dthr = dthr * absorbed
        # emission found by the BSDF ray: when the first surfaces' direct light is resampled, only what their
        # delta (glass) rays find, which resampling cannot reach
        collect = None if not (bounce == 0 and direct_resampled) else \
            (np.zeros(len(keep), bool) if ray.delta is None else ray.delta[keep])
        add = _adder(target, idx, throughput, dthr, first, target_g)
        # the world resampled at the first surfaces too: only their delta rays collect it
        world_collect = collect if world_resampled else None
        hsel, hp = _emission_on_rays(ctx, o, d, hits, prev_pdf, collect, world_collect, add, world_on,
                                     origin_n if ctx.world.sampled else None, ray_state)
        if hsel.size == 0:
            break
        last = None if budget is None else budget[idx[hsel]] <= bounce  # this path's bounces are spent
        if bounce == ctx.max_bounces:
            break
        if last is not None and last.any():
            hsel, hp = hsel[~last], hp[~last]
            if hsel.size == 0:
                break
        idx, throughput = idx[hsel], cols(throughput, hsel)
        if dthr is not None:
            dthr = cols(dthr, hsel)
        s = Surface(ctx, hp, hits.u[hsel], hits.v[hsel], cols(o, hsel), cols(d, hsel), hits.t[hsel], walks=True,
                    path=path_state.take(ray_state, hsel))
        state = s.path
        if bounce == 0 and first_bounce:
            # from here on the path estimates the radiance leaving x2: throughput 1, accumulated per first hit
            first = FirstBounce(idx, throughput, prev_pdf[hsel], s.p, s.facing_normals()[0], s.params,
                                np.zeros((3, len(idx)), np.float32), np.zeros((3, len(idx)), np.float32),
                                light_groups.zeros(ctx.groups, len(idx)), light_groups.zeros(ctx.groups, len(idx)),
                                None if hits.tint is None else cols(hits.tint, hsel))
            if budget is not None:
                budget = budget[idx]
            idx = np.arange(len(idx))
            throughput = np.ones((3, len(idx)), np.float32)
    out = PathResult(direct, indirect, None, direct_g, indirect_g, walked)
    if first_bounce:
        if first is None:
            first = _no_first_bounce(ctx)
        else:
            _through_first(first, indirect, indirect_g)
        out.first = first
    out.add_walked_indirect(indirect, indirect_g)
    return out


def _kept(ctx: TraceContext, hits, d: np.ndarray):
    """(3, k) the light rays ``d`` kept on their way to ``hits``: through absorbing meshes (volume.transmittance)
    and the tints of coloured transparent surfaces (Hits.tint); None where both are white."""
    absorbed = volume.transmittance(ctx, hits.prim, hits.t, d)
    if hits.tint is None:
        return absorbed
    return hits.tint if absorbed is None else absorbed * hits.tint


def _ray_throughput(ray: BsdfRay, s: Surface, throughput, dthr, at_x2: bool, roulette: bool, rng):
    """The paths' throughput (3, k) along the BSDF rays ``ray`` from surfaces ``s``, the throughput through x2's
    diffuse lobe (``at_x2``: this ray leaves x2; after it ``dthr`` carried on; None without a first bounce), and
    which rays go on ((k,) bool: finite, and past Russian roulette where ``roulette``)."""
    rows, wi_l, f = ray.rows, ray.wi_l, ray.f
    thr = cols(throughput, rows) * f
    scale = wi_l[2] / np.maximum(ray.pdf, np.float32(1e-30))
    if ray.delta is not None:
        scale = np.where(ray.delta, np.float32(1.0), scale).astype(np.float32)
    thr *= scale
    if at_x2:  # x2's diffuse lobe alone (throughput 1 before it)
        dthr = diffuse_f(s.view, wi_l, rows) * scale
        if ray.walked is not None:  # (a walk counts as x2's diffuse light)
            dthr[:, ray.walked] = cols(f, np.flatnonzero(ray.walked)) * scale[ray.walked]
    elif dthr is not None:
        dthr = cols(dthr, rows) * f * scale
    ok = vfinite(thr)
    if roulette:
        q = np.clip(vmax(thr), 0.05, 1.0)
        ok &= rng.random(len(rows), dtype=np.float32) < q
        thr /= q
        if dthr is not None:
            dthr /= q
    return thr, dthr, ok


def _through_first(first: FirstBounce, indirect, indirect_g) -> None:
    """The first bounces' radiance made finite, and the indirect light (by light group where kept) it carries to
    the primary surfaces: throughput · lo."""
    first.lo = finite(first.lo)
    first.lo_d = finite(first.lo_d)
    indirect[:, first.rows] = first.throughput * first.lo
    if indirect_g is not None:
        indirect_g[:, :, first.rows] = first.throughput * first.lo_g
