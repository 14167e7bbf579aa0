"""Reference path tracer: the unbiased baseline every other method is compared with.

Estimator per pixel sample (wavefront form, vectorized over the rays of a tile):
  L = Le(x0) + Σ_k T_k [ f·|cos|·Le / p_light · w_light  (next-event estimation at x_k)
                          + f·|cos|/p_bsdf · Le(x_{k+1}) · w_bsdf ]   (BSDF sampling)
with power-heuristic MIS weights w = p²/(p_light² + p_bsdf²), both pdfs in solid angle.
``max_bounces`` = 0 is direct light only (as in Cycles); Russian roulette from bounce ``rr_start``.
Lamps (Blender Light objects) emit but do not occlude; a ray collects the nearest lamp in front
of its geometry hit and continues. The world colour is collected by escaping rays (weight 1:
it is not light-sampled). Suns are light-sampled only.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import camera as camera_mod
from .accel import Accel, offset_origin, shadow_rays
from .bsdf import SurfaceParams, eval_bsdf, sample_bsdf
from . import restir_di
from .lights import LightTable, emitted_radiance, spot_factor, triangle_geometry
from .sampling import dot, norm, orthonormal_basis, to_local, to_world
from .scene import Scene
from .textures import apply_texture


@dataclass
class TraceContext:
    """Everything a tile needs, built once per frame."""

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


def _power_heuristic(a, b):
    a2 = a * a
    return np.where(a2 > 0, a2 / np.maximum(a2 + b * b, 1e-30), 0.0).astype(np.float32)


def _accumulate(target: np.ndarray, rows: np.ndarray, values: np.ndarray) -> None:
    """target[rows] += values; ``rows`` are unique path indices, so buffered indexing is exact."""
    target[rows] += values


def _sanitize(x: np.ndarray) -> np.ndarray:
    return np.where(np.isfinite(x), x, 0.0).astype(np.float32)


class Surface:
    """Shading data at hits: p, ng, ns (both facing the incoming ray), uv, BSDF params, frame."""

    def __init__(self, ctx: TraceContext, prim, u, v, o, d, t):
        scene = ctx.scene
        geom = scene.geometry
        mats = scene.materials
        self.prim = prim
        self.b1, self.b2 = u, v
        self.p = (o + d * t[:, None]).astype(np.float32)
        ng = ctx.geom_ng[prim]
        bary = np.stack([1 - u - v, u, v], axis=1)
        ns = np.einsum("ijk,ij->ik", geom.normals[prim], bary)
        ns /= np.maximum(norm(ns), 1e-12)[:, None]
        bad = ~np.isfinite(ns).all(axis=1) | (norm(ns) < 0.5)
        ns[bad] = ng[bad]
        ns = np.where((dot(ns, ng) < 0)[:, None], -ns, ns)
        flip = dot(ng, d) > 0
        s = np.where(flip, -1.0, 1.0).astype(np.float32)[:, None]
        self.ng = (ng * s).astype(np.float32)
        self.ns = (ns * s).astype(np.float32)
        self.wo = (-d).astype(np.float32)
        mat = geom.material[prim]
        self.mat = mat
        self.params = ctx.material_params.take(mat)
        self.uv = None
        if geom.uvs is not None:
            self.uv = np.einsum("ijk,ij->ik", geom.uvs[prim], bary)
            textured = np.flatnonzero(mats.base_tex[mat] >= 0)
            if textured.size:  # re-derive the parameters where a texture drives the base colour
                tm = mat[textured]
                base = apply_texture(mats.base_color[tm], mats.base_tex[tm], self.uv[textured], mats.textures)
                sub = SurfaceParams.from_material(base, mats.metallic[tm], mats.roughness[tm], mats.f0[tm])
                for field in ("diffuse", "f0", "f0_dielectric", "alpha", "p_spec", "spec_on"):
                    getattr(self.params, field)[textured] = getattr(sub, field)
        self.t, self.bt = orthonormal_basis(self.ns)
        self.wo_l = to_local(self.wo, self.ns, self.t, self.bt)
        # view vectors below the shading hemisphere (shading-normal artefact): bend to the horizon
        self.wo_l[:, 2] = np.maximum(self.wo_l[:, 2], 1e-4)
        self.wo_l /= norm(self.wo_l)[:, None]

    def emission(self, ctx: TraceContext):
        """Emitted radiance (n, 3) towards the incoming ray (mesh emission is two-sided by default)."""
        return emitted_radiance(ctx.scene.geometry, ctx.scene.materials, self.prim, self.b1, self.b2)


def _lamp_emission(ctx: TraceContext, lh, o, d, sel):
    """Radiance collected from the nearest lamp hit by rays ``sel`` (front faces only), and the
    solid-angle light pdf of that point for MIS."""
    prim = lh.prim[sel]
    t = lh.t[sel]
    ng = ctx.lamp_ng[prim]
    cos_l = -dot(d[sel], ng)
    lamps = ctx.scene.lamps
    p = o[sel] + d[sel] * t[:, None]
    le = emitted_radiance(lamps.tris, ctx.scene.materials, prim, lh.u[sel], lh.v[sel])
    le *= spot_factor(lamps, prim, o[sel])[:, None]
    le = np.where((cos_l > 0)[:, None], le, 0.0)
    light = ctx.lights.lamp_to_light[prim]
    pdf = np.where(light >= 0, ctx.lights.tri_pdf_solid_angle(np.maximum(light, 0), t, cos_l), 0.0)
    del p
    return le.astype(np.float32), pdf.astype(np.float32)


def trace(ctx: TraceContext, x: np.ndarray, y: np.ndarray, rng: np.random.Generator, di=None, reservoir=None):
    """Trace one path per raster sample point (x, y).

    Returns emission seen directly (n, 3), direct (n, 3) and indirect (n, 3) radiance, and alpha (n,).
    With ``di`` (a restir_di.DISettings with method 'RIS' or 'RESTIR') the direct light of the primary hit comes
    from resampled importance sampling instead of NEE + MIS (triangle emitters found by the first BSDF
    ray then belong to RIS and are not added again); ``reservoir`` (dict of (n,) arrays "M", "W") then
    receives the shaded reservoirs' confidence and unbiased contribution weight. With method 'RESTIR'
    the primary hits and initial reservoirs are written to ``reservoir["gbuf"]`` and ``reservoir["res"]``
    at frame rows ``reservoir["rows"]`` instead, and shaded after spatial reuse.
    """
    cam = ctx.scene.camera
    n = len(x)
    o, d, tmax = camera_mod.generate_rays(cam, x, y)
    direct = np.zeros((n, 3), np.float32)
    indirect = np.zeros((n, 3), np.float32)
    emitted = np.zeros((n, 3), np.float32)
    alpha = np.ones(n, np.float32)
    hits = ctx.geom_accel.intersect(o, d, tmax)
    alive = hits.prim >= 0
    # lamps seen by the camera (those marked visible to camera rays)
    if len(ctx.scene.lamps.tris):
        lh = ctx.lamp_accel.intersect(o, d, np.minimum(hits.t, tmax))
        sel = np.flatnonzero((lh.prim >= 0) & (lh.t < hits.t))
        sel = sel[ctx.scene.lamps.camera_visible[lh.prim[sel]]]
        if sel.size:
            le, _ = _lamp_emission(ctx, lh, o, d, sel)
            emitted[sel] += le
    miss = ~alive
    if ctx.film_transparent:
        alpha[miss] = 0.0
    else:
        emitted[miss] += ctx.scene.world_radiance
    idx = np.flatnonzero(alive)
    if idx.size == 0:
        return _sanitize(emitted), direct, indirect, alpha
    o, d = o[idx], d[idx]
    prim, hu, hv, ht = hits.prim[idx], hits.u[idx], hits.v[idx], hits.t[idx]
    throughput = np.ones((idx.size, 3), np.float32)
    prev_pdf = np.zeros(idx.size, np.float32)

    for bounce in range(ctx.max_bounces + 1):
        s = Surface(ctx, prim, hu, hv, o, d, ht)
        target = direct if bounce == 0 else indirect
        ris_here = bounce == 0 and di is not None and di.method in ("RIS", "RESTIR")
        if bounce == 0:
            emitted[idx] += s.emission(ctx)
        if ris_here:
            px = np.floor(x[idx]).astype(np.int64) - cam.window[0]
            py = np.floor(y[idx]).astype(np.int64) - cam.window[1]
            res = restir_di.initial_ris(ctx, s, rng, di, px, py)
            if di.method == "RIS":
                direct[idx] += restir_di.shade(ctx, s, res, rng)
                if reservoir is not None:
                    reservoir["M"][idx] = res.M
                    reservoir["W"][idx] = res.W
            else:  # spatial reuse follows at frame level: hand over surfaces and reservoirs
                rows = reservoir["rows"][idx]
                depth = dot(s.p - camera_mod.position(cam), np.broadcast_to(camera_mod.forward(cam), s.p.shape))
                inst = ctx.scene.geometry.instance
                reservoir["gbuf"].store(rows, s, depth, None if inst is None else inst[s.prim])
                reservoir["res"].assign(rows, res)
        # --- next-event estimation -------------------------------------------------------
        elif not ctx.lights.empty:
            ls = ctx.lights.sample(s.p, rng.random((idx.size, 4), dtype=np.float32))
            wi_l = to_local(ls.wi, s.ns, s.t, s.bt)
            f, pdf_b = eval_bsdf(s.params, s.wo_l, wi_l)
            geo_ok = dot(ls.wi, s.ng) > 0
            w = np.where(ls.delta, 1.0, _power_heuristic(ls.pdf, pdf_b))
            contrib = throughput * f * (np.abs(wi_l[:, 2]) * w / np.maximum(ls.pdf, 1e-30))[:, None] * ls.le
            live = np.flatnonzero(geo_ok & (ls.pdf > 0) & (contrib.max(axis=1) > 0))
            if live.size:
                so, sd, far = shadow_rays(s.p[live], s.ng[live], ls.pos[live], ls.wi[live], ls.dist[live])
                vis = ~ctx.geom_accel.occluded(so, sd, far)
                _accumulate(target, idx[live[vis]], _sanitize(contrib[live[vis]]))
        # --- BSDF sampling (its emission hit still belongs to this bounce's direct light) -------
        u = rng.random((idx.size, 3), dtype=np.float32)
        wi_l, f, pdf = sample_bsdf(s.params, s.wo_l, u[:, 0], u[:, 1], u[:, 2])
        wi = to_world(wi_l, s.ns, s.t, s.bt)
        wi /= np.maximum(norm(wi), 1e-12)[:, None]
        ok = (pdf > 0) & (dot(wi, s.ng) > 0)
        throughput = throughput * f * (wi_l[:, 2] / np.maximum(pdf, 1e-30))[:, None]
        if bounce + 1 >= ctx.rr_start:
            q = np.clip(throughput.max(axis=1), 0.05, 1.0)
            ok &= rng.random(idx.size, dtype=np.float32) < q
            throughput /= q[:, None]
        keep = np.flatnonzero(ok & np.isfinite(throughput).all(axis=1))
        if keep.size == 0:
            break
        idx, throughput, prev_pdf = idx[keep], throughput[keep], pdf[keep]
        o = offset_origin(s.p[keep], s.ng[keep], wi[keep])
        d = wi[keep].astype(np.float32)
        hits = ctx.geom_accel.intersect(o, d)
        # emission found by the BSDF ray: lamps in front of the hit, then the hit itself, else the world
        target = direct if bounce == 0 else indirect
        if len(ctx.scene.lamps.tris) and not ris_here:
            lh = ctx.lamp_accel.intersect(o, d, hits.t)
            sel = np.flatnonzero((lh.prim >= 0) & (lh.t < hits.t))
            if sel.size:
                le, pl = _lamp_emission(ctx, lh, o, d, sel)
                w = _power_heuristic(prev_pdf[sel], pl)
                _accumulate(target, idx[sel], _sanitize(throughput[sel] * le * w[:, None]))
        hit = hits.prim >= 0
        esc = np.flatnonzero(~hit)
        if esc.size:  # film transparency affects camera rays only
            _accumulate(target, idx[esc], _sanitize(throughput[esc] * ctx.scene.world_radiance))
        hsel = np.flatnonzero(hit)
        if hsel.size == 0:
            break
        hp = hits.prim[hsel]
        light = ctx.lights.geom_to_light[hp]
        em = np.flatnonzero(light >= 0)
        if em.size and not ris_here:
            hs = hsel[em]
            le = emitted_radiance(ctx.scene.geometry, ctx.scene.materials, hp[em], hits.u[hs], hits.v[hs])
            cos_l = -dot(d[hs], ctx.geom_ng[hp[em]])
            two = ctx.lights.tri_two_sided[light[em]]
            le = np.where(((cos_l > 0) | two)[:, None], le, 0.0)
            pl = ctx.lights.tri_pdf_solid_angle(light[em], hits.t[hs], cos_l)
            w = _power_heuristic(prev_pdf[hs], pl)
            _accumulate(target, idx[hs], _sanitize(throughput[hs] * le * w[:, None]))
        idx, throughput, prev_pdf = idx[hsel], throughput[hsel], prev_pdf[hsel]
        o, d = o[hsel], d[hsel]
        prim, hu, hv, ht = hits.prim[hsel], hits.u[hsel], hits.v[hsel], hits.t[hsel]

    return _sanitize(emitted), direct, indirect, alpha


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
        s = Surface(ctx, hits.prim[hit], hits.u[hit], hits.v[hit], o[hit], d[hit], hits.t[hit])
        depth[hit] = np.einsum("ij,j->i", s.p - camera_mod.position(cam), camera_mod.forward(cam))
        normal[hit] = s.ns
        motion = ctx.scene.motion
        inst = ctx.scene.geometry.instance
        if motion is not None and inst is not None:
            here = np.stack([x[hit], y[hit]], axis=1)
            for which, cols, sign in (("prev", slice(0, 2), 1.0), ("next", slice(2, 4), -1.0)):
                other_cam = motion.camera_prev if which == "prev" else motion.camera_next
                if other_cam is None:
                    continue
                moved = motion.moved_points(s.p, inst[s.prim], which)
                raster, _z = camera_mod.project(other_cam, moved)
                vector[hit, cols] = sign * (raster - here)
    return depth, normal, np.where(np.isfinite(vector), vector, 0.0).astype(np.float32)


def build_context(scene: Scene, max_bounces: int, film_transparent: bool = False) -> TraceContext:
    geom = scene.geometry
    lamps = scene.lamps
    verts = np.concatenate([geom.verts.reshape(-1, 3), lamps.tris.verts.reshape(-1, 3)])
    finite = verts[np.isfinite(verts).all(axis=1)]
    radius = float(np.linalg.norm(finite.max(0) - finite.min(0)) / 2) if len(finite) else 1.0
    geom_ng, _ = triangle_geometry(geom.verts) if len(geom) else (np.zeros((0, 3), np.float32), None)
    lamp_ng, _ = triangle_geometry(lamps.tris.verts) if len(lamps.tris) else (np.zeros((0, 3), np.float32), None)
    return TraceContext(scene=scene, geom_accel=Accel(geom.verts), lamp_accel=Accel(lamps.tris.verts),
                        lights=LightTable(scene, max(radius, 1e-3)), geom_ng=geom_ng, lamp_ng=lamp_ng,
                        material_params=SurfaceParams.from_material(
                            scene.materials.base_color, scene.materials.metallic, scene.materials.roughness,
                            scene.materials.f0),
                        max_bounces=int(max(0, max_bounces)), film_transparent=film_transparent)
