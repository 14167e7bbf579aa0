"""ReSTIR GI (Ouyang et al. 2021): reservoirs over secondary surface points, initial samples and shading.

A sample is a point x2 on a surface (position, unit geometric normal n2 facing the side the light leaves
from) with the radiance Lo (RGB, W·sr⁻¹·m⁻², scene-linear) leaving it toward the primary surface x1 that
found it, estimated by the rest of a path (next-event estimation at x2 and further bounces).

Everything is in AREA measure on the secondary surfaces, exactly like ReSTIR DI with x2 as a light point of
radiance Lo: the target at a primary surface x1 is
  p̂(x2) = luminance(f(ωo, ωi) · Lo) · |cos θ1| · cos φ2 / d²       (0 where x2 faces away from x1)
(target.ShadingTerms.evaluate, the full material at x1), and a reservoir's W is in m². Shifting a sample to
another pixel keeps x2 (the reconnection shift); in solid angle its Jacobian is
  |J| = (cos φ_q / cos φ_r) · (|x1_r − x2|² / |x1_q − x2|²)          (r: the pixel that made the sample,
                                                                      q: the pixel receiving it)
(:func:`reconnection_jacobian`). An area-measure W already contains it: W_ω at q = W_area · cos φ_q / d_q²
= W_ω at r · |J|, so reuse.py merges GI reservoirs unchanged and no Jacobian is applied anywhere.

Caching Lo assumes x2 reflects the same radiance toward every receiver (Lambertian). So the path splits the
light leaving x2 by lobe (pathtracer.FirstBounce.lo_d: the same light samples weighed by x2's diffuse lobe
alone): only that diffuse part is cached and reused; the specular part (all of it on metals) goes to the pixel
as the path traced it. The split is exact; the one approximation left is the Principled diffuse lobe's layering
weight at x2 (one minus the specular layer's albedo toward the viewer), taken at the direction the sample was made
for (Diffuse BSDF: exact; at roughness 1 the weight varies by ~4 % over the hemisphere). At a glossy x1
(roughness below the threshold) the reservoirs resample the diffuse lobe only and the specular lobe keeps the
path-traced sample: f = f_d + f_s splits the integral exactly there too.

Unbiased reuse (pairwise MIS) needs the neighbour's target at the canonical sample to be zero where the
neighbour could not have found it: a shadow ray from the neighbour's x1 to the sample (``evaluate_mis``).

Reservoir memory per pixel: age int16 (-1 = empty), x2 3 x float32, n2 3 x float16, Lo 3 x float32, M, W, p̂
float32 = 44 bytes.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.accel import shadow_rays
from ..lights.tiles import PackedPoints
from ..materials.bsdf import diffuse_f, eval_view
from ..modes import IndirectMethod, values
from ..sampling import cols, dot, finite, norm, to_local, vmax
from .reservoir import Reservoirs
from .target import LUM as _LUM

INDIRECT_METHODS = values(IndirectMethod)  # AUTO: core/integrators/method_choice.py
GI_TARGETS = ("INTEGRAND", "RADIANCE")  # p̂ = lum(f · Lo) |cos θ1| G  or  lum(Lo) G (compared in docs/RESULTS.md)
JACOBIAN_LIMIT = 10.0  # biased mode: shifts whose |J| is outside [1/10, 10] are rejected (as RTXDI's sample app)


class GIReservoirs(Reservoirs):
    """age int16 (frames since the sample was made; -1 = empty), x2 (x, y, z), its normal (nx, ny, nz, float16),
    Lo (lr, lg, lb); M, W (m²), p̂. With light groups (:func:`reservoir_kind`) a sample also carries its Lo by
    group (g<k>r, g<k>g, g<k>b for group k: lights/groups.py), resampled and reused with it."""

    SAMPLE = {"age": np.int16, "x": np.float32, "y": np.float32, "z": np.float32, "nx": np.float16,
              "ny": np.float16, "nz": np.float16, "lr": np.float32, "lg": np.float32, "lb": np.float32}
    groups = 0  # light groups whose Lo the samples carry

    def group_lo(self, rows) -> np.ndarray:
        """(G, 3, k) the Lo by light group of reservoirs ``rows``."""
        return np.stack([np.stack([getattr(self, f"g{k}{c}")[rows] for c in "rgb"]) for k in range(self.groups)])

    def set_group_lo(self, rows, lo_g: np.ndarray) -> None:
        """Reservoirs ``rows`` get the Lo by light group ``lo_g`` (G, 3, k)."""
        for k in range(self.groups):
            for i, c in enumerate("rgb"):
                getattr(self, f"g{k}{c}")[rows] = lo_g[k, i]


_KINDS = {0: GIReservoirs}


def reservoir_kind(groups: int) -> type:
    """The GI reservoir class whose samples carry their Lo by ``groups`` light groups (GIReservoirs for none)."""
    kind = _KINDS.get(groups)
    if kind is None:
        fields = {f"g{k}{c}": np.float32 for k in range(groups) for c in "rgb"}
        kind = type(f"GIReservoirs{groups}", (GIReservoirs,), {"SAMPLE": {**GIReservoirs.SAMPLE, **fields},
                                                                "groups": groups, "__module__": __name__})
        _KINDS[groups] = kind
    return kind


def __getattr__(name: str):
    """The grouped reservoir classes by name (GIReservoirs<G>), for pickles made in another process."""
    if name.startswith("GIReservoirs") and name[len("GIReservoirs"):].isdigit():
        return reservoir_kind(int(name[len("GIReservoirs"):]))
    raise AttributeError(name)


@dataclass
class GISettings:
    """ReSTIR GI stages: spatial neighbours / radius (pixels, 0 = automatic) / passes, confidence cap (the
    largest M a reused reservoir keeps), max sample age (frames), roughness threshold (below it x1 resamples its
    diffuse lobe only; its specular lobe keeps the path-traced sample)."""

    neighbors: int = 3
    radius: float = 0.0
    passes: int = 4  # spatial passes per sample (the choice: docs/RESULTS.md, "ReSTIR GI")
    confidence_cap: float = 20.0
    max_age: int = 30
    roughness_threshold: float = 0.3


def reconnection_jacobian(x1_from: np.ndarray, x1_to: np.ndarray, x2: np.ndarray, n2: np.ndarray) -> np.ndarray:
    """|J| (n,) of moving a sample x2 (normal n2) from the receiver x1_from to the receiver x1_to (all (3, n)):
    dω_to / dω_from = (cos φ_to / cos φ_from) · (|x1_from − x2|² / |x1_to − x2|²), φ the angle at x2 between
    n2 and the direction to the receiver; 0 where it is not finite."""
    a = x1_from - x2
    b = x1_to - x2
    da, db = dot(a, a), dot(b, b)
    cos_a = np.abs(dot(a, n2)) / np.sqrt(np.maximum(da, 1e-30))
    cos_b = np.abs(dot(b, n2)) / np.sqrt(np.maximum(db, 1e-30))
    with np.errstate(divide="ignore", invalid="ignore"):
        j = (cos_b / cos_a) * (da / db)
    return np.where(np.isfinite(j), j, 0.0).astype(np.float32)


def glossy_x1(params, threshold: float) -> np.ndarray:
    """(n,) bool: primary surfaces whose specular lobe is too sharp to reconnect (roughness² = α below
    threshold², with a specular lobe)."""
    return (params.alpha < np.float32(threshold) ** 2) & (params.spec_on > 0)


def diffuse_only(terms, glossy: np.ndarray):
    """The target terms with the specular lobe switched off where ``glossy`` (in place: spec_on row)."""
    if glossy.any():
        terms.spec_on[glossy] = 0.0
        terms.glossy = bool((terms.spec_on > 0).any())
    return terms


def radiance_target(terms, pts: PackedPoints) -> np.ndarray:
    """The alternative target lum(Lo) · cos φ2 / d² (area measure), zero where f · cos θ1 is (below x1's horizon)
    or x2 faces away: the BSDF at x1 left out."""
    d = pts.pos - terms.p
    d2 = np.maximum(dot(d, d), np.float32(1e-30))
    cl = -dot(d, pts.normal)
    ok = (dot(d, terms.ns) > 0) & (dot(d, terms.ng) > 0) & (cl > 1e-8 * np.sqrt(d2))
    lum = np.abs(_LUM[0] * pts.le[0] + _LUM[1] * pts.le[1] + _LUM[2] * pts.le[2])  # negative lights: |Lo|
    return (lum * cl / (d2 * np.sqrt(d2)) * ok).astype(np.float32)


def initial(first, terms, n: int, glossy: np.ndarray, space=None):
    """One GI reservoir per primary surface (n) from its first bounce (pathtracer.FirstBounce), and the part of
    the path-traced indirect light (3, n) the reservoirs do not carry: the light x2's specular lobe sent, and the
    specular lobe at glossy x1 (``glossy`` (n,) bool). ``terms``: the GI target terms of the n surfaces (specular
    lobe off where glossy). A reservoir holds its one candidate, x2 with its diffuse light lo_d: M = 1,
    W = 1 / p_area with p_area = p_ω · cos φ2 / d² the pdf of x2 in area measure. With light groups (``first.lo_g``)
    the reservoirs carry lo_d by group, and the rest comes by group too: (reservoirs, rest, rest by group (G, 3, n)
    or None)."""
    groups = 0 if first.lo_g is None else len(first.lo_g)
    res = reservoir_kind(groups).empty(n)
    res.M[:] = 1.0
    rest = np.zeros((3, n), np.float32)
    rest_g = np.zeros((groups, 3, n), np.float32) if groups else None
    rows = first.rows
    if rows.size == 0:
        return res, rest, rest_g
    lo_d = first.lo_d
    lo_d_g = first.lo_d_g
    if first.tint is not None:  # the reservoir holds the light that reached x1 through the transparent tints
        lo_d = lo_d * first.tint
        lo_d_g = None if lo_d_g is None else lo_d_g * first.tint
    here = terms.take(rows)
    pts = PackedPoints(first.p, first.n2, lo_d, np.zeros(len(rows), np.float32), np.zeros(len(rows), bool))
    p_hat = (space or GISpace()).evaluate(here, pts)
    d = first.p - here.p
    d2 = dot(d, d)
    cos2 = -dot(d, first.n2) / np.sqrt(np.maximum(d2, 1e-30))
    p_area = first.pdf * cos2 / np.maximum(d2, 1e-30)
    ok = (p_hat > 0) & (p_area > 0)
    # what the reservoir does not carry: x2's specular light, all of a sample it cannot hold, x1's specular lobe
    carried = first.throughput * ok
    g = glossy[rows] & ok
    if g.any():
        kd_t = here.kd[:, g] / _LUM[:, None]          # f_d = kd (the terms hold kd · luminance weights)
        ci = np.maximum(dot(cols(d, np.flatnonzero(g)), cols(here.ns, np.flatnonzero(g))), 0.0) / \
            np.sqrt(np.maximum(d2[g], 1e-30))
        carried[:, g] = kd_t * (ci / np.maximum(first.pdf[g], 1e-30))
        if first.tint is not None:
            carried[:, g] *= first.tint[:, g]
    rest[:, rows] = finite(first.throughput * (first.lo - first.lo_d) + (first.throughput - carried) * first.lo_d)
    if groups:
        rest_g[:, :, rows] = finite(first.throughput * (first.lo_g - first.lo_d_g) +
                                    (first.throughput - carried) * first.lo_d_g)
    sel = np.flatnonzero(ok)
    r = rows[sel]
    res.age[r] = 0
    res.x[r], res.y[r], res.z[r] = first.p[0, sel], first.p[1, sel], first.p[2, sel]
    res.nx[r], res.ny[r], res.nz[r] = first.n2[0, sel], first.n2[1, sel], first.n2[2, sel]
    res.lr[r], res.lg[r], res.lb[r] = lo_d[0, sel], lo_d[1, sel], lo_d[2, sel]
    res.p_hat[r] = p_hat[sel]
    res.W[r] = 1.0 / p_area[sel]
    if groups:
        res.set_group_lo(r, lo_d_g[:, :, sel])
    return res, rest, rest_g



def _points(res: GIReservoirs, idx=None) -> np.ndarray:
    """(11, n) packed points (target.PackedPoints rows) of reservoirs ``idx`` (all when None)."""
    take = (lambda a: a) if idx is None else (lambda a: a[idx])
    n = len(res) if idx is None else len(take(res.x))
    out = np.zeros((11, n), np.float32)
    for i, name in enumerate(("x", "y", "z", "nx", "ny", "nz", "lr", "lg", "lb")):
        out[i] = take(getattr(res, name))
    return out


class GISpace:
    """GI samples for the generic reuse code (reuse.py): points x2 with radiance Lo, the DI target function.
    ``accel``: the geometry (visibility of the neighbours' primary hits in the unbiased mode; None: no rays)."""

    kind = GIReservoirs

    def __init__(self, accel=None, target: str = "INTEGRAND", groups: int = 0):
        if target not in GI_TARGETS:
            raise ValueError(f"unknown GI target {target!r}; available: {GI_TARGETS}")
        self.accel = accel
        self.target_kind = target
        self.kind = reservoir_kind(groups)  # the reservoirs' class (their samples' Lo by ``groups`` light groups)

    @staticmethod
    def prepare(res: GIReservoirs, spans=None, team=None) -> np.ndarray:
        """The reservoirs' packed points (by ``team``'s processes, span by span, where given)."""
        if team is None or team.size == 1:
            return _points(res)
        out = team.empty((11, len(res)), np.float32)
        for i, sl in enumerate(spans):
            if team.owns(i):
                out[:, sl] = _points(res, sl)
        team.barrier()
        return out

    @staticmethod
    def gather(prepared: np.ndarray, idx) -> PackedPoints:
        return PackedPoints.of(prepared[:, idx] if isinstance(idx, slice) else np.take(prepared, idx, axis=1))

    def evaluate(self, terms, pts: PackedPoints) -> np.ndarray:
        if self.target_kind == "RADIANCE":
            return radiance_target(terms, pts)
        return terms.evaluate(pts, want_pdf=False)[0]

    @staticmethod
    def shift_ok(p_to: np.ndarray, p_from: np.ndarray, pts: PackedPoints) -> np.ndarray:
        """Biased mode: (n,) bool, the reconnection Jacobian of moving samples ``pts`` from primary hits p_from to
        p_to lies in [1 / JACOBIAN_LIMIT, JACOBIAN_LIMIT]. Without it the 1/M merge turns samples made far
        from x2 into fireflies next to it (the pairwise MIS weights of the unbiased mode handle them)."""
        j = reconnection_jacobian(p_from, p_to, pts.pos, pts.normal)
        return (j <= JACOBIAN_LIMIT) & (j >= np.float32(1.0 / JACOBIAN_LIMIT))

    def evaluate_mis(self, terms, pts: PackedPoints) -> np.ndarray:
        """p̂ with visibility: zero where the surfaces ``terms`` cannot see the sample (they could not have
        found it, so their technique must get no MIS weight for it)."""
        p = self.evaluate(terms, pts)
        live = np.flatnonzero(p > 0)
        if live.size and self.accel is not None:
            p[live[~visible(self.accel, cols(terms.p, live), cols(terms.ng, live), cols(pts.pos, live),
                            cols(pts.normal, live))]] = 0.0
        return p


def visible(accel, p: np.ndarray, ng: np.ndarray, x2: np.ndarray, n2: np.ndarray) -> np.ndarray:
    """(n,) bool: whether the primary surfaces (p, ng) see the points x2 (normals n2, facing them) unoccluded."""
    q = x2 + n2 * np.float32(1e-4) * np.maximum(np.abs(x2).max(axis=0), np.float32(1.0))
    wi = q - p
    dist = norm(wi)
    wi = wi / np.maximum(dist, np.float32(1e-30))
    o, d, far = shadow_rays(p, ng, q, wi, dist)
    return ~accel.occluded(o, d, far)


def clear_occluded(accel, terms, res: GIReservoirs) -> GIReservoirs:
    """The reservoirs (of surfaces ``terms``) with every sample their surface cannot see emptied (M kept), in
    place. Run after each merge of the unbiased mode: a reservoir then only ever holds samples its own surface
    sees, the domain its technique is credited with in the neighbours' MIS weights (``GISpace.evaluate_mis``).
    Without it a sample passed on by an earlier spatial pass could be invisible to the surface holding it and the
    MIS weights of later passes summed to more than one (biased bright; docs/RESULTS.md, "ReSTIR GI"). The
    estimate is unchanged otherwise: an occluded sample contributes nothing when shaded."""
    live = np.flatnonzero(res.has_sample())
    if live.size:
        pts = _points(res, live)
        vis = visible(accel, cols(terms.p, live), cols(terms.ng, live), pts[0:3], pts[3:6])
        res.clear(live[~vis])
    return res


def shade(accel, surf, res: GIReservoirs, glossy: np.ndarray, verified: bool = False, sums=None) -> np.ndarray:
    """Indirect radiance (3, n) at the primary surfaces ``surf`` from their GI reservoirs: f · Lo · |cos θ1| ·
    cos φ2 / d² · V · W with one shadow ray (f the diffuse lobe only where ``glossy``), none when the samples are
    ``verified`` visible (:func:`clear_occluded`); with light groups also f · Lo_group · ... into ``sums``
    (G, 3, n)."""
    n = len(surf)
    out = np.zeros((3, n), np.float32)
    live = np.flatnonzero(res.has_sample() & (res.W > 0))
    if live.size == 0:
        return out
    sub = surf if live.size == n else surf.take(live)
    pts = _points(res, live)
    x2, n2, lo = pts[0:3], pts[3:6], pts[6:9]
    p = sub.p
    d = x2 - p
    dist = norm(d)
    wi = d / np.maximum(dist, np.float32(1e-30))
    cos2 = -dot(wi, n2)
    wi_l = to_local(wi, sub.ns, sub.t, sub.bt)
    f, _pdf = eval_view(sub.view, sub.wo_l, wi_l)
    g = glossy[live]
    if g.any():
        gr = np.flatnonzero(g)
        f[:, gr] = diffuse_f(sub.view, cols(wi_l, gr), gr)
    ok = (cos2 > 0) & (dot(wi, sub.ng) > 0)
    scale = np.abs(wi_l[2]) * cos2 / np.maximum(dist * dist, np.float32(1e-30)) * res.W[live] * ok
    contrib = f * lo
    contrib *= scale
    go = np.flatnonzero(vmax(np.abs(contrib)) > 0)
    if go.size:
        if not verified:
            go = go[visible(accel, cols(p, go), cols(sub.ng, go), cols(x2, go), cols(n2, go))]
        out[:, live[go]] = cols(contrib, go)
        if sums is not None and res.groups:
            sums[:, :, live[go]] += finite(res.group_lo(live[go]) * cols(f, go) * scale[go])
    return finite(out)


def age_history(res: GIReservoirs, max_age: int) -> GIReservoirs:
    """The reservoirs as next frame's history: every sample one frame older, those older than ``max_age``
    dropped (a copy; confidence M kept)."""
    out = res.replace(age=res.age.copy(), W=res.W.copy(), p_hat=res.p_hat.copy())
    has = out.has_sample()
    out.age[has] += 1
    out.clear(has & (out.age > max_age))
    return out
