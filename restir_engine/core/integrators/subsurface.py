"""Subsurface scattering of the Principled BSDF by random walks, as Cycles renders its Random Walk methods.

Where a material has a Subsurface Weight, the subsurface share of the diffuse lobe (SurfaceParams ``sss``, layered
like the diffuse lobe; the BSDF's diffuse lobe leaves it out) is estimated by walks: at the camera's first hits one
walk per hit beside the BSDF (:func:`subsurface_light`), at the paths' later vertices a walk in place of the BSDF
sample, picked with the lobe's share of the albedo (:func:`vertex_walks`). A walk refracts into the mesh, goes
through a homogeneous medium until it crosses the mesh's surface again (leaving it: a walk that meets the surface
from outside, having slipped through it by rounding, is lost), and leaves there through a white Lambertian lobe
(the exit's own material is not evaluated), where it takes next-event estimation and continues as a path.

The medium (per colour channel, scene units): extinction σt and single-scattering albedo α fitted so that a
half-space of it reflects the Base Color (clamped to 1), from the mean free path ``radius`` (Subsurface Radius x
Scale) and the phase function's g (Subsurface Anisotropy):
  WALK_CHIANG        Blender 5.0's Random Walk and 5.2's Random Walk (Legacy): the radius scaled by 1/(4π);
                     α from Wrenninge, Villemin and Hery's fit in g (Chiang, Kutz and Burley 2016 at g = 0);
                     σt = 1/(radius (1 - g)).
  WALK_VAN_DE_HULST  Blender 5.2's Random Walk: the radius as given; α from d'Eon's van de Hulst mapping
                     (A Hitchhiker's Guide to Multiple Scattering, eq. 53.7); σt = 1/radius.
  WALK_SKIN          Random Walk (Skin): the radius scaled by √(3 (1 - α')) with α' the dipole albedo inversion
                     at the Subsurface IOR; α as WALK_CHIANG (van de Hulst where g < 0).
Where α < 0.2 it is raised to 0.2 and the walk's weight scaled by α/0.2. The walk's weight starts at the lobe's
weight over the Base Color (the medium's scattering puts the colour back).

Entry: refraction through a GGX interface of α = Roughness² (Skin: half the walks enter with a cosine lobe, the
other half through α = 1) at the entry's IOR, about a visible normal; no weight. Exit: the first crossing of the
same object's surface; the exit is shaded as a white Lambertian surface whose normal faces out. The walk samples a
channel per step (probability ∝ its weight x α), its free flight from that channel's σt, directions from the
Henyey–Greenstein phase function (isotropic after 9 steps, with σs and σt reduced by (1 - g): the similarity
relation), and weighs each step by the balance heuristic over the three channels; it ends after 256 steps or when
its weight falls below 1e-6. Light is scene-linear RGB.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.accel import offset_origin
from ..lights import groups as light_groups
from ..lights.groups import Tap
from ..materials.subsurface_lobe import lobe_weight
from ..materials.surface import Surface
from ..sampling import cols, cosine_hemisphere, dot, norm, orthonormal_basis, vmax

WALK_NONE, WALK_CHIANG, WALK_VAN_DE_HULST, WALK_SKIN = 0, 1, 2, 3
MAX_STEPS = 256
SIMILARITY_AFTER = 9
MIN_ALPHA = 0.2
WEIGHT_FLOOR = 1e-6
MIN_RADIUS = 1e-8
OTHER_OBJECT_SKIPS = 8  # surfaces of other objects a step may pass through (the walk sees its own mesh only)


def _poly(g, coeffs) -> np.ndarray:
    """Σ c_k g^k."""
    out = np.zeros_like(g)
    for c in reversed(coeffs):
        out = out * g + c
    return out


def chiang_alpha(albedo: np.ndarray, g: np.ndarray) -> np.ndarray:
    """Single-scattering albedo α (3, k) of a medium with phase g (k,) whose half-space reflects ``albedo`` (3, k)
    (Wrenninge, Villemin and Hery's fit; Chiang, Kutz and Burley's at g = 0)."""
    g = np.asarray(g, np.float64)
    a_ = _poly(g, (1.8260523782, -1.28451056436, -1.79904629312, 9.19393289202, -22.8215585862, 32.0234874259,
                   -23.6264803333, 7.21067002658))
    b_ = 4.98511194385 + 0.127355959438 * np.exp(_poly(g, (0.0, 31.1491581433, -201.847017512, 841.576016723,
                                                         -2018.09288505, 2731.71560286, -1935.41424244,
                                                         559.009054474)))
    c_ = _poly(g, (1.09686102424, -0.394704063468, 1.05258115941, -8.83963712726, 28.8643230661, -46.8802913581,
                   38.5402837518, -12.7181042538))
    d_ = _poly(g, (0.496310210422, 0.360146581622, -2.15139309747, 17.8896899217, -55.2984010333, 82.065982243,
                   -58.5106008578, 15.8478295021))
    e_ = 4.23190299701 + 0.00310603949088 * np.exp(_poly(g, (0.0, 76.7316253952, -594.356773233, 2448.8834203,
                                                            -5576.68528998, 7116.60171912, -4763.54467887,
                                                            1303.5318055)))
    f_ = _poly(g, (2.40602999408, -2.51814844609, 9.18494908356, -79.2191708682, 259.082868209, -403.613804597,
                   302.85712436, -87.4370473567))
    a = np.clip(np.asarray(albedo, np.float64), 0.0, 1.0)
    blend = a ** 0.25
    alpha = (1 - blend) * a_ * np.arctan(b_ * a) ** c_ + blend * d_ * np.arctan(e_ * a) ** f_
    return np.clip(alpha, 0.0, 0.999999)


def van_de_hulst_alpha(albedo: np.ndarray, g: np.ndarray) -> np.ndarray:
    """Single-scattering albedo α (3, k) from the half-space albedo (3, k) and g (k,) by d'Eon's van de Hulst
    mapping: s² = (4.20863 c - √(9.59217 + 41.6808 c + 17.7126 c²) + 4.09712)², α = (1 - s²)/(1 - g s²)."""
    c = np.clip(np.asarray(albedo, np.float64), 0.0, 1.0)
    s2 = (4.20863 * c - np.sqrt(9.59217 + 41.6808 * c + 17.7126 * c * c) + 4.09712) ** 2
    den = 1.0 - np.asarray(g, np.float64) * s2
    alpha = np.where(den != 0, (1.0 - s2) / np.where(den != 0, den, 1.0), 0.0)
    return np.clip(alpha, 0.0, 0.999999)


def dipole_radius_scale(albedo: np.ndarray, ior: np.ndarray) -> np.ndarray:
    """√(3 (1 - α')) (3, k): α' the albedo whose dipole diffuse reflectance (Jensen's, with the F_dr fit at ``ior``
    (k,)) is ``albedo`` (3, k), found by 12 bisection steps (0 below 1e-4, 0.999999 from 0.995)."""
    ior = np.asarray(ior, np.float64)
    inv = 1.0 / ior
    f_dr = inv * (-1.440 * inv + 0.710) + 0.668 + 0.0636 * ior
    four_a = (4.0 / 3.0) * (1.0 + f_dr) / (1.0 - f_dr)
    rd = np.asarray(albedo, np.float64)
    lo, hi = np.zeros_like(rd), np.ones_like(rd)
    mid = lo
    for _ in range(12):
        mid = 0.5 * (lo + hi)
        s = np.sqrt(3.0 * (1.0 - mid))
        f = 0.5 * mid * (1.0 + np.exp(-four_a * s)) * np.exp(-s)
        below = f < rd
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    ap = np.where(rd < 1e-4, 0.0, np.where(rd >= 0.995, 0.999999, mid))
    return np.sqrt(3.0 * (1.0 - ap))


@dataclass
class Medium:
    """Per walk (k): extinction ``sigma_t`` and single-scattering albedo ``alpha`` (3, k) (per scene unit), the
    phase function's ``g`` (k,) and the walk's starting weight ``weight`` (3, k)."""

    sigma_t: np.ndarray
    alpha: np.ndarray
    g: np.ndarray
    weight: np.ndarray


def medium(lobe_weight: np.ndarray, albedo: np.ndarray, radius: np.ndarray, g: np.ndarray, method: np.ndarray,
           ior: np.ndarray) -> Medium:
    """The walks' :class:`Medium` from the lobe's weight (3, k) at the entry, the Base Color ``albedo`` (3, k,
    clamped to 1), the mean free path ``radius`` (3, k, scene units), g (k,), the method (k,: WALK_*) and the
    entry's IOR (k,) (Skin's radius adjustment)."""
    albedo = np.clip(np.asarray(albedo, np.float64), 0.0, 1.0)
    r = np.asarray(radius, np.float64).copy()
    method = np.asarray(method)
    g = np.asarray(g, np.float64)
    chiang = method == WALK_CHIANG
    r[:, chiang] *= 0.25 / np.pi
    skin = np.flatnonzero(method == WALK_SKIN)
    if skin.size:
        r[:, skin] *= dipole_radius_scale(albedo[:, skin], ior[skin])
    vdh = (method == WALK_VAN_DE_HULST) | (g < 0)
    alpha = np.where(vdh, van_de_hulst_alpha(albedo, g), chiang_alpha(albedo, g))
    mfp = np.maximum(r, 1e-16)
    sigma_t = np.where(vdh, 1.0 / mfp, 1.0 / (mfp * (1.0 - g)))
    weight = np.where(albedo > 0, np.asarray(lobe_weight, np.float64) / np.where(albedo > 0, albedo, 1.0), 0.0)
    low = alpha < MIN_ALPHA
    weight = np.where(low, weight * alpha / MIN_ALPHA, weight)
    alpha = np.where(low, MIN_ALPHA, alpha)
    return Medium(sigma_t.astype(np.float32), alpha.astype(np.float32), g.astype(np.float32),
                  weight.astype(np.float32))


def _visible_normals(wo_l: np.ndarray, alpha: np.ndarray, u1: np.ndarray, u2: np.ndarray) -> np.ndarray:
    """Isotropic GGX normals (3, k) in the local frame visible from ``wo_l`` (3, k, z > 0), of roughness α (k,)."""
    vx, vy, vz = alpha * wo_l[0], alpha * wo_l[1], wo_l[2]
    ln = np.sqrt(vx * vx + vy * vy + vz * vz)
    vx, vy, vz = vx / ln, vy / ln, vz / ln
    lsq = vx * vx + vy * vy
    inv = np.where(lsq > 0, 1.0 / np.sqrt(np.maximum(lsq, 1e-30)), 0.0)
    t1x, t1y = np.where(lsq > 0, -vy * inv, 1.0), np.where(lsq > 0, vx * inv, 0.0)
    t2x, t2y, t2z = -vz * t1y, vz * t1x, vx * t1y - vy * t1x
    r = np.sqrt(u1)
    phi = 2.0 * np.pi * u2
    p1, p2 = r * np.cos(phi), r * np.sin(phi)
    sw = 0.5 * (1.0 + vz)
    p2 = (1.0 - sw) * np.sqrt(np.maximum(0.0, 1.0 - p1 * p1)) + sw * p2
    pz = np.sqrt(np.maximum(0.0, 1.0 - p1 * p1 - p2 * p2))
    h = np.stack([alpha * (p1 * t1x + p2 * t2x + pz * vx), alpha * (p1 * t1y + p2 * t2y + pz * vy),
                  np.maximum(p2 * t2z + pz * vz, 0.0)])
    return (h / np.maximum(norm(h), 1e-12)).astype(np.float32)


def entry_directions(wo: np.ndarray, ns: np.ndarray, ng: np.ndarray, alpha: np.ndarray, ior: np.ndarray,
                     skin: np.ndarray, u: np.ndarray):
    """Directions (3, k) into the surface from entries seen along ``wo`` (3, k, toward the viewer) with shading and
    geometric normals ``ns``, ``ng`` (3, k, facing the viewer): refraction about a visible GGX normal of roughness α
    (k,) at index ``ior`` (k,); ``skin`` (k,) bool rows enter by a cosine lobe half the time and otherwise through
    α = 1. ``u`` (2, k) uniforms. Returns (directions, ok (k,) bool: the direction goes below the surface)."""
    u0, u1 = u[0].astype(np.float64), u[1]
    diffuse = skin & (u0 < 0.5)
    u0 = np.where(skin, np.where(u0 < 0.5, 2.0 * u0, 2.0 * (u0 - 0.5)), u0)
    a = np.where(skin, 1.0, alpha).astype(np.float32)
    t, b = orthonormal_basis(ns)
    wo_l = np.stack([dot(wo, t), dot(wo, b), dot(wo, ns)])
    front = wo_l[2] > 0
    wo_l[2] = np.maximum(wo_l[2], 1e-6)
    wo_l /= norm(wo_l)
    h_l = _visible_normals(wo_l, a, u0.astype(np.float32), u1)
    h = h_l[0] * t + h_l[1] * b + h_l[2] * ns
    cos_hi = dot(h, wo)
    neta = (1.0 / np.asarray(ior, np.float32)).astype(np.float32)
    arg = 1.0 - neta * neta * (1.0 - cos_hi * cos_hi)
    nk = neta * cos_hi - np.maximum(np.sqrt(np.maximum(arg, 0.0)), 1e-7)
    d = -neta * wo + nk * h
    if diffuse.any():
        rows = np.flatnonzero(diffuse)
        c = cosine_hemisphere(u0[rows].astype(np.float32), u1[rows])
        d[:, rows] = -(c[0] * t[:, rows] + c[1] * b[:, rows] + c[2] * ns[:, rows])
    d = (d / np.maximum(norm(d), 1e-12)).astype(np.float32)
    ok = (front | diffuse) & (dot(ng, d) < 0)
    return d, ok


def _phase_directions(d: np.ndarray, g: np.ndarray, u1: np.ndarray, u2: np.ndarray) -> np.ndarray:
    """Henyey–Greenstein directions (3, k) about the propagation directions ``d`` (3, k) with g (k,)."""
    cos_t = 1.0 - 2.0 * u1
    strong = np.abs(g) >= 1e-3
    if strong.any():
        gs = np.where(strong, g, 1.0)
        k = (1.0 - gs * gs) / (1.0 - gs * cos_t)
        cos_t = np.where(strong, (1.0 + gs * gs - k * k) / (2.0 * gs), cos_t)
    cos_t = np.clip(cos_t, -1.0, 1.0)
    sin_t = np.sqrt(np.maximum(0.0, 1.0 - cos_t * cos_t))
    phi = 2.0 * np.pi * u2
    t, b = orthonormal_basis(d)
    out = (sin_t * np.cos(phi)) * t + (sin_t * np.sin(phi)) * b + cos_t * d
    return (out / np.maximum(norm(out), 1e-12)).astype(np.float32)


@dataclass
class Exits:
    """Walks that left their mesh: ``rows`` (k,) the walks, the exit triangles ``prim`` and barycentrics ``u``,
    ``v`` (k,), the exit points ``p`` and the walks' last directions ``d`` (3, k, outward), and each walk's weight
    ``weight`` (3, k)."""

    rows: np.ndarray
    prim: np.ndarray
    u: np.ndarray
    v: np.ndarray
    p: np.ndarray
    d: np.ndarray
    weight: np.ndarray


def _same_object_hits(ctx, o, d, tmax, obj):
    """The nearest hit (prim, t, u, v) of rays (o, d, up to tmax) on their own object ``obj`` (k,), passing through
    other objects' surfaces (prim -1: none within tmax)."""
    hits = ctx.geom_accel.intersect(o, d, tmax)  # fresh arrays, this function's to change
    prim, t, u, v = hits.prim, hits.t, hits.u, hits.v
    inst = ctx.scene.geometry.instance
    if inst is None:
        return prim, t, u, v
    for _ in range(OTHER_OBJECT_SKIPS):
        other = np.flatnonzero((prim >= 0) & (inst[np.maximum(prim, 0)] != obj))
        if other.size == 0:
            return prim, t, u, v
        dd = cols(d, other)
        start = cols(o, other) + dd * t[other]
        step = np.maximum(vmax(np.abs(start)), np.float32(1.0)) * np.float32(1e-4)
        h = ctx.geom_accel.intersect(start + dd * step, dd, tmax[other] - t[other] - step)
        prim[other] = h.prim
        t[other] = np.where(h.prim >= 0, t[other] + step + h.t, np.inf)
        u[other], v[other] = h.u, h.v
    prim[(prim >= 0) & (inst[np.maximum(prim, 0)] != obj)] = -1
    return prim, t, u, v


def _uniform_directions(u1: np.ndarray, u2: np.ndarray) -> np.ndarray:
    """Directions (3, k) uniform over the sphere (the isotropic phase function)."""
    z = 1.0 - 2.0 * u1
    r = np.sqrt(np.maximum(0.0, 1.0 - z * z))
    phi = np.float32(2.0 * np.pi) * u2
    return np.stack([r * np.cos(phi), r * np.sin(phi), z]).astype(np.float32)


def walk(ctx, p: np.ndarray, ng: np.ndarray, d: np.ndarray, obj: np.ndarray, med: Medium,
         rng: np.random.Generator) -> Exits:
    """Random walks from entry points ``p`` (3, k) (geometric normals ``ng`` facing out) along entry directions
    ``d`` (3, k) through the media ``med`` of objects ``obj`` (k,), until each crosses its object's surface. The
    walks' state is kept compacted to the walks still going."""
    k = p.shape[1]
    ss_ = med.sigma_t * med.alpha
    state = {"id": np.arange(k), "pos": offset_origin(p, ng, d), "dir": d.copy(), "w": med.weight.copy(),
             "st": med.sigma_t, "ss": ss_, "st2": med.sigma_t - ss_ * med.g, "ss2": ss_ * (1.0 - med.g),
             "alpha": med.alpha, "g": med.g, "obj": obj}
    isotropic = not bool(np.any(np.abs(med.g) >= 1e-3))
    out = []
    for step in range(MAX_STEPS):
        m = state["id"].size
        if m == 0:
            break
        u = rng.random((4, m), dtype=np.float32)
        late = step > SIMILARITY_AFTER
        st, ss = (state["st2"], state["ss2"]) if late else (state["st"], state["ss"])
        if step > 0:
            state["dir"] = _uniform_directions(u[2], u[3]) if isotropic or late else \
                _phase_directions(state["dir"], state["g"], u[2], u[3])
        w, dr, o = state["w"], state["dir"], state["pos"]
        cp = np.abs(w) * state["alpha"]
        tot = cp.sum(axis=0)
        cp = np.where(tot > 0, cp / np.where(tot > 0, tot, 1.0), np.float32(1.0 / 3.0)).astype(np.float32)
        ch = (u[0] >= cp[0]).astype(np.intp) + (u[0] >= cp[0] + cp[1])
        sig = st[ch, np.arange(m)]
        dist = (-np.log1p(-np.minimum(u[1], np.float32(1 - 1e-7))) / np.maximum(sig, 1e-30)).astype(np.float32)
        prim, th, hu, hv = _same_object_hits(ctx, o, dr, dist, state["obj"])
        hit = (prim >= 0) & (th < dist)
        # a crossing into the mesh (the walk slipped out through a surface it started on, by rounding) ends it
        lost = hit & (dot(cols(ctx.geom_ng_rows, np.maximum(prim, 0)), dr) < 0)
        hit &= ~lost
        dist = np.where(hit, th, dist).astype(np.float32)
        state["pos"] = o + dr * dist
        tr = np.exp(-st * dist)
        pdf = (cp * np.where(hit, tr, st * tr)).sum(axis=0)
        w = w * np.where(hit, tr, ss * tr) / np.maximum(pdf, 1e-30)
        state["w"] = w
        done = np.flatnonzero(hit)
        if done.size:
            out.append((state["id"][done], prim[done], hu[done], hv[done], cols(state["pos"], done), cols(dr, done),
                        cols(w, done)))
        keep = np.flatnonzero(~hit & ~lost & (vmax(w) >= WEIGHT_FLOOR) & np.isfinite(w).all(axis=0))
        if keep.size < m:
            state = {key: (a[keep] if a.ndim == 1 else np.take(a, keep, axis=1)) for key, a in state.items()}
    if not out:
        z = np.zeros(0, np.int64)
        e3 = np.zeros((3, 0), np.float32)
        return Exits(z, z, np.zeros(0, np.float32), np.zeros(0, np.float32), e3, e3.copy(), e3.copy())
    cat = [np.concatenate([part[i] for part in out], axis=-1) for i in range(7)]
    order = np.argsort(cat[0], kind="stable")
    cat = [c[..., order] for c in cat]
    return Exits(*cat)


def walkable_rows(ctx, surf) -> np.ndarray:
    """The surfaces (indices) that keep a subsurface share of a walked method."""
    if not ctx.has_subsurface or not surf.params.has_subsurface():
        return np.zeros(0, np.int64)
    rows = np.flatnonzero(vmax(surf.params.sss) > 0)
    return rows[ctx.scene.materials.sss_method[surf.bsdf_mat[rows]] > 0]


@dataclass
class WalkExits:
    """Walks from surfaces that left their mesh: ``at`` (k,) the walks' indices among the surfaces walked, ``surf``
    the exits (a white Lambertian Surface, k) and ``weight`` (3, k) each walk's weight, the lobe's weight included."""

    at: np.ndarray
    surf: Surface
    weight: np.ndarray


def walk_from(ctx, surf, rows: np.ndarray, lobe_w: np.ndarray, rng: np.random.Generator) -> WalkExits | None:
    """One walk from each surface ``rows`` of ``surf`` whose lobe weighs ``lobe_w`` (3, k): entry, walk, exit
    (:class:`WalkExits`, or None where none left its mesh)."""
    mats = ctx.scene.materials
    mat = surf.bsdf_mat[rows]
    method = mats.sss_method[mat]
    params = surf.params.take(rows)
    ior = mats.sss_ior[mat]
    med = medium(lobe_w, params.sss_albedo, mats.sss_radius[mat].T, mats.sss_anisotropy[mat], method, ior)
    u = rng.random((2, rows.size), dtype=np.float32)
    d, ok = entry_directions(cols(surf.wo, rows), cols(surf.ns, rows), cols(surf.ng, rows), params.alpha, ior,
                             method == WALK_SKIN, u)
    inst = ctx.scene.geometry.instance
    obj = np.zeros(rows.size, np.int64) if inst is None else inst[surf.prim[rows]].astype(np.int64)
    start = np.flatnonzero(ok)
    if start.size == 0:
        return None
    sub = Medium(cols(med.sigma_t, start), cols(med.alpha, start), med.g[start], cols(med.weight, start))
    ex = walk(ctx, cols(surf.p, rows[start]), cols(surf.ng, rows[start]), cols(d, start), obj[start], sub, rng)
    if ex.rows.size == 0:
        return None
    o = ex.p + ex.d * np.float32(1e-3)  # the exit seen from outside, as Cycles shades it
    s = Surface(ctx, ex.prim, ex.u, ex.v, o, -ex.d, np.full(ex.rows.size, 1e-3, np.float32), lambert=True)
    return WalkExits(start[ex.rows], s, ex.weight)


@dataclass
class SubsurfaceLight:
    """Light the walks from surfaces ``rows`` (k,) bring back: ``direct`` (3, k) at their exits (next-event
    estimation and the exit's BSDF ray's emitter hits), ``indirect`` (3, k) the paths' bounces after the exit; with
    light groups the same by group (G, 3, k), else None."""

    rows: np.ndarray
    direct: np.ndarray
    indirect: np.ndarray
    direct_g: np.ndarray | None = None
    indirect_g: np.ndarray | None = None


def subsurface_light(ctx, surf, rng: np.random.Generator, continue_paths, budget=None) -> SubsurfaceLight | None:
    """One walk per surface of ``surf`` (the camera's first hits) with a subsurface share, beside their BSDF, and
    the light its exit gathers (next_event + ``continue_paths``, pathtracer's). None where no surface has one."""
    from .pathtracer import next_event
    rows = walkable_rows(ctx, surf)
    if rows.size == 0:
        return None
    k = rows.size
    direct, indirect = np.zeros((3, k), np.float32), np.zeros((3, k), np.float32)
    direct_g, indirect_g = light_groups.zeros(ctx.groups, k), light_groups.zeros(ctx.groups, k)
    ex = walk_from(ctx, surf, rows, lobe_weight(surf, rows), rng)
    if ex is not None:
        at, w = ex.at, ex.weight
        g = ctx.groups is not None
        direct[:, at] += next_event(ctx, ex.surf, rng, w, taps=(Tap(direct_g, at),) if g else ())
        out = continue_paths(ctx, ex.surf, rng, budget=None if budget is None else budget[rows[at]])
        direct[:, at] += out.direct * w
        indirect[:, at] += out.indirect * w
        if g:
            direct_g[:, :, at] += out.direct_g * w
            indirect_g[:, :, at] += out.indirect_g * w
    return SubsurfaceLight(rows, direct, indirect, direct_g, indirect_g)


@dataclass
class VertexWalks:
    """At a path vertex after the first (n surfaces): the surfaces that chose their subsurface lobe ``walking``
    ((n,) bool), the factor ``bsdf_scale`` (n,) of the others' BSDF samples (1/(1 - P(walk))), and the walks that
    left their mesh (:class:`WalkExits`, ``exits.at`` indexing ``rows``, the walking surfaces), their weight divided
    by P(walk)."""

    walking: np.ndarray
    bsdf_scale: np.ndarray
    rows: np.ndarray
    exits: WalkExits | None


def vertex_walks(ctx, surf, rng: np.random.Generator) -> VertexWalks | None:
    """Pick, at each surface with a subsurface share, its subsurface lobe or its BSDF, with probability P(walk) =
    the lobe's share of the surface's albedo toward the viewer (0.05..0.95 where the BSDF reflects too), and walk
    the chosen (as Cycles picks a closure). None where no surface has a share."""
    from ..materials.denoising_albedo import denoising_albedo
    from ..materials.params import luminance_rows
    cand = walkable_rows(ctx, surf)
    if cand.size == 0:
        return None
    lw = lobe_weight(surf, cand)
    a = luminance_rows(lw)
    b = np.maximum(luminance_rows(denoising_albedo(surf.take(cand))) - a, 0.0)
    p = np.where(a + b > 0, a / np.maximum(a + b, 1e-12), 0.0)
    p = np.where(b > 0, np.clip(p, 0.05, 0.95), p).astype(np.float32)
    go = rng.random(cand.size, dtype=np.float32) < p
    n = len(surf)
    walking = np.zeros(n, bool)
    walking[cand[go]] = True
    scale = np.ones(n, np.float32)
    scale[cand[~go]] = 1.0 / (1.0 - p[~go])
    rows = cand[go]
    exits = walk_from(ctx, surf, rows, lw[:, go] / p[go], rng) if rows.size else None
    return VertexWalks(walking, scale, rows, exits)


def with_exit_rays(ray, surf, walks: VertexWalks, u: np.ndarray):
    """The BSDF rays ``ray`` (pathtracer.BsdfRay from ``surf``) without the walking surfaces' (the others' weighed by
    1/(1 - P(walk))), and one cosine-sampled ray from each walk's exit, weighed by the walk (its ``walked`` rows
    True, ``origin_n`` the exits' normals). ``u`` (2, len(walks.rows)) uniforms."""
    from .pathtracer import BsdfRay
    keep = np.flatnonzero(~walks.walking[ray.rows])
    rows = ray.rows[keep]
    f = cols(ray.f, keep) * walks.bsdf_scale[rows]
    parts = [(rows, cols(ray.wi_l, keep), f, ray.pdf[keep], cols(ray.o, keep), cols(ray.d, keep),
              np.zeros(keep.size, bool) if ray.delta is None else ray.delta[keep], np.zeros(keep.size, bool),
              cols(surf.ns, rows))]
    ex = walks.exits
    if ex is not None:
        s = ex.surf
        wi_l = cosine_hemisphere(u[0, ex.at], u[1, ex.at])
        wi = wi_l[0] * s.t + wi_l[1] * s.bt + wi_l[2] * s.ns
        wi = (wi / np.maximum(norm(wi), 1e-12)).astype(np.float32)
        up = np.flatnonzero(dot(wi, s.ng) > 0)
        pdf = (wi_l[2, up] / np.float32(np.pi)).astype(np.float32)
        d = cols(wi, up)
        parts.append((walks.rows[ex.at[up]], cols(wi_l, up), cols(ex.weight, up) / np.float32(np.pi), pdf,
                      offset_origin(cols(s.p, up), cols(s.ng, up), d), d, np.zeros(up.size, bool),
                      np.ones(up.size, bool), cols(s.ns, up)))
    cat = [np.concatenate([p[i] for p in parts], axis=-1) for i in range(9)]
    out = BsdfRay(cat[0], cat[1], cat[2], cat[3], cat[4], cat[5], delta=cat[6] if ray.delta is not None else None)
    out.walked, out.origin_n = cat[7], cat[8]
    return out
