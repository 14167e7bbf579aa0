"""The unbiased reference path tracer (also the indirect light of every integrator).

Estimator per pixel sample (wavefront form, vectorized over the rays of a chunk):
  L = Le(x0) + Σ_k T_k [ f·|cos|·Le / p_light · w_light  (next-event estimation at x_k)
                          + f·|cos|/p_bsdf · Le(x_{k+1}) · w_bsdf ]   (BSDF sampling)
with power-heuristic MIS weights w = p²/(p_light² + p_bsdf²), both pdfs in solid angle.
``max_bounces`` = 0 is direct light only (as in Cycles); Russian roulette from bounce ``rr_start``.
Lamps (Blender Light objects) emit but do not occlude; a ray collects the nearest lamp in front
of its geometry hit and continues. The world (core/lights/world.py: a constant colour or an environment image) is a
light too: next-event estimation samples it besides the lights (:func:`world_event`, its own shadow ray) and
escaping BSDF rays collect it MIS-weighted against that. Suns are light-sampled only.

The path is split in three calls so that another direct-light estimator can take the place of the first
vertex's next-event estimation: :func:`primary` (camera rays, emission seen directly), :func:`next_event`
(NEE at a set of surfaces) and :func:`continue_paths` (the BSDF half of the first vertex's direct light,
then bounces 1..max_bounces). With ``direct_resampled`` the first BSDF ray's emitter hits are left to the
resampled estimator (ReSTIR DI) and the ray may be the one that estimator already traced.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..geometry import camera as camera_mod
from ..geometry.accel import Accel, Hits, offset_origin, shadow_rays
from ..lights.table import LightTable, emitted_radiance, spot_factor, triangle_geometry
from ..lights.world import World
from ..lights.world_points import WorldSphere
from ..materials import microfacet_tables
from ..materials.bsdf import SurfaceParams, diffuse_f, eval_view, sample_bsdf
from ..materials.cutout import Cutout
from ..materials.glass import DELTA_PDF, sample_glass
from ..materials.surface import Surface
from ..sampling import cols, dot, finite, norm, to_local, to_world, vfinite, vmax
from ..scene import Scene


@dataclass
class TraceContext:
    """Everything a chunk needs, built once per frame (reused while the scene content is unchanged).
    Per-triangle data the path tracer gathers is kept as rows (structure of arrays)."""

    scene: Scene
    geom_accel: Accel
    lamp_accel: Accel
    lights: LightTable
    geom_ng: np.ndarray  # (n, 3) unit geometric normals
    lamp_ng: np.ndarray
    material_params: SurfaceParams  # per material, untextured (gathered per hit)
    max_bounces: int
    rr_start: int = 3
    film_transparent: bool = False
    material_albedo: np.ndarray = None  # (m, 32) GGX albedo rows over μo at each material's α
    material_layer: np.ndarray = None   # (m, 32) dielectric layer factor S rows over μo (microfacet_tables)
    has_mix: bool = False  # some material is a Mix/Add shader (core/materials/mix.py)
    world: World = None    # the background as a light (core/lights/world.py)
    normal_maps: bool = False  # some material has a tangent-space normal map (surface.normal_map)
    bump_maps: bool = False    # some material has a Bump node (surface.bump_map)
    has_glass: bool = False    # some material has a smooth glass closure (core/materials/glass.py)
    geom_flat: np.ndarray = None        # (n,) bool: the triangle's three corner normals are equal (no interpolation)
    geom_ng_rows: np.ndarray = None     # (3, n) geom_ng as rows
    geom_normal_rows: np.ndarray = None  # (9, n) corner shading normals as rows (corner 0 x, y, z, corner 1 ...)
    lamp_ng_rows: np.ndarray = None     # (3, n_lamp) lamp_ng as rows
    geom_derived: "GeometryDerived" = None  # the geometry-only arrays above, kept for a rebuild over the same triangles
    emit_accel: Accel = None  # the emissive scene triangles alone (light index = primitive index), or None
    # what rendering this content measured (shared by the frames and views that reuse this context):
    # "auto_indirect" -> the last frame's AUTO indirect measurement and choice (renderer.FrameRenderer._remember)
    measured: dict = field(default_factory=dict)


def power_heuristic(a, b):
    a2 = a * a
    return np.where(a2 > 0, a2 / np.maximum(a2 + b * b, 1e-30), 0.0).astype(np.float32)


@dataclass
class LampHits:
    """Per ray: prim the lamp triangle crossed (-1: none), t, (u, v) barycentrics (sphere coordinates on a
    point/spot sphere), cos_l between -d and the lamp's normal there."""

    prim: np.ndarray
    t: np.ndarray
    u: np.ndarray
    v: np.ndarray
    cos_l: np.ndarray


def lamp_hits(ctx: TraceContext, o: np.ndarray, d: np.ndarray, tmax: np.ndarray) -> LampHits:
    """The nearest lamp each ray (o, d: (3, n) rows) crosses before ``tmax`` (n,). A ray that enters a point/spot
    sphere's proxy is intersected with the sphere itself."""
    h = ctx.lamp_accel.intersect(o, d, tmax)
    lh = LampHits(h.prim, h.t, h.u, h.v, np.zeros(len(h.prim), np.float32))
    lh.prim[~(lh.t < tmax)] = -1
    hit = np.flatnonzero(lh.prim >= 0)
    if hit.size == 0:
        return lh
    prim = lh.prim[hit]
    lh.cos_l[hit] = -dot(cols(d, hit), cols(ctx.lamp_ng_rows, prim))
    lights = ctx.lights
    if lights.any_sphere:
        light = lights.lamp_to_light[prim]
        sph = np.flatnonzero(lights.sphere_r[np.maximum(light, 0)] * (light >= 0) > 0)
        if sph.size:
            rows = hit[sph]
            t, b1, b2, cos_l = lights.sphere_hits(light[sph], cols(o, rows), cols(d, rows), tmax[rows])
            lh.t[rows], lh.u[rows], lh.v[rows], lh.cos_l[rows] = t, b1, b2, cos_l
            lh.prim[rows[~np.isfinite(t)]] = -1  # through the proxy, past the sphere
    return lh


def _lamp_emission(ctx: TraceContext, lh, o, d, sel):
    """Radiance (3, k) collected from the nearest lamp hit (:func:`lamp_hits`) by rays ``sel`` (front faces
    only), and the solid-angle light pdf (k,) of that point for MIS."""
    prim = lh.prim[sel]
    t = lh.t[sel]
    cos_l = lh.cos_l[sel]
    lamps = ctx.scene.lamps
    le = emitted_radiance(lamps.tris, ctx.scene.materials, prim, lh.u[sel], lh.v[sel])
    le *= spot_factor(lamps, prim, cols(o, sel)) * (cos_l > 0)
    light = ctx.lights.lamp_to_light[prim]
    pdf = np.where(light >= 0, ctx.lights.pdf_solid_angle(np.maximum(light, 0), cols(o, sel), t, cos_l), 0.0)
    return le, pdf.astype(np.float32)


@dataclass
class PrimaryHits:
    """Camera rays through n raster points: emission seen directly (3, n), alpha (n,), the rows that hit
    geometry (k,) and their surfaces (surface.Surface, k)."""

    emitted: np.ndarray
    alpha: np.ndarray
    rows: np.ndarray
    surf: Surface


def primary(ctx: TraceContext, x: np.ndarray, y: np.ndarray, may_hit: np.ndarray | None = None,
            may_see_lamp: np.ndarray | None = None) -> PrimaryHits:
    """Camera rays through raster points (x, y) (window pixels + jitter, y up). ``may_hit`` / ``may_see_lamp`` (n,)
    bool: False where the ray is known to meet no geometry / no lamp visible to the camera (projected boxes,
    camera.box_pixels and camera.emitter_pixels), which is then not traced against it; under a constant world a ray
    that may meet neither is not generated at all (it sees the world's colour, or nothing on a transparent film)."""
    if may_hit is not None and ctx.world.image is None:
        need = may_hit if not len(ctx.scene.lamps.tris) else \
            np.ones(len(x), bool) if may_see_lamp is None else may_hit | may_see_lamp
        if not need.all():
            idx = np.flatnonzero(need)
            sub = primary(ctx, x[idx], y[idx], may_hit[idx], None if may_see_lamp is None else may_see_lamp[idx])
            transparent = ctx.film_transparent
            emitted = np.empty((3, len(x)), np.float32)
            emitted[:] = 0.0 if transparent else ctx.world.color[:, None]
            emitted[:, idx] = sub.emitted
            alpha = np.full(len(x), 0.0 if transparent else 1.0, np.float32)
            alpha[idx] = sub.alpha
            return PrimaryHits(emitted, alpha, idx[sub.rows], sub.surf)
    cam = ctx.scene.camera
    o, d, tmax = camera_mod.generate_rays(cam, x, y)
    if may_hit is None or may_hit.all():
        hits = ctx.geom_accel.intersect(o, d, tmax)
    else:
        hits = Hits(len(x))
        idx = np.flatnonzero(may_hit)
        if idx.size:
            sub = ctx.geom_accel.intersect(cols(o, idx), cols(d, idx), None if tmax is None else tmax[idx])
            hits.prim[idx], hits.t[idx], hits.u[idx], hits.v[idx] = sub.prim, sub.t, sub.u, sub.v
    emitted, alpha = _seen(ctx, o, d, tmax, hits, lamp_mask=may_see_lamp)
    rows = np.flatnonzero(hits.prim >= 0)
    surf = Surface(ctx, hits.prim[rows], hits.u[rows], hits.v[rows], cols(o, rows), cols(d, rows), hits.t[rows])
    return PrimaryHits(emitted, alpha, rows, surf)


def seen_emission(ctx: TraceContext, x: np.ndarray, y: np.ndarray):
    """What camera rays through raster points (x, y) see emitted (3, n) and their alpha (n,): the part of
    :func:`primary` that needs no surface (extra rays per pixel for pixel coverage)."""
    o, d, tmax = camera_mod.generate_rays(ctx.scene.camera, x, y)
    return _seen(ctx, o, d, tmax, ctx.geom_accel.intersect(o, d, tmax))


def _seen(ctx: TraceContext, o, d, tmax, hits, camera: bool = True, lamp_mask: np.ndarray | None = None):
    """Emission (3, n) camera rays meet first: visible lamps in front of the hit, emissive surfaces, the world
    where nothing is hit (unless the film is transparent); alpha (n,) 0 where nothing is hit on a transparent
    film. ``camera`` False: rays continuing a camera ray through delta interfaces (every lamp is seen, the film's
    transparency does not apply). ``lamp_mask`` (n,) bool: only these rays may see a lamp (None: all)."""
    n = len(hits.prim)
    emitted = np.zeros((3, n), np.float32)
    alpha = np.ones(n, np.float32)
    rows = None if lamp_mask is None else np.flatnonzero(lamp_mask)
    if len(ctx.scene.lamps.tris) and (rows is None or rows.size):  # lamps seen (camera rays: those visible to them)
        far = hits.t if tmax is None else np.minimum(hits.t, tmax)
        oo, dd = (o, d) if rows is None else (cols(o, rows), cols(d, rows))
        lh = lamp_hits(ctx, oo, dd, far if rows is None else far[rows])
        sel = np.flatnonzero(lh.prim >= 0)
        if camera:
            sel = sel[ctx.scene.lamps.camera_visible[lh.prim[sel]]]
        if sel.size:
            em = _lamp_emission(ctx, lh, oo, dd, sel)[0]
            emitted[:, sel if rows is None else rows[sel]] += em
    miss = hits.prim < 0
    if ctx.film_transparent and camera:
        alpha[miss] = 0.0
    elif miss.any():
        m = np.flatnonzero(miss)
        emitted[:, m] += ctx.world.radiance(cols(d, m))
    if ctx.lights.n_geom:  # emissive surfaces (mesh emission is two-sided by default)
        prim = np.maximum(hits.prim, 0)
        em = np.flatnonzero((hits.prim >= 0) & (ctx.lights.geom_to_light[prim] >= 0))
        if em.size:
            emitted[:, em] += emitted_radiance(ctx.scene.geometry, ctx.scene.materials, prim[em], hits.u[em],
                                               hits.v[em])
    return finite(emitted), alpha


@dataclass
class SpecularChains:
    """Camera paths continued through smooth glass to the first other surface (:func:`follow_specular`): per
    remaining hit row, the throughput (3, k) of the delta interfaces crossed and their number ``depth`` (k,)."""

    throughput: np.ndarray
    depth: np.ndarray


def follow_specular(ctx: TraceContext, hits: PrimaryHits, rng: np.random.Generator) -> SpecularChains | None:
    """Continue the camera rays that met smooth glass through its delta interfaces (reflection or refraction
    drawn by Fresnel) until they meet another surface, in place: ``hits.surf`` becomes that surface (so resampling
    runs where the light is actually shaded), the emission met on the way (lamps, emissive surfaces, the world,
    times the throughput so far; MIS weight 1 after a delta interface) joins ``hits.emitted``, and rows that
    escape, die on a shading-normal artefact or exceed the bounce budget leave ``hits.rows``. Returns the chains
    (None when no camera ray met glass)."""
    s = hits.surf
    if s.glass is None or ctx.max_bounces == 0:
        return None
    n = len(hits.rows)
    prim, b1, b2 = s.prim.copy(), s.b1.copy(), s.b2.copy()
    o, d, t = s.p.copy(), -s.wo, np.zeros(n, np.float32)
    thr = np.ones((3, n), np.float32)
    depth = np.zeros(n, np.int64)
    alive = np.ones(n, bool)
    idx = np.flatnonzero(s.glass)
    cur = s.take(idx)
    for k in range(ctx.max_bounces + 1):  # as the path tracer: rays from vertices 0..max_bounces find emission,
        ray = sample_rays(cur, rng.random((3, len(idx)), dtype=np.float32))  # vertices up to max_bounces are shaded
        alive[np.setdiff1d(idx, idx[ray.rows])] = False
        idx = idx[ray.rows]
        if idx.size == 0:
            break
        thr[:, idx] *= ray.f
        depth[idx] += 1
        hit = ctx.geom_accel.intersect(ray.o, ray.d)
        em, _a = _seen(ctx, ray.o, ray.d, None, hit, camera=False)
        pix = hits.rows[idx]
        hits.emitted[:, pix] += finite(cols(thr, idx) * em)
        got = (hit.prim >= 0) & (depth[idx] <= ctx.max_bounces)
        alive[idx[~got]] = False
        sel = np.flatnonzero(got)
        idx = idx[sel]
        if idx.size == 0:
            break
        prim[idx], b1[idx], b2[idx], t[idx] = hit.prim[sel], hit.u[sel], hit.v[sel], hit.t[sel]
        o[:, idx], d[:, idx] = cols(ray.o, sel), cols(ray.d, sel)
        cur = Surface(ctx, prim[idx], b1[idx], b2[idx], o[:, idx], d[:, idx], t[idx])
        more = np.zeros(len(idx), bool) if cur.glass is None else cur.glass
        if not more.any():
            idx = idx[:0]
            break
        cur = cur.take(np.flatnonzero(more))
        idx = idx[more]
    alive[idx] = False  # still on glass when the bounce budget ran out
    keep = np.flatnonzero(alive)
    hits.rows = hits.rows[keep]
    hits.surf = Surface(ctx, prim[keep], b1[keep], b2[keep], o[:, keep], d[:, keep], t[keep])
    return SpecularChains(thr[:, keep], depth[keep])


def next_event(ctx: TraceContext, s: Surface, rng: np.random.Generator, throughput=None, diffuse: bool = False):
    """Next-event estimation at surfaces s (n): one light sample each, MIS-weighted against BSDF sampling
    (delta lights weight 1), one shadow ray. Radiance (3, n), times ``throughput`` (3, n) if given. With
    ``diffuse`` also the part reflected by the diffuse lobe alone: (radiance, diffuse part)."""
    n = len(s)
    if ctx.world.sampled and n:
        w_out = world_event(ctx, s, rng, throughput, diffuse)
    else:
        w_out = None
    out = np.zeros((3, n), np.float32)
    if ctx.lights.empty or n == 0:
        if w_out is not None:
            return w_out
        return (out, out.copy()) if diffuse else out
    ls = ctx.lights.sample(s.p, rng.random((4, n), dtype=np.float32))
    wi_l = to_local(ls.wi, s.ns, s.t, s.bt)
    f, pdf_b = eval_view(s.view, s.wo_l, wi_l)
    w = np.where(ls.delta, np.float32(1.0), power_heuristic(ls.pdf, pdf_b))
    contrib = f * ls.le
    contrib *= np.abs(wi_l[2]) * w / np.maximum(ls.pdf, np.float32(1e-30))
    if throughput is not None:
        contrib *= throughput
    live = np.flatnonzero((dot(ls.wi, s.ng) > 0) & (ls.pdf > 0) & (vmax(contrib) > 0))
    lv = live
    if live.size:
        so, sd, far = shadow_rays(cols(s.p, live), cols(s.ng, live), cols(ls.pos, live), cols(ls.wi, live),
                                  ls.dist[live])
        lv = live[~ctx.geom_accel.occluded(so, sd, far)]
        out[:, lv] = finite(cols(contrib, lv))
    if not diffuse:
        return out if w_out is None else out + w_out
    out_d = np.zeros((3, n), np.float32)
    if lv.size:
        kd = diffuse_f(s.view, cols(wi_l, lv), lv)
        out_d[:, lv] = finite(kd * cols(ls.le, lv) * (np.abs(wi_l[2, lv]) * w[lv] /
                                                       np.maximum(ls.pdf[lv], np.float32(1e-30))))
    if w_out is not None:
        return out + w_out[0], out_d + w_out[1]
    return out, out_d


def world_event(ctx: TraceContext, s: Surface, rng: np.random.Generator, throughput=None, diffuse: bool = False):
    """Next-event estimation of the world at surfaces s (n): one direction sampled from the world's distribution,
    MIS-weighted against BSDF sampling, one shadow ray to infinity. Radiance (3, n) (times ``throughput``), and
    with ``diffuse`` also the part the diffuse lobe alone reflects."""
    n = len(s)
    u = rng.random((2, n), dtype=np.float32)
    wi, pdf, le = ctx.world.sample(u[0], u[1], (s.ns, s.t, s.bt))
    wi_l = to_local(wi, s.ns, s.t, s.bt)
    f, pdf_b = eval_view(s.view, s.wo_l, wi_l)
    w = power_heuristic(pdf, pdf_b)
    scale = np.abs(wi_l[2]) * w / np.maximum(pdf, np.float32(1e-30))
    contrib = f * le * scale
    if throughput is not None:
        contrib *= throughput
    out = np.zeros((3, n), np.float32)
    live = np.flatnonzero((dot(wi, s.ng) > 0) & (pdf > 0) & (vmax(contrib) > 0))
    if live.size:
        so, sd, far = shadow_rays(cols(s.p, live), cols(s.ng, live), np.zeros((3, live.size), np.float32),
                                  cols(wi, live), np.full(live.size, np.inf, np.float32))
        live = live[~ctx.geom_accel.occluded(so, sd, far)]
        out[:, live] = finite(cols(contrib, live))
    if not diffuse:
        return out
    out_d = np.zeros((3, n), np.float32)
    if live.size:
        out_d[:, live] = finite(diffuse_f(s.view, cols(wi_l, live), live) * cols(le, live) * scale[live])
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
                                         s.glass_alpha[g], u[1, g], u[2, g], s.glass_ms[g])
        wi[:, g] = wg
        wi_l[:, g] = 0.0
        wi_l[2, g] = 1.0  # unused for delta rows (their throughput is the weight)
        f[:, g] = weight
        pdf[g] = DELTA_PDF
        ok[g] = valid
        delta = s.glass
    rows = np.flatnonzero(ok)
    d = cols(wi, rows)
    return BsdfRay(rows, cols(wi_l, rows), cols(f, rows), pdf[rows], offset_origin(cols(s.p, rows), cols(s.ng, rows), d),
                   d, delta=None if delta is None else delta[rows])


def needs_continuation(ctx: TraceContext, direct_resampled: bool, world_resampled: bool = False) -> bool:
    """Whether :func:`continue_paths` has anything to add: bounces, or the first BSDF ray's emitter hits (when
    the direct light is not resampled) or the world it escapes to."""
    return ctx.max_bounces > 0 or not direct_resampled or ctx.world.sampled and not world_resampled


@dataclass
class FirstBounce:
    """Where the first BSDF rays of primary surfaces (n) went, for ReSTIR GI: ``rows`` (k,) the surfaces whose
    ray hit geometry at x2; ``throughput`` (3, k) f·|cos θ|/p of that ray (p: ``pdf`` (k,), solid angle);
    x2 ``p`` (3, k), its geometric normal ``n2`` (3, k) turned toward the primary surface, its BSDF parameters
    ``params`` (bsdf.SurfaceParams, k) and ``lo`` (3, k) the radiance leaving x2 toward the primary surface
    estimated by the rest of the path (next-event estimation at x2 and bounces 2..max_bounces; not x2's own
    emission, which is the primary surface's direct light), ``lo_d`` (3, k) the part of it x2's diffuse lobe
    reflects (the same light samples weighed by the diffuse lobe alone). The path tracer's indirect light is
    throughput · lo."""

    rows: np.ndarray
    throughput: np.ndarray
    pdf: np.ndarray
    p: np.ndarray
    n2: np.ndarray
    params: SurfaceParams
    lo: np.ndarray
    lo_d: np.ndarray = None


@dataclass
class PathResult:
    """What :func:`continue_paths` found for primary surfaces (n): ``direct`` (3, n) the first BSDF ray's emitter
    hits (MIS-weighted) and the world it escapes to; ``indirect`` (3, n) bounces 1..max_bounces; ``first`` the
    :class:`FirstBounce` when asked for (indirect is then its throughput · lo), else None. Radiance, scene-linear."""

    direct: np.ndarray
    indirect: np.ndarray
    first: FirstBounce | None = None


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
    direct = np.zeros((3, n), np.float32)
    indirect = np.zeros((3, n), np.float32)
    idx = np.arange(n)
    throughput = np.ones((3, n), np.float32)
    lamps = ctx.scene.lamps
    world_on = ctx.world.sampled or bool((ctx.world.mean > 0).any())
    first = None
    dthr = None  # with first_bounce, after x2's BSDF sample: the throughput through x2's diffuse lobe alone
    for bounce in range(ctx.max_bounces + 1):
        target = direct if bounce == 0 else (indirect if first is None else first.lo)
        if bounce == 1 and first is not None:  # at x2: split by lobe (throughput is 1 here)
            ne, ne_d = next_event(ctx, s, rng, None, diffuse=True)
            target[:, idx] += ne
            first.lo_d[:, idx] += ne_d
        elif bounce > 0 and dthr is not None:
            ne = next_event(ctx, s, rng, None)
            target[:, idx] += ne * throughput
            first.lo_d[:, idx] += ne * dthr
        elif bounce > 0:
            target[:, idx] += next_event(ctx, s, rng, throughput)
        # --- BSDF sampling (its emission hit still belongs to this bounce's direct light) -------
        ray = first_ray if bounce == 0 and first_ray is not None else \
            sample_rays(s, rng.random((3, len(idx)), dtype=np.float32))
        rows, wi_l, f, pdf, o, d, hits = ray.rows, ray.wi_l, ray.f, ray.pdf, ray.o, ray.d, ray.hits
        thr = cols(throughput, rows) * f
        scale = wi_l[2] / np.maximum(pdf, np.float32(1e-30))
        if ray.delta is not None:
            scale = np.where(ray.delta, np.float32(1.0), scale).astype(np.float32)
        thr *= scale
        if bounce == 1 and first is not None:  # x2's diffuse lobe alone (throughput 1 before it)
            dthr = diffuse_f(s.view, wi_l, rows) * scale
        elif dthr is not None:
            dthr = cols(dthr, rows) * f * scale
        ok = vfinite(thr)
        if bounce + 1 >= ctx.rr_start:
            q = np.clip(vmax(thr), 0.05, 1.0)
            ok &= rng.random(len(rows), dtype=np.float32) < q
            thr /= q
            if dthr is not None:
                dthr /= q
        keep = np.flatnonzero(ok)
        if keep.size == 0:
            break
        if ctx.world.sampled:
            origin_n = cols(s.ns, rows[keep])  # the receivers' normals, for a constant world's light-sample pdf
        idx, throughput, prev_pdf = idx[rows[keep]], cols(thr, keep), pdf[keep]
        if dthr is not None:
            dthr = cols(dthr, keep)
        o, d = cols(o, keep), cols(d, keep)
        if hits is None:
            hits = ctx.geom_accel.intersect(o, d)
        else:
            hits = hits.take(keep)
        # emission found by the BSDF ray: lamps in front of the hit, then the hit itself, else the world; when
        # the first surfaces' direct light is resampled, only what their delta (glass) rays find, which
        # resampling cannot reach
        collect = None if not (bounce == 0 and direct_resampled) else \
            (np.zeros(len(keep), bool) if ray.delta is None else ray.delta[keep])
        if (collect is None or collect.any()) and len(lamps.tris):
            lh = lamp_hits(ctx, o, d, hits.t)
            sel = np.flatnonzero((lh.prim >= 0) if collect is None else (lh.prim >= 0) & collect)
            if sel.size:
                le, pl = _lamp_emission(ctx, lh, o, d, sel)
                le *= power_heuristic(prev_pdf[sel], pl)
                target[:, idx[sel]] += finite(cols(throughput, sel) * le)
                if dthr is not None:
                    first.lo_d[:, idx[sel]] += finite(cols(dthr, sel) * le)
        hit = hits.prim >= 0
        esc = np.flatnonzero(~hit)
        if world_resampled and collect is not None:  # only delta rays, which resampling cannot reach
            esc = esc[collect[esc]]
        if esc.size and world_on:  # film transparency affects camera rays only
            de = cols(d, esc)
            le = ctx.world.radiance(de)
            if ctx.world.sampled:  # the world was light-sampled at this vertex too
                le *= power_heuristic(prev_pdf[esc], ctx.world.pdf(de, cols(origin_n, esc)))
            target[:, idx[esc]] += finite(cols(throughput, esc) * le)
            if dthr is not None:
                first.lo_d[:, idx[esc]] += finite(cols(dthr, esc) * le)
        hsel = np.flatnonzero(hit)
        if hsel.size == 0:
            break
        hp = hits.prim[hsel]
        last = None if budget is None else budget[idx[hsel]] <= bounce  # this path's bounces are spent
        if collect is None or collect.any():
            light = ctx.lights.geom_to_light[hp]
            em = np.flatnonzero((light >= 0) if collect is None else (light >= 0) & collect[hsel])
            if em.size:
                hs = hsel[em]
                le = emitted_radiance(ctx.scene.geometry, ctx.scene.materials, hp[em], hits.u[hs], hits.v[hs])
                cos_l = -dot(cols(d, hs), cols(ctx.geom_ng_rows, hp[em]))
                le *= (cos_l > 0) | ctx.lights.tri_two_sided[light[em]]
                pl = ctx.lights.tri_pdf_solid_angle(light[em], hits.t[hs], cos_l)
                le *= power_heuristic(prev_pdf[hs], pl)
                target[:, idx[hs]] += finite(cols(throughput, hs) * le)
                if dthr is not None:
                    first.lo_d[:, idx[hs]] += finite(cols(dthr, hs) * le)
        if bounce == ctx.max_bounces:
            break
        if last is not None and last.any():
            hsel, hp = hsel[~last], hp[~last]
            if hsel.size == 0:
                break
        idx, throughput = idx[hsel], cols(throughput, hsel)
        if dthr is not None:
            dthr = cols(dthr, hsel)
        s = Surface(ctx, hp, hits.u[hsel], hits.v[hsel], cols(o, hsel), cols(d, hsel), hits.t[hsel])
        if bounce == 0 and first_bounce:
            # from here on the path estimates the radiance leaving x2: throughput 1, accumulated per first hit
            first = FirstBounce(idx, throughput, prev_pdf[hsel], s.p, s.ng, s.params,
                                np.zeros((3, len(idx)), np.float32), np.zeros((3, len(idx)), np.float32))
            if budget is not None:
                budget = budget[idx]
            idx = np.arange(len(idx))
            throughput = np.ones((3, len(idx)), np.float32)
    if not first_bounce:
        return PathResult(direct, indirect)
    if first is None:
        first = FirstBounce(np.zeros(0, np.int64), np.zeros((3, 0), np.float32), np.zeros(0, np.float32),
                            np.zeros((3, 0), np.float32), np.zeros((3, 0), np.float32),
                            ctx.material_params.take(np.zeros(0, np.intp)), np.zeros((3, 0), np.float32),
                            np.zeros((3, 0), np.float32))
    else:
        first.lo = finite(first.lo)
        first.lo_d = finite(first.lo_d)
        indirect[:, first.rows] = first.throughput * first.lo
    return PathResult(direct, indirect, first)


def gbuffer(ctx: TraceContext, x: np.ndarray, y: np.ndarray):
    """First hit at raster points (x, y): planar depth along the camera axis (n,) (1e10 = nothing,
    as Cycles), the world-space shading normal facing the camera (n, 3) (zero = nothing) and the motion
    vector (n, 4) in Blender's convention: (prev - current, current - next) raster positions in pixels
    (zero without neighbouring-frame data or where nothing is hit)."""
    cam = ctx.scene.camera
    o, d, tmax = camera_mod.generate_rays(cam, x, y)
    hits = ctx.geom_accel.intersect(o, d, tmax)
    depth = np.full(len(x), 1e10, np.float32)
    normal = np.zeros((len(x), 3), np.float32)
    vector = np.zeros((len(x), 4), np.float32)
    hit = np.flatnonzero(hits.prim >= 0)
    if hit.size:
        s = Surface(ctx, hits.prim[hit], hits.u[hit], hits.v[hit], cols(o, hit), cols(d, hit), hits.t[hit])
        depth[hit] = dot(s.p - camera_mod.position(cam)[:, None], camera_mod.forward(cam)[:, None])
        normal[hit] = s.ns.T
        motion = ctx.scene.motion
        inst = ctx.scene.geometry.instance
        if motion is not None and inst is not None:
            here = np.stack([x[hit], y[hit]], axis=1)
            for which, which_cols, sign in (("prev", slice(0, 2), 1.0), ("next", slice(2, 4), -1.0)):
                other_cam = motion.camera_prev if which == "prev" else motion.camera_next
                if other_cam is None:
                    continue
                moved = motion.moved_points(s.p, inst[s.prim], which)
                raster, _z = camera_mod.project(other_cam, moved)
                vector[hit, which_cols] = sign * (raster - here)
    return depth, normal, np.where(np.isfinite(vector), vector, 0.0).astype(np.float32)


@dataclass
class GeometryDerived:
    """Per-triangle arrays derived from the geometry alone (kept while the triangles are unchanged)."""

    bounds: tuple          # (min (3,), max (3,)) of the finite vertices, or None when there are none
    ng: np.ndarray         # (n, 3) unit geometric normals
    ng_rows: np.ndarray    # (3, n)
    flat: np.ndarray       # (n,) bool: the three corner normals are equal
    normal_rows: np.ndarray  # (9, n) corner shading normals as rows
    boxes: tuple = None    # (lo (k, 3), hi (k, 3)): each instance's box (one box without instances; camera.box_pixels)

    @staticmethod
    def of(geom) -> "GeometryDerived":
        verts = geom.verts.reshape(-1, 3)
        finite = verts[np.isfinite(verts).all(axis=1)]
        bounds = (finite.min(0), finite.max(0)) if len(finite) else None
        boxes = instance_boxes(geom, bounds)
        ng, _ = triangle_geometry(geom.verts) if len(geom) else (np.zeros((0, 3), np.float32), None)
        nrm = geom.normals
        flat = (nrm[:, 0] == nrm[:, 1]).all(axis=1) & (nrm[:, 0] == nrm[:, 2]).all(axis=1)
        return GeometryDerived(bounds, ng, np.ascontiguousarray(ng.T), flat,
                               np.ascontiguousarray(nrm.reshape(len(nrm), 9).T, dtype=np.float32), boxes)


def instance_boxes(geom, bounds) -> tuple:
    """(lo (k, 3), hi (k, 3)) float32: the bounding box of each instance's finite vertices (geometry.instance),
    or the scene's ``bounds`` as one box when there are no instances; empty without geometry."""
    empty = (np.zeros((0, 3), np.float32), np.zeros((0, 3), np.float32))
    if bounds is None:
        return empty
    inst = geom.instance
    if inst is None or len(inst) == 0 or inst.min() == inst.max():
        return np.asarray(bounds[0], np.float32)[None], np.asarray(bounds[1], np.float32)[None]
    v = geom.verts
    ok = np.isfinite(v).all(axis=2)[..., None]
    tlo = np.where(ok, v, np.inf).min(axis=1)
    thi = np.where(ok, v, -np.inf).max(axis=1)
    order = np.argsort(inst, kind="stable")
    starts = np.flatnonzero(np.r_[True, np.diff(inst[order]) != 0])
    lo = np.minimum.reduceat(tlo[order], starts)
    hi = np.maximum.reduceat(thi[order], starts)
    keep = np.isfinite(lo).all(axis=1) & np.isfinite(hi).all(axis=1)
    return lo[keep].astype(np.float32), hi[keep].astype(np.float32)


def build_context(scene: Scene, max_bounces: int, film_transparent: bool = False, accels: dict | None = None
                  ) -> TraceContext:
    """Everything the chunks need for ``scene``. ``accels`` (optional) hands over what an earlier context built
    over exactly these triangles (an edit of materials, lamps or the world): "geom" / "lamp" Embree scenes
    (Accel), "derived" (GeometryDerived); they are reused instead of rebuilt."""
    accels = accels or {}
    geom = scene.geometry
    lamps = scene.lamps
    derived = accels.get("derived") or GeometryDerived.of(geom)
    lamp_verts = lamps.tris.verts.reshape(-1, 3)
    lamp_verts = lamp_verts[np.isfinite(lamp_verts).all(axis=1)]
    boxes = [b for b in (derived.bounds, (lamp_verts.min(0), lamp_verts.max(0)) if len(lamp_verts) else None)
             if b is not None]
    lo = np.min([b[0] for b in boxes], axis=0) if boxes else np.zeros(3)
    hi = np.max([b[1] for b in boxes], axis=0) if boxes else np.zeros(3)
    radius = float(np.linalg.norm(hi - lo) / 2) if boxes else 1.0
    geom_ng = derived.ng
    lamp_ng, _ = triangle_geometry(lamps.tris.verts) if len(lamps.tris) else (np.zeros((0, 3), np.float32), None)
    params = SurfaceParams.of_table(scene.materials)
    geom_ng_rows = derived.ng_rows
    cut = Cutout.of(geom, scene.materials)
    geom_accel = accels["geom"].with_cutout(cut, geom_ng_rows if cut else None) if "geom" in accels else \
        Accel(geom.verts, cut, geom_ng_rows if cut else None)
    world = World(scene.world_radiance, getattr(scene, "world_image", None), getattr(scene, "world_rotation", None))
    lights = LightTable(scene, max(radius, 1e-3))
    if world.sampled:  # the world's points may enter ReSTIR DI reservoirs (di.CandidateSettings.world_candidates)
        lights.attach_world(WorldSphere(world, (lo + hi) / 2, max(radius, 1e-3)))
    return TraceContext(scene=scene, geom_accel=geom_accel,
                        lamp_accel=accels["lamp"] if "lamp" in accels else Accel(lamps.tris.verts),
                        lights=lights, geom_ng=geom_ng, lamp_ng=lamp_ng,
                        emit_accel=Accel(lights.tri_verts[:lights.n_geom]) if lights.n_geom else None,
                        material_params=params, max_bounces=int(max(0, max_bounces)),
                        film_transparent=film_transparent, material_albedo=microfacet_tables.albedo_rows(params.alpha),
                        material_layer=microfacet_tables.layer_rows(params.alpha, params.f0r),
                        has_mix=scene.materials.mix_first is not None and bool((scene.materials.mix_first >= 0).any()),
                        normal_maps=scene.materials.normal_tex is not None
                        and bool((scene.materials.normal_tex >= 0).any()),
                        bump_maps=scene.materials.bump_tex is not None and bool((scene.materials.bump_tex >= 0).any()),
                        has_glass=scene.materials.transmission is not None
                        and bool((scene.materials.transmission > 0).any()),
                        world=world,
                        geom_flat=derived.flat, geom_ng_rows=geom_ng_rows, geom_normal_rows=derived.normal_rows,
                        lamp_ng_rows=np.ascontiguousarray(lamp_ng.T), geom_derived=derived)
