"""The ReSTIR DI target function p̂ with per-surface terms computed once and reused for every candidate.

For a surface point x (shading normal n_s, geometric normal n_g, view direction ωo in world space) and a
light point y (position, unit normal n_l, radiance Le), in area measure on the lights:
  p̂(y) = |luminance(f(ωo, ωi) · Le)| · |cos θ_s| |cos θ_l| / d²    (0 below the geometric horizon,
                                                                     at a back face of a one-sided light)
  p_b(y) = p_b,ω(ωi | ωo) · |cos θ_l| / d²                            (the BSDF sampling pdf, area measure)
with f the Principled model of bsdf.py. Because luminance is linear, luminance(f · Le) splits into
  Le · k_d  +  S(ωi) · (Le · A + (1 - ωo·h)⁵ · Le · B + max(F(ωo·h) - f0, 0) · Le · C)
where k_d, A, B and C are per-surface RGB vectors (luminance weights folded in), S is the scalar
D·G/(4 cos θ_o cos θ_i) of the GGX lobes and F the exact dielectric Fresnel (η² - 1 and f0 per-surface rows); only S
and the Fresnel terms depend on the candidate. The absolute value makes a light of negative power (Cycles subtracts
its light) a candidate like any other; the estimate f · Le · W keeps its sign. A metal's Specular Tint (F82 term) is
left out of p̂: p̂ then overestimates a tinted metal's grazing reflection a little, which costs variance, not bias. The half
vector is never formed: with unit ωo, ωi, |ωo + ωi|² = 2 + 2 ωo·ωi, cos θ_h = (cos θ_o + cos θ_i)/|ωo + ωi|
and ωo·h = (1 + ωo·ωi)/|ωo + ωi|. Agrees with bsdf.eval_bsdf to float32 rounding (tested). At anisotropic surfaces
p̂ is the isotropic lobe of the same α = √(αx αy) (positive wherever the anisotropic one is: unbiased, with the
variance of a less exact target), while the BSDF pdf, which weighs the BSDF candidates against the light candidates,
is the anisotropic one the BSDF sampler draws from (``aniso``, for the surfaces of the initial resampling).

Layout: structure of arrays. Terms are a (32, n) float32 block (:data:`LAYOUT` rows), light points a
(11, ...) block (light_tiles.PackedPoints); the candidate axis broadcasts, so p̂ of m candidates at n
surfaces is one pass over (m, n) arrays. In a scene with anisotropic or sheen materials the block has ANISO_WIDTH
rows: the specular lobes' αx, αy and tangent X (world) follow (:data:`ANISO_LAYOUT`; αx = αy = α and X any tangent
where a surface is isotropic), and p̂'s D and Smith Λ(ωi) are the anisotropic GGX's (core/materials/anisotropy.py)
about the shading normal (the BSDF's bent specular normal, where it differs, only in the BSDF itself and in the pdf);
then a sheen surface's roughness (:data:`SHEEN_ROW`), whose diffuse term takes its light factor R(μi)
(core/materials/sheen.py), so p̂ is the sheen lobe's own.
"""
from __future__ import annotations

import numpy as np

from ..lights.receiver import receiver_factor
from ..lights.tiles import PackedPoints, light_points
from ..materials.anisotropy import AnisoWorld
from ..materials.bsdf import view_terms
from ..materials.microfacet import fresnel_exact, half_vector_terms
from ..materials.sheen import albedo
from ..parallel.pool import in_worker, pool
from ..sampling import to_world

LUM = np.array([0.2126, 0.7152, 0.0722], np.float32)
INV_PI = np.float32(1.0 / np.pi)

LAYOUT = {"p": slice(0, 3), "ng": slice(3, 6), "ns": slice(6, 9), "wo": slice(9, 12), "kd": slice(12, 15),
          "a": slice(15, 18), "b": slice(18, 21), "c": slice(21, 24), "co": 24, "alpha2": 25, "alpha": 26,
          "lam_o": 27, "p_spec": 28, "spec_on": 29, "eta2m1": 30, "f0r": 31}
WIDTH = 32  # float32 per surface: 128 bytes
ANISO_LAYOUT = {"ax": 32, "ay": 33, "tx": slice(34, 37)}
SHEEN_ROW = 37  # a sheen surface's roughness (0: not a sheen lobe)
ANISO_WIDTH = 38  # the block's rows with the extension (anisotropy and sheen)


def width(anisotropic: bool, sheen: bool = False) -> int:
    """Rows of a block of terms: WIDTH, or ANISO_WIDTH where some material may be anisotropic or a sheen."""
    return ANISO_WIDTH if anisotropic or sheen else WIDTH


class ShadingTerms:
    """Per-surface terms of p̂ as a (32, n) float32 block (:data:`LAYOUT`): each term a contiguous row, the
    terms of other pixels (spatial and temporal neighbours) one column gather away (:meth:`take`)."""

    def __init__(self, packed: np.ndarray, glossy: bool | None = None, dielectric: bool | None = None,
                 aniso: AnisoWorld | None = None, stretched: bool | None = None, sheeny: bool | None = None):
        self.packed = packed
        self.aniso = aniso  # anisotropic surfaces: their exact BSDF pdf (of_surfaces; not kept in the packed rows)
        for name, rows in LAYOUT.items():
            setattr(self, name, packed[rows])
        self.stretched = False  # some surface's lobe is anisotropic (ANISO_LAYOUT rows)
        self.sheeny = False     # some surface is a sheen lobe (SHEEN_ROW)
        if packed.shape[0] >= ANISO_WIDTH:
            for name, rows in ANISO_LAYOUT.items():
                setattr(self, name, packed[rows])
            self.stretched = bool((self.ax != self.ay).any()) if stretched is None else stretched
            self.sheen_r = packed[SHEEN_ROW]
            self.sheeny = bool((self.sheen_r > 0).any()) if sheeny is None else sheeny
        self.glossy = bool((self.spec_on > 0).any()) if glossy is None else glossy
        # whether some surface has a dielectric lobe (its exact Fresnel is evaluated per candidate)
        self.dielectric = (self.glossy and bool((self.c > 0).any())) if dielectric is None else dielectric

    def __len__(self) -> int:
        return self.packed.shape[1]

    @staticmethod
    def of_surfaces(surf, out: np.ndarray | None = None) -> "ShadingTerms":
        """Terms of surfaces ``surf`` (a surface.Surface: p, ng, ns, wo, wo_l, params), written into ``out``
        ((32, n) float32, e.g. a slice of a frame's block) when given."""
        prm = surf.params
        packed = np.empty((WIDTH, surf.p.shape[1]), np.float32) if out is None else out
        packed[LAYOUT["p"]] = surf.p
        packed[LAYOUT["ng"]] = surf.ng
        packed[LAYOUT["ns"]] = surf.ns
        # wo in the bent frame: the local view vector back in world space (wo·ns = cos θ_o exactly)
        wl = surf.wo_l
        packed[LAYOUT["wo"]] = to_world(wl, surf.ns, surf.t, surf.bt)
        # the BSDF's view terms (bsdf.ViewTerms, shared with shading) with the luminance weights folded in
        v = view_terms(surf)
        packed[LAYOUT["co"]] = v.co
        packed[LAYOUT["kd"]] = v.kd * LUM[:, None]
        spec_a, spec_b = v.spec_full()
        packed[LAYOUT["a"]] = spec_a * LUM[:, None]
        if spec_b is None:
            packed[LAYOUT["b"]] = 0.0
        else:
            packed[LAYOUT["b"]] = spec_b * LUM[:, None]
        if v.spec_c is None:
            packed[LAYOUT["c"]] = 0.0
            packed[LAYOUT["eta2m1"]] = 0.0
            packed[LAYOUT["f0r"]] = 0.0
        else:
            packed[LAYOUT["c"]] = v.spec_c * LUM[:, None]
            packed[LAYOUT["eta2m1"]] = v.eta2m1
            packed[LAYOUT["f0r"]] = v.f0r
        packed[LAYOUT["lam_o"]] = v.lam_o
        packed[LAYOUT["spec_on"]] = prm.spec_on
        packed[LAYOUT["p_spec"]] = prm.p_spec
        packed[LAYOUT["alpha"]] = prm.alpha
        packed[LAYOUT["alpha2"]] = v.alpha2
        aniso = None
        if v.aniso is not None:
            r = v.aniso.rows
            ns, t, bt = np.take(surf.ns, r, axis=1), np.take(surf.t, r, axis=1), np.take(surf.bt, r, axis=1)
            aniso = AnisoWorld.of(v.aniso, lambda w: to_world(w, ns, t, bt), np.take(wl, r, axis=1))
        if packed.shape[0] >= ANISO_WIDTH:
            packed[ANISO_LAYOUT["ax"]] = prm.alpha
            packed[ANISO_LAYOUT["ay"]] = prm.alpha
            packed[ANISO_LAYOUT["tx"]] = surf.t
            if aniso is not None:
                packed[ANISO_LAYOUT["ax"], aniso.rows] = aniso.ax
                packed[ANISO_LAYOUT["ay"], aniso.rows] = aniso.ay
                packed[ANISO_LAYOUT["tx"].start:ANISO_LAYOUT["tx"].stop, aniso.rows] = aniso.x
            packed[SHEEN_ROW] = 0.0
            if v.sheen is not None:
                packed[SHEEN_ROW, v.sheen.rows] = np.maximum(v.sheen.roughness, np.float32(1e-3))
        ext = packed.shape[0] >= ANISO_WIDTH
        return ShadingTerms(packed, dielectric=v.spec_c is not None and v.glossy, aniso=aniso,
                            stretched=aniso is not None and ext, sheeny=v.sheen is not None and ext)

    def take(self, idx) -> "ShadingTerms":
        """Terms of surfaces ``idx`` (index array or slice). Without a glossy surface among them only the
        rows the diffuse target and pdf read are gathered (p, ng, ns, kd, p_spec: 13 of 32)."""
        aniso = None if self.aniso is None else self.aniso.take(idx, len(self))
        if isinstance(idx, slice):
            return ShadingTerms(self.packed[:, idx], self.glossy, self.dielectric, aniso, self.stretched, self.sheeny)
        if self.glossy or self.sheeny:
            return ShadingTerms(np.take(self.packed, idx, axis=1), self.glossy, self.dielectric, aniso, self.stretched,
                                self.sheeny)
        out = np.empty((WIDTH, len(idx)), np.float32)
        np.take(self.packed[0:9], idx, axis=1, out=out[0:9])
        np.take(self.packed[12:15], idx, axis=1, out=out[12:15])
        p_spec = LAYOUT["p_spec"]
        np.take(self.packed[p_spec], idx, out=out[p_spec])  # the BSDF pdf
        return ShadingTerms(out, False, False)

    def evaluate(self, pts: PackedPoints, want_pdf: bool = True):
        """p̂ and the BSDF pdf in area measure (None unless ``want_pdf``) of light points ``pts`` whose
        components are (...) arrays broadcasting against this block's (n,) rows: (n,) for one point per
        surface, (m, n) for m candidates per surface. Spot cones must already be applied (:func:`with_spots`)."""
        pos, nl, le = pts.pos, pts.normal, pts.le
        p, ns, ng = self.p, self.ns, self.ng
        dx = pos[0] - p[0]
        dy = pos[1] - p[1]
        dz = pos[2] - p[2]
        d2 = dx * dx
        d2 += dy * dy
        d2 += dz * dz
        if not self.glossy:
            return self._evaluate_diffuse(dx, dy, dz, d2, pts, want_pdf)
        inv = np.maximum(d2, np.float32(1e-30))
        np.sqrt(inv, out=inv)
        np.divide(np.float32(1.0), inv, out=inv)
        ci = dx * ns[0]
        ci += dy * ns[1]
        ci += dz * ns[2]
        ci *= inv
        cl = dx * nl[0]
        cl += dy * nl[1]
        cl += dz * nl[2]
        cl *= inv
        np.negative(cl, out=cl)                      # cos θ_l, positive on the light's front face
        ok = ci > 0
        gn = dx * ng[0]
        gn += dy * ng[1]
        gn += dz * ng[2]
        ok &= gn > 0
        acl = np.abs(cl)
        ok &= acl > 1e-8
        ok &= (cl > 0) | pts.two_sided
        to_area = acl
        to_area *= inv
        to_area *= inv                               # |cos θ_l| / d²
        lum = le[0] * self.kd[0]
        lum += le[1] * self.kd[1]
        lum += le[2] * self.kd[2]
        if self.sheeny:
            lum *= self._sheen_factor(ci)
        pdf_s = None
        if self.glossy:
            wdw = dx * self.wo[0]
            wdw += dy * self.wo[1]
            wdw += dz * self.wo[2]
            wdw *= inv                               # ωo·ωi
            cos_h, odh, dist_d = half_vector_terms(wdw, self.co, ci, self.alpha2)
            if self.stretched:
                dist_d, g = self._stretched(dx, dy, dz, inv, ci)
            else:
                g = self._smith_light(ci)
            g *= 0.5
            g += 0.5 + self.lam_o                    # 1 + Λ(ωo) + Λ(ωi)
            s = self.spec_on * dist_d
            s /= g
            den4 = (4.0 * self.co) * ci
            np.maximum(den4, np.float32(1e-12), out=den4)
            s /= den4                                # D·G/(4 cos θ_o cos θ_i)
            c = 1.0 - odh
            np.clip(c, 0.0, 1.0, out=c)
            c5 = c * c
            c5 *= c5
            c5 *= c
            spec = le[0] * self.b[0]
            spec += le[1] * self.b[1]
            spec += le[2] * self.b[2]
            spec *= c5
            spec += le[0] * self.a[0]
            spec += le[1] * self.a[1]
            spec += le[2] * self.a[2]
            if self.dielectric:
                fr = fresnel_exact(odh, self.eta2m1)
                fr -= self.f0r
                np.maximum(fr, 0.0, out=fr)
                fr *= le[0] * self.c[0] + le[1] * self.c[1] + le[2] * self.c[2]
                spec += fr
            spec *= s
            lum += spec
            if want_pdf:
                pdf_s = self._reflection_pdf(dist_d, cos_h, odh, dx, dy, dz, inv)
        lum *= ci
        lum *= to_area
        np.abs(lum, out=lum)                         # |f · Le|: a negative light's samples are drawn too
        p_hat = np.multiply(lum, ok, out=lum)  # zero where the point does not light the surface (x bool: 18x
        #                                        faster than np.where; the factors are finite by construction)
        if not want_pdf:
            return p_hat, None
        pdf = np.maximum(ci, np.float32(0.0))
        pdf *= (1.0 - self.p_spec) * INV_PI
        if pdf_s is not None:
            pdf_s *= self.p_spec
            pdf += pdf_s
        pdf *= to_area
        return p_hat, np.multiply(pdf, ok, out=pdf)


    def _smith_light(self, ci):
        """√(1 + α² tan² θi) = 1 + 2 Λ(ωi) of the isotropic GGX at cos θi = ``ci``."""
        c2 = ci * ci
        np.clip(c2, 1e-12, 1.0, out=c2)
        tan2 = 1.0 - c2
        tan2 /= c2
        tan2 *= self.alpha2
        tan2 += 1.0
        np.sqrt(tan2, out=tan2)
        return tan2

    def _reflection_pdf(self, dist_d, cos_h, odh, dx, dy, dz, inv):
        """The specular lobes' sampling pdf D cos θh/(4 ωo·h) (solid angle), the anisotropic surfaces' own where
        there are some (their sampler's: AnisoWorld) toward directions (dx, dy, dz) · inv."""
        pdf_s = dist_d * cos_h
        pdf_s /= 4.0 * odh
        if self.aniso is not None:
            ra = self.aniso.rows
            iv = inv[..., ra]
            pdf_s[..., ra] = self.aniso.reflection_pdf(dx[..., ra] * iv, dy[..., ra] * iv, dz[..., ra] * iv)
        return pdf_s

    def _sheen_factor(self, ci):
        """The diffuse term's factor at every surface: R(μi = ci, roughness) at sheen surfaces, 1 elsewhere."""
        r = np.broadcast_to(self.sheen_r, np.shape(ci))
        return np.where(r > 0, albedo(np.maximum(r, np.float32(1e-3)), np.clip(ci, 0.0, 1.0)), np.float32(1.0))

    def _stretched(self, dx, dy, dz, inv, ci):
        """The anisotropic GGX's D(h) and √(1 + (αx² ix² + αy² iy²)/cos² θi) = 1 + 2 Λ(ωi) of directions
        (dx, dy, dz) · inv at every surface, in the frame (X, n_s x X, n_s) of ANISO_LAYOUT's tangent (isotropic
        surfaces: αx = αy = α, the isotropic terms)."""
        tx, ns, wo = self.tx, self.ns, self.wo
        ty = np.stack([ns[1] * tx[2] - ns[2] * tx[1], ns[2] * tx[0] - ns[0] * tx[2], ns[0] * tx[1] - ns[1] * tx[0]])
        ix = (dx * tx[0] + dy * tx[1] + dz * tx[2]) * inv
        iy = (dx * ty[0] + dy * ty[1] + dz * ty[2]) * inv
        hx = ix + (wo[0] * tx[0] + wo[1] * tx[1] + wo[2] * tx[2])
        hy = iy + (wo[0] * ty[0] + wo[1] * ty[1] + wo[2] * ty[2])
        hz = ci + self.co
        q = hx * hx / (self.ax * self.ax) + hy * hy / (self.ay * self.ay)
        q /= np.maximum(hx * hx + hy * hy + hz * hz, np.float32(1e-30))   # h unit: (hx/αx)² + (hy/αy)², and
        h2 = hz * hz / np.maximum(hx * hx + hy * hy + hz * hz, np.float32(1e-30))
        q += h2                                                              # + hz²
        d = np.float32(np.pi) * self.ax * self.ay * q * q
        d = np.divide(np.float32(1.0), np.maximum(d, np.float32(1e-30)), out=d)
        c2 = np.clip(ci * ci, 1e-12, 1.0)
        lam = ((self.ax * ix) ** 2 + (self.ay * iy) ** 2) / c2
        lam += 1.0
        np.sqrt(lam, out=lam)
        return d, lam

    def _evaluate_diffuse(self, dx, dy, dz, d2, pts: PackedPoints, want_pdf: bool):
        """:meth:`evaluate` for blocks without a glossy surface, without square roots: with unnormalized
        d·n_s > 0 and -d·n_l, |cos θ_s| |cos θ_l| / d² = (d·n_s)(|d·n_l|) / d⁴."""
        ns, ng, nl = self.ns, self.ng, pts.normal
        dn = dx * ns[0]
        dn += dy * ns[1]
        dn += dz * ns[2]
        sheen_f = self._sheen_factor(dn / np.sqrt(np.maximum(d2, np.float32(1e-30)))) if self.sheeny else None
        ln = dx * nl[0]
        ln += dy * nl[1]
        ln += dz * nl[2]
        np.negative(ln, out=ln)                      # -d·n_l: positive on the light's front face
        ok = dn > 0
        gn = dx * ng[0]
        gn += dy * ng[1]
        gn += dz * ng[2]
        ok &= gn > 0
        ok &= (ln > 0) | pts.two_sided
        aln = np.abs(ln, out=ln)
        ok &= aln * aln > np.float32(1e-16) * d2     # |cos θ_l| > 1e-8
        geo = dn
        geo *= aln
        d2 *= d2
        np.maximum(d2, np.float32(1e-30), out=d2)
        geo /= d2
        geo *= ok                                    # |cos θ_s| |cos θ_l| / d² where the point lights x
        le, kd = pts.le, self.kd
        p_hat = le[0] * kd[0]
        p_hat += le[1] * kd[1]
        p_hat += le[2] * kd[2]
        if sheen_f is not None:
            p_hat *= sheen_f
        np.abs(p_hat, out=p_hat)                     # |f · Le| (negative lights)
        p_hat *= geo
        if not want_pdf:
            return p_hat, None
        geo *= (1.0 - self.p_spec) * INV_PI
        return p_hat, geo


def with_spots(pts: PackedPoints, spot_tri: np.ndarray, lamps, receivers: np.ndarray) -> PackedPoints:
    """``pts`` with the receiver-dependent factor of lamp triangles ``spot_tri`` (same shape as the points, -1 =
    none: lights/receiver.receiver_factor, a spot cone, a Light Falloff, a node texture) towards ``receivers`` ((3, n), broadcasting
    like the points) applied to the radiance."""
    spot = np.nonzero(spot_tri >= 0)
    if spot[0].size == 0:
        return pts
    rec = np.broadcast_to(receivers, (3,) + spot_tri.shape)
    at = np.broadcast_to(pts.pos, (3,) + spot_tri.shape)
    le = pts.le.copy()
    f = receiver_factor(lamps, spot_tri[spot], np.stack([rec[i][spot] for i in range(3)]),
                        np.stack([at[i][spot] for i in range(3)]))
    for i in range(3):
        le[i][spot] *= f[i] if f.ndim == 2 else f
    return PackedPoints(pts.pos, pts.normal, le, pts.pdf, pts.two_sided)


class FramePoints:
    """The light points of a frame of reservoirs (empty reservoirs hold an arbitrary point), packed as
    (11, n) for column gathers by neighbouring pixels, with their spot lamp triangles (None: no spots)."""

    CHUNK = 65536  # points per pool task

    def __init__(self, lights, light: np.ndarray, b1: np.ndarray, b2: np.ndarray):
        n = len(light)
        if lights.n_tri == 0 or n <= self.CHUNK or in_worker():
            pts = light_points(lights, np.maximum(light, 0), b1, b2)
            self.rows = pts.packed()
            self.spot_tri = pts.spot_tri if pts.has_spots else None
            return
        self.rows = np.empty((11, n), np.float32)
        spans = [slice(a, min(n, a + self.CHUNK)) for a in range(0, n, self.CHUNK)]
        parts = list(pool().map(lambda sl: light_points(lights, np.maximum(light[sl], 0), b1[sl], b2[sl],
                                                        out=self.rows[:, sl]).spot_tri, spans))
        spot_tri = np.concatenate(parts)
        self.spot_tri = spot_tri if (spot_tri >= 0).any() else None

    @classmethod
    def shared(cls, lights, light: np.ndarray, b1: np.ndarray, b2: np.ndarray, spans, team) -> "FramePoints":
        """The same points, each of ``spans`` (slices of the reservoirs) computed by the member of ``team`` that
        owns it (parallel/team.py) into the team's shared buffers; complete after its barrier."""
        if lights.n_tri == 0:
            return cls(lights, light, b1, b2)
        self = cls.__new__(cls)
        n = len(light)
        self.rows = team.empty((11, n), np.float32)
        spot = team.empty(n, np.int32)
        for i, sl in enumerate(spans):
            if team.owns(i):
                spot[sl] = light_points(lights, np.maximum(light[sl], 0), b1[sl], b2[sl],
                                        out=self.rows[:, sl]).spot_tri
        team.barrier()
        self.spot_tri = spot if (spot >= 0).any() else None
        return self

    def points(self, q) -> PackedPoints:
        """Points of reservoirs ``q`` (index array or slice), spot cones not applied."""
        return PackedPoints.of(np.take(self.rows, q, axis=1) if not isinstance(q, slice) else self.rows[:, q])

