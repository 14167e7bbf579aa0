"""The emission a path's rays meet, as the path tracer weighs it: lamps crossed before the hit (a point or spot
lamp's sphere through its proxy), emissive triangles hit, the world and the suns seen by escaping rays, each
MIS-weighted against light sampling by the power heuristic (solid-angle pdfs). Radiance, scene-linear RGB."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..lights.receiver import receiver_factor
from ..lights.table import emitted_radiance
from ..materials.glass import DELTA_PDF
from ..sampling import cols, dot, norm
from .trace_context import TraceContext


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
    os, ds = cols(o, sel), cols(d, sel)
    le *= receiver_factor(lamps, prim, os, os + ds * np.where(np.isfinite(t), t, 0).astype(np.float32)) * (cos_l > 0)
    light = ctx.lights.lamp_to_light[prim]
    pdf = np.where(light >= 0, ctx.lights.pdf_solid_angle(np.maximum(light, 0), cols(o, sel), t, cos_l), 0.0)
    return le, pdf.astype(np.float32)


def _lamps_on_rays(ctx: TraceContext, o, d, hits, prev_pdf, collect, add) -> None:
    """Lamps in front of the rays' hits (``collect``: only those rays, or None for all), MIS-weighted against
    light sampling (solid-angle pdfs)."""
    lh = lamp_hits(ctx, o, d, hits.t)
    sel = np.flatnonzero((lh.prim >= 0) if collect is None else (lh.prim >= 0) & collect)
    if sel.size:
        le, pl = _lamp_emission(ctx, lh, o, d, sel)
        le *= power_heuristic(prev_pdf[sel], pl)
        add(sel, le, None if ctx.groups is None else ctx.groups.of_lights(ctx.lights.lamp_to_light[lh.prim[sel]]))


def _world_on_rays(ctx: TraceContext, d, esc, prev_pdf, origin_n, add) -> None:
    """The world seen by the escaping rays ``esc``; MIS-weighted where the world was light-sampled at the vertex
    (``origin_n``: the receivers' normals, for a constant world's light-sample pdf)."""
    de = cols(d, esc)
    le = ctx.world.radiance(de)
    if origin_n is not None:
        le *= power_heuristic(prev_pdf[esc], ctx.world.pdf(de, cols(origin_n, esc)))
    add(esc, le, None if ctx.groups is None else ctx.groups.world)


def _suns_on_rays(ctx: TraceContext, d, esc, prev_pdf, add) -> None:
    """The suns of non-zero angle seen by escaping delta rays ``esc`` (from glass, where no light was sampled; the
    other vertices light-sample the suns and their BSDF rays never collect them): a sun's disk radiance
    E / (π sin² θ) within its half-angle θ, weight 1."""
    lamps = ctx.scene.lamps
    esc = esc[prev_pdf[esc] >= DELTA_PDF]
    if esc.size == 0:
        return
    de = cols(d, esc)
    de = de / np.maximum(norm(de), np.float32(1e-30))
    for k in np.flatnonzero(lamps.sun_cos < 1.0 - 1e-9):  # a loop over suns, not rays
        inside = np.flatnonzero(de.T @ lamps.sun_dir[k].astype(np.float32) >= lamps.sun_cos[k])
        if inside.size == 0:
            continue
        sin2 = max(1.0 - float(lamps.sun_cos[k]) ** 2, 1e-30)
        le = np.repeat((lamps.sun_irradiance[k] / (np.pi * sin2)).astype(np.float32)[:, None], inside.size, axis=1)
        group = None if ctx.groups is None else ctx.groups.of_lights(np.full(inside.size, ctx.lights.n_tri + k))
        add(esc[inside], le, group)


def _emitters_hit(ctx: TraceContext, d, hits, hsel, hp, prev_pdf, collect, add, path=None) -> None:
    """Emissive triangles hit by the rays ``hsel`` (primitives ``hp``), MIS-weighted against light sampling;
    ``path``: the rays' Light Path state or None."""
    light = ctx.lights.geom_to_light[hp]
    em = np.flatnonzero((light >= 0) if collect is None else (light >= 0) & collect[hsel])
    if em.size:
        hs = hsel[em]
        le = emitted_radiance(ctx.scene.geometry, ctx.scene.materials, hp[em], hits.u[hs], hits.v[hs],
                              -cols(d, hs) if ctx.has_programs else None,
                              path=None if path is None else {k: v[hs] for k, v in path.items()})
        cos_l = -dot(cols(d, hs), cols(ctx.geom_ng_rows, hp[em]))
        le *= (cos_l > 0) | ctx.lights.tri_two_sided[light[em]]
        pl = ctx.lights.tri_pdf_solid_angle(light[em], hits.t[hs], cos_l)
        le *= power_heuristic(prev_pdf[hs], pl)
        add(hs, le, None if ctx.groups is None else ctx.groups.of_lights(light[em]))


def _emission_on_rays(ctx: TraceContext, o, d, hits, prev_pdf, collect, world_collect, add, world: bool, origin_n,
                      path: dict | None = None):
    """The emission BSDF rays (o, d; traced ``hits``) find, into ``add``: lamps in front of the hits, then the
    hit emitters, else the world where ``world``. ``collect`` (or None: all rays): the rays that collect lamps and
    emitters; ``world_collect`` (or None: all) the escaping rays that collect the world; ``path``: the rays' Light
    Path state (integrators/path_state.py) or None. Returns (rows that hit geometry, their primitives)."""
    gather = collect is None or bool(collect.any())
    if gather and len(ctx.scene.lamps.tris):
        _lamps_on_rays(ctx, o, d, hits, prev_pdf, collect, add)
    hit = hits.prim >= 0
    esc = np.flatnonzero(~hit)
    if world_collect is not None:
        esc = esc[world_collect[esc]]
    if esc.size and world:  # film transparency affects camera rays only
        _world_on_rays(ctx, d, esc, prev_pdf, origin_n, add)
    if esc.size and gather and len(ctx.scene.lamps.sun_dir):
        _suns_on_rays(ctx, d, esc if collect is None else esc[collect[esc]], prev_pdf, add)
    hsel = np.flatnonzero(hit)
    hp = hits.prim[hsel]
    if hsel.size and gather:
        _emitters_hit(ctx, d, hits, hsel, hp, prev_pdf, collect, add, path)
    return hsel, hp
