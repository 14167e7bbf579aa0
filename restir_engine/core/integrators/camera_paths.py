"""Camera paths: primary hits through pixel positions (the emission seen directly, film alpha, cut-outs), camera
paths continued through smooth glass to the surface behind (ReSTIR resamples there), and the data passes' G-buffer
(depth, normal, motion vector at pixel centres)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry import camera as camera_mod
from ..geometry.accel import Hits
from ..lights import groups as light_groups
from ..lights.table import emitted_radiance
from . import path_state
from ..materials import volume
from ..materials.surface import Surface
from ..sampling import cols, finite
from .pathtracer import sample_rays
from .ray_emission import _lamp_emission, lamp_hits
from .trace_context import TraceContext


@dataclass
class PrimaryHits:
    """Camera rays through n raster points: emission seen directly (3, n), alpha (n,), the rows that hit
    geometry (k,) and their surfaces (surface.Surface, k); with light groups ``emitted_g`` (G, 3, n), the emission
    by the group of what emits it (lights/groups.py). ``tint`` (3, k) or None: the colour the rays to those surfaces
    kept through coloured transparent surfaces in front (the emission seen already has it; the light the surfaces
    reflect is to be scaled by it)."""

    emitted: np.ndarray
    alpha: np.ndarray
    rows: np.ndarray
    surf: Surface
    emitted_g: np.ndarray = None
    tint: np.ndarray = None


def primary(ctx: TraceContext, x: np.ndarray, y: np.ndarray, may_hit: np.ndarray | None = None,
            may_see_lamp: np.ndarray | None = None, lens_uv: np.ndarray | None = None) -> PrimaryHits:
    """Camera rays through raster points (x, y) (window pixels + jitter, y up). ``may_hit`` / ``may_see_lamp`` (n,)
    bool: False where the ray is known to meet no geometry / no lamp visible to the camera (projected boxes,
    camera.box_pixels and camera.emitter_pixels), which is then not traced against it; under a constant world a ray
    that may meet neither is not generated at all (it sees the world's colour, or nothing on a transparent film).
    ``lens_uv`` (2, n): aperture samples where the camera has a lens."""
    if may_hit is not None and ctx.world.image is None:
        need = may_hit if not len(ctx.scene.lamps.tris) else \
            np.ones(len(x), bool) if may_see_lamp is None else may_hit | may_see_lamp
        if not need.all():
            idx = np.flatnonzero(need)
            sub = primary(ctx, x[idx], y[idx], may_hit[idx], None if may_see_lamp is None else may_see_lamp[idx],
                          None if lens_uv is None else lens_uv[:, idx])
            transparent = ctx.film_transparent
            emitted = np.empty((3, len(x)), np.float32)
            emitted[:] = 0.0 if transparent else ctx.world.color[:, None]
            emitted[:, idx] = sub.emitted
            alpha = np.full(len(x), 0.0 if transparent else 1.0, np.float32)
            alpha[idx] = sub.alpha
            emitted_g = light_groups.zeros(ctx.groups, len(x))
            if emitted_g is not None:
                if not transparent and ctx.groups.world >= 0:
                    emitted_g[ctx.groups.world] = ctx.world.color[:, None]
                emitted_g[:, :, idx] = sub.emitted_g
            return PrimaryHits(emitted, alpha, idx[sub.rows], sub.surf, emitted_g, sub.tint)
    cam = ctx.scene.camera
    o, d, tmax = camera_mod.generate_rays(cam, x, y, lens_uv)
    if may_hit is None or may_hit.all():
        hits = ctx.geom_accel.intersect(o, d, tmax, camera=True)
    else:
        hits = Hits(len(x))
        idx = np.flatnonzero(may_hit)
        if idx.size:
            hits.put(idx, ctx.geom_accel.intersect(cols(o, idx), cols(d, idx), None if tmax is None else tmax[idx],
                                                   camera=True))
    emitted, alpha, emitted_g = _seen(ctx, o, d, tmax, hits, lamp_mask=may_see_lamp)
    rows = np.flatnonzero(hits.prim >= 0)
    tint = None if hits.tint is None else cols(hits.tint, rows)
    surf = Surface(ctx, hits.prim[rows], hits.u[rows], hits.v[rows], cols(o, rows), cols(d, rows), hits.t[rows],
                   camera=True)
    held = holdout_hits(ctx, surf)
    if held is not None:  # the pixel is transparent and black there
        alpha[rows[held]] = 0.0
        emitted[:, rows[held]] = 0.0
        if emitted_g is not None:
            emitted_g[:, :, rows[held]] = 0.0
        scale = np.ones(len(rows), np.float32)
        scale[held] = 0.0
        surf.params.scale(scale)
    return PrimaryHits(emitted, alpha, rows, surf, emitted_g, tint)


def holdout_hits(ctx: TraceContext, surf) -> np.ndarray | None:
    """Indices of camera hits ``surf`` on a Holdout shader or a holdout object (Object > Visibility > Holdout);
    None when there are none."""
    mat_hold = getattr(ctx.scene.materials, "holdout", None)
    objs = getattr(ctx.scene.geometry, "objects", None)
    obj_hold = getattr(objs, "holdout", None)
    held = np.zeros(len(surf.prim), bool)
    if mat_hold is not None and mat_hold.any():
        held |= mat_hold[surf.bsdf_mat]
    inst = ctx.scene.geometry.instance
    if obj_hold is not None and obj_hold.any() and inst is not None:
        held |= obj_hold[inst[surf.prim]]
    return np.flatnonzero(held) if held.any() else None


def seen_emission(ctx: TraceContext, x: np.ndarray, y: np.ndarray, lens_uv: np.ndarray | None = None):
    """What camera rays through raster points (x, y) (and aperture samples ``lens_uv``) see emitted (3, n), their
    alpha (n,) and the emission by light group (G, 3, n) or None: the part of :func:`primary` that needs no surface
    (extra rays per pixel for pixel coverage)."""
    o, d, tmax = camera_mod.generate_rays(ctx.scene.camera, x, y, lens_uv)
    return _seen(ctx, o, d, tmax, ctx.geom_accel.intersect(o, d, tmax, camera=True))


def _tinted(hits, emitted, emitted_g):
    """The emission rays ``hits`` saw (3, n) (and by light group (G, 3, n) or None) times the colour they kept
    through the transparent surfaces in front of it."""
    if hits.tint is None:
        return emitted, emitted_g
    return emitted * hits.tint, None if emitted_g is None else emitted_g * hits.tint


def _seen(ctx: TraceContext, o, d, tmax, hits, camera: bool = True, lamp_mask: np.ndarray | None = None):
    """Emission (3, n) camera rays meet first: visible lamps in front of the hit, emissive surfaces, the world
    where nothing is hit (unless the film is transparent); alpha (n,) 0 where nothing is hit on a transparent
    film. ``camera`` False: rays continuing a camera ray through delta interfaces (every lamp is seen, the film's
    transparency does not apply). ``lamp_mask`` (n,) bool: only these rays may see a lamp (None: all). With light
    groups also the emission by group (G, 3, n) (else None)."""
    n = len(hits.prim)
    emitted = np.zeros((3, n), np.float32)
    groups = ctx.groups
    emitted_g = light_groups.zeros(groups, n)
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
            if groups is not None:
                light_groups.add(emitted_g, sel if rows is None else rows[sel],
                                 groups.of_lights(ctx.lights.lamp_to_light[lh.prim[sel]]), em)
    miss = hits.prim < 0
    if ctx.film_transparent and camera:
        alpha[miss] = 0.0
    elif miss.any():
        m = np.flatnonzero(miss)
        em = ctx.world.radiance(cols(d, m), camera=camera)
        emitted[:, m] += em
        if groups is not None:
            light_groups.add(emitted_g, m, groups.world, em)
    if ctx.lights.n_geom:  # emissive surfaces (mesh emission is two-sided by default)
        prim = np.maximum(hits.prim, 0)
        em = np.flatnonzero((hits.prim >= 0) & (ctx.lights.geom_to_light[prim] >= 0))
        if em.size:
            footprint = camera_mod.pixel_footprint(ctx.scene.camera, hits.t[em]) if ctx.has_programs else None
            le = emitted_radiance(ctx.scene.geometry, ctx.scene.materials, prim[em], hits.u[em], hits.v[em],
                                  -cols(d, em) if ctx.has_programs else None, camera, footprint)
            emitted[:, em] += le
            if groups is not None:
                light_groups.add(emitted_g, em, groups.of_lights(ctx.lights.geom_to_light[prim[em]]), le)
    if tmax is not None and camera:  # frame points off a panorama's image (beyond a fisheye's circle): black
        dead = tmax < 0
        if dead.any():
            emitted[:, dead] = 0.0
            alpha[dead] = 0.0
            if emitted_g is not None:
                emitted_g[:, :, dead] = 0.0
    emitted, emitted_g = _tinted(hits, emitted, emitted_g)
    return finite(emitted), alpha, None if emitted_g is None else finite(emitted_g)


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
    thr = np.ones((3, n), np.float32) if hits.tint is None else hits.tint.copy()
    depth = np.zeros(n, np.int64)
    alive = np.ones(n, bool)
    idx = np.flatnonzero(s.glass)
    cur = s.take(idx)
    # the Light Path state of each pixel's chain (path_state.py), where some program reads it
    state = path_state.at_camera(n) if ctx.reads_path else None
    for k in range(ctx.max_bounces + 1):  # as the path tracer: rays from vertices 0..max_bounces find emission,
        ray = sample_rays(cur, rng.random((3, len(idx)), dtype=np.float32))  # vertices up to max_bounces are shaded
        alive[np.setdiff1d(idx, idx[ray.rows])] = False
        if state is not None and ray.kinds is not None:
            moved = path_state.after_bounce(path_state.take(state, idx), ray.rows, *ray.kinds)
            for key, v in moved.items():
                state[key][idx[ray.rows]] = v
        idx = idx[ray.rows]
        if idx.size == 0:
            break
        thr[:, idx] *= ray.f
        depth[idx] += 1
        hit = ctx.geom_accel.intersect(ray.o, ray.d)
        absorbed = volume.transmittance(ctx, hit.prim, hit.t, ray.d)  # the segment inside an absorbing mesh
        if absorbed is not None:
            thr[:, idx] *= absorbed
        em, _a, em_g = _seen(ctx, ray.o, ray.d, None, hit, camera=False)  # (through the tints in front of it)
        pix = hits.rows[idx]
        hits.emitted[:, pix] += finite(cols(thr, idx) * em)
        if em_g is not None:
            hits.emitted_g[:, :, pix] += finite(cols(thr, idx) * em_g)
        if hit.tint is not None:
            thr[:, idx] *= hit.tint
        got = (hit.prim >= 0) & (depth[idx] <= ctx.max_bounces)
        alive[idx[~got]] = False
        sel = np.flatnonzero(got)
        idx = idx[sel]
        if idx.size == 0:
            break
        prim[idx], b1[idx], b2[idx], t[idx] = hit.prim[sel], hit.u[sel], hit.v[sel], hit.t[sel]
        o[:, idx], d[:, idx] = cols(ray.o, sel), cols(ray.d, sel)
        cur = Surface(ctx, prim[idx], b1[idx], b2[idx], o[:, idx], d[:, idx], t[idx],
                      path=path_state.take(state, idx))
        more = np.zeros(len(idx), bool) if cur.glass is None else cur.glass
        if not more.any():
            idx = idx[:0]
            break
        cur = cur.take(np.flatnonzero(more))
        idx = idx[more]
    alive[idx] = False  # still on glass when the bounce budget ran out
    keep = np.flatnonzero(alive)
    hits.rows = hits.rows[keep]
    hits.surf = Surface(ctx, prim[keep], b1[keep], b2[keep], o[:, keep], d[:, keep], t[keep], walks=True,
                        path=path_state.take(state, keep))
    hits.tint = None
    return SpecularChains(thr[:, keep], depth[keep])




def gbuffer(ctx: TraceContext, x: np.ndarray, y: np.ndarray):
    """First hit at raster points (x, y): planar depth along the camera axis (n,) (1e10 = nothing,
    as Cycles), the world-space shading normal facing the camera (n, 3) (zero = nothing) and the motion
    vector (n, 4) in Blender's convention: (prev - current, current - next) raster positions in pixels
    (zero without neighbouring-frame data or where nothing is hit)."""
    cam = ctx.scene.camera
    o, d, tmax = camera_mod.generate_rays(cam, x, y)
    hits = ctx.geom_accel.intersect(o, d, tmax, camera=True)
    depth = np.full(len(x), 1e10, np.float32)
    normal = np.zeros((len(x), 3), np.float32)
    vector = np.zeros((len(x), 4), np.float32)
    hit = np.flatnonzero(hits.prim >= 0)
    if hit.size:
        s = Surface(ctx, hits.prim[hit], hits.u[hit], hits.v[hit], cols(o, hit), cols(d, hit), hits.t[hit])
        depth[hit] = camera_mod.view_depth(cam, s.p)
        normal[hit] = s.facing_normals()[1].T
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


