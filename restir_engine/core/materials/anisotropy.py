"""Anisotropic GGX for the specular lobes (Principled Anisotropic, Glossy Anisotropy), as Cycles defines it.

Roughness r gives α = r²; an aspect k stretches it along the tangent X and squeezes it along the bitangent Y:
αx = α / k, αy = α · k, so √(αx αy) = α and the lobe's energy compensation (the GGX albedo tables, read at α) is the
isotropic lobe's. The aspect comes from the anisotropy a as each node defines it: the Principled BSDF
k = √(1 - 0.9 a) for a in (0, 1] (isotropic for a ≤ 0); the Glossy BSDF, a clamped to [-0.99, 0.99], k = 1/(1 - a)
for a > 0 and 1 + a for a < 0 (its positive anisotropy stretches the lobe across the tangent, the Principled's along
it). The tangent T (the node's Tangent input; by default the radial tangent about the
object's Z axis) is turned about the normal N by Rotation · 2π, then made orthogonal to the lobe's normal:
X = normalize(T - (T·N) N), Y = N x X.

In the lobe's frame (X, Y, N), for unit directions w and microfacet normals h:
  D(h)   = 1 / (π αx αy (hx²/αx² + hy²/αy² + hz²)²)
  Λ(w)   = (√(1 + (αx² wx² + αy² wy²)/wz²) - 1)/2, so wz (1 + 2 Λ(w)) = √(wz² + αx² wx² + αy² wy²)
  G2     = 1/(1 + Λ(ωo) + Λ(ωi)) (height-correlated), and D G2/(4 cos θo cos θi) = D/(2 (vo cos θi + vi cos θo))
           with v = √(wz² + αx² wx² + αy² wy²)
Sampling draws the normals visible from ωo (Heitz 2018: the view stretched to the unit hemisphere, a point of the
projected disk, the normal stretched back), density G1(ωo) max(ωo·h, 0) D(h)/cos θo with G1(ωo) = 1/(1 + Λ(ωo)), so
the reflected direction's pdf is G1(ωo) D(h)/(4 cos θo) = D(h)/(2 (cos θo + vo)); a stretched lobe seen at a grazing
angle keeps weights f cos θi/pdf = F G2/G1 ≤ F.
Directions are (3, k) rows in the surface's local shading frame (z = shading normal), float32.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..sampling import dot, orthonormal_basis

GLOSSY_MAX = 0.99  # Cycles clamps the Glossy BSDF's anisotropy to [-0.99, 0.99]
_PI = np.float32(np.pi)


def renumbered(rows: np.ndarray, idx, n: int):
    """Rows ``rows`` (k,) of ``n`` surfaces seen through ``idx`` (index array or slice): (their positions in the
    taken surfaces, their positions in ``rows``), or None when ``idx`` takes none of them."""
    pos = np.full(n, -1, np.intp)
    pos[rows] = np.arange(len(rows))
    sub = pos[idx]
    keep = np.flatnonzero(sub >= 0)
    return None if keep.size == 0 else (keep, sub[keep])


def principled_aspect(anisotropy) -> np.ndarray:
    """The Principled BSDF's aspect √(1 - 0.9 a) of Anisotropic a (1 where a ≤ 0)."""
    a = np.clip(np.asarray(anisotropy, np.float32), 0.0, 1.0)
    return np.sqrt(1.0 - np.float32(0.9) * a).astype(np.float32)


def glossy_aspect(anisotropy) -> np.ndarray:
    """The Glossy BSDF's aspect of Anisotropy a: 1/(1 - a) (a > 0), 1 + a (a < 0), a clamped to ±GLOSSY_MAX."""
    a = np.clip(np.asarray(anisotropy, np.float32), -GLOSSY_MAX, GLOSSY_MAX)
    return np.where(a >= 0, 1.0 / (1.0 - a), 1.0 + a).astype(np.float32)


@dataclass
class AnisoFrame:
    """The anisotropic hits of a batch of surfaces: ``rows`` (k,) their indices, ``ax``, ``ay`` (k,) the GGX
    roughnesses along x and y, and the lobe's frame in local shading coordinates: ``x``, ``y``, ``n`` (3, k) unit
    (``n``: the specular lobes' normal, the shading normal z or Cycles' bent specular normal)."""

    rows: np.ndarray
    ax: np.ndarray
    ay: np.ndarray
    x: np.ndarray
    y: np.ndarray
    n: np.ndarray

    @staticmethod
    def of(rows, alpha, asp, tangent_l, normal_l) -> "AnisoFrame":
        """From the hits' isotropic α (k,), aspect (k,), (rotated) tangent and lobe normal in the local frame
        (3, k); a tangent along the normal (no direction left in the plane) takes an arbitrary one."""
        t = tangent_l - dot(tangent_l, normal_l) * normal_l
        ln = np.sqrt(dot(t, t))
        fallback, _b = orthonormal_basis(normal_l)
        ok = ln > np.float32(1e-6)
        x = np.where(ok, t / np.where(ok, ln, np.float32(1.0)), fallback).astype(np.float32)
        y = np.cross(normal_l.T, x.T).T.astype(np.float32)
        return AnisoFrame(np.asarray(rows, np.intp), (alpha / asp).astype(np.float32),
                          (alpha * asp).astype(np.float32), x, y, normal_l.astype(np.float32))

    def take(self, idx, n: int) -> "AnisoFrame | None":
        """The frame of surfaces ``idx`` (index array or slice into the ``n`` surfaces), renumbered; None when none
        of them is anisotropic."""
        got = renumbered(self.rows, idx, n)
        if got is None:
            return None
        keep, s = got
        return AnisoFrame(keep, self.ax[s], self.ay[s], self.x[:, s], self.y[:, s], self.n[:, s])

    def lobe(self, w: np.ndarray):
        """(wx, wy, wz) (k,) each: local directions (3, k) of these rows in the lobe's frame."""
        return dot(w, self.x), dot(w, self.y), dot(w, self.n)

    def smith_v(self, w: np.ndarray) -> np.ndarray:
        """v = √(wz² + αx² wx² + αy² wy²) = wz (1 + 2 Λ(w)) (k,) of local directions w (3, k)."""
        wx, wy, wz = self.lobe(w)
        return smith_v(self.ax, self.ay, wx, wy, wz)

    def spec_terms(self, wo: np.ndarray, wi: np.ndarray, vo: np.ndarray):
        """(D G2/(4 cos θo cos θi), the reflection's pdf D/(2 (cos θo + vo))) (k,) each of local directions wo, wi
        (3, k) with the view's ``vo`` (:meth:`smith_v`); 0 where wi is below the lobe's normal."""
        ox, oy, oz = self.lobe(wo)
        ix, iy, iz = self.lobe(wi)
        hx, hy, hz = ox + ix, oy + iy, oz + iz
        ln = np.sqrt(hx * hx + hy * hy + hz * hz)
        ln = np.maximum(ln, np.float32(1e-12))
        hx, hy, hz = hx / ln, hy / ln, hz / ln
        d = ggx_d(self.ax, self.ay, hx, hy, hz)
        vi = smith_v(self.ax, self.ay, ix, iy, iz)
        ok = (iz > 0) & (oz > 0)
        den = np.maximum(2.0 * (vo * iz + vi * oz), np.float32(1e-12))
        s = np.where(ok, d / den, np.float32(0.0)).astype(np.float32)
        pdf = np.where(ok, d / (2.0 * (oz + vo)), np.float32(0.0)).astype(np.float32)
        return s, pdf

    def sample_normals(self, sel: np.ndarray, wo: np.ndarray, u1: np.ndarray, u2: np.ndarray) -> np.ndarray:
        """Microfacet normals (3, len(sel)) in the local frame for rows ``sel`` (indices into this frame) visible
        from their local views ``wo`` (3, len(sel)), from uniforms u1, u2 (see the module docstring)."""
        ax, ay = self.ax[sel], self.ay[sel]
        x, y, n = self.x[:, sel], self.y[:, sel], self.n[:, sel]
        vx, vy, vz = ax * dot(wo, x), ay * dot(wo, y), np.maximum(dot(wo, n), np.float32(1e-6))
        ln = np.sqrt(vx * vx + vy * vy + vz * vz)
        vx, vy, vz = vx / ln, vy / ln, vz / ln
        lsq = vx * vx + vy * vy
        inv = np.where(lsq > 0, 1.0 / np.sqrt(np.maximum(lsq, np.float32(1e-30))), np.float32(0.0))
        t1x, t1y = np.where(lsq > 0, -vy * inv, np.float32(1.0)), np.where(lsq > 0, vx * inv, np.float32(0.0))
        t2x, t2y, t2z = vy * 0.0 - vz * t1y, vz * t1x, vx * t1y - vy * t1x   # Vh x T1 (T1 has no z)
        r = np.sqrt(u1)
        phi = np.float32(2.0 * np.pi) * u2
        p1, p2 = r * np.cos(phi), r * np.sin(phi)
        sw = 0.5 * (1.0 + vz)
        p2 = (1.0 - sw) * np.sqrt(np.maximum(0.0, 1.0 - p1 * p1)) + sw * p2
        pz = np.sqrt(np.maximum(0.0, 1.0 - p1 * p1 - p2 * p2))
        hx = ax * (p1 * t1x + p2 * t2x + pz * vx)
        hy = ay * (p1 * t1y + p2 * t2y + pz * vy)
        hz = np.maximum(p2 * t2z + pz * vz, np.float32(0.0))
        ln = np.maximum(np.sqrt(hx * hx + hy * hy + hz * hz), np.float32(1e-12))
        h = (hx / ln) * x + (hy / ln) * y + (hz / ln) * n
        return h.astype(np.float32)


def smith_v(ax, ay, wx, wy, wz) -> np.ndarray:
    """√(wz² + αx² wx² + αy² wy²) (see the module docstring)."""
    v = wz * wz + (ax * wx) ** 2 + (ay * wy) ** 2
    return np.sqrt(np.maximum(v, np.float32(0.0))).astype(np.float32)


def ggx_d(ax, ay, hx, hy, hz) -> np.ndarray:
    """The anisotropic GGX distribution D(h) of unit microfacet normals in the lobe's frame (0 below it)."""
    q = (hx / ax) ** 2 + (hy / ay) ** 2 + hz * hz
    d = 1.0 / (_PI * ax * ay * np.maximum(q * q, np.float32(1e-30)))
    return np.where(hz > 0, d, np.float32(0.0)).astype(np.float32)


@dataclass
class AnisoWorld:
    """An :class:`AnisoFrame` in world space, for the ReSTIR DI target's BSDF pdf (restir/target.py): ``rows``
    (k,) columns of a block of surfaces, ``ax``, ``ay`` (k,), the lobe's frame ``x``, ``y``, ``n`` and the view
    ``wo`` (3, k) in world space."""

    rows: np.ndarray
    ax: np.ndarray
    ay: np.ndarray
    x: np.ndarray
    y: np.ndarray
    n: np.ndarray
    wo: np.ndarray

    @staticmethod
    def of(frame: AnisoFrame, to_world, wo_l: np.ndarray) -> "AnisoWorld":
        """``frame`` with its vectors taken to world space by ``to_world`` ((3, k) local -> world, of the frame's
        rows) and the rows' local view ``wo_l`` (3, k)."""
        return AnisoWorld(frame.rows, frame.ax, frame.ay, to_world(frame.x), to_world(frame.y), to_world(frame.n),
                          to_world(wo_l))

    def take(self, idx, n: int) -> "AnisoWorld | None":
        """The rows of surfaces ``idx`` (index array or slice into the ``n`` surfaces), renumbered; None if none."""
        got = renumbered(self.rows, idx, n)
        if got is None:
            return None
        keep, s = got
        return AnisoWorld(keep, self.ax[s], self.ay[s], self.x[:, s], self.y[:, s], self.n[:, s], self.wo[:, s])

    def reflection_pdf(self, wx, wy, wz) -> np.ndarray:
        """The specular lobes' sampling pdf D/(2 (cos θo + vo)) (solid angle) of unit world directions with
        components wx, wy, wz (..., k), broadcasting over leading (candidate) axes; 0 below the lobe's normal."""
        x, y, n, wo = self.x, self.y, self.n, self.wo
        ix = wx * x[0] + wy * x[1] + wz * x[2]
        iy = wx * y[0] + wy * y[1] + wz * y[2]
        iz = wx * n[0] + wy * n[1] + wz * n[2]
        ox, oy, oz = dot(wo, x), dot(wo, y), dot(wo, n)
        hx, hy, hz = ox + ix, oy + iy, oz + iz
        ln = np.maximum(np.sqrt(hx * hx + hy * hy + hz * hz), np.float32(1e-12))
        hx, hy, hz = hx / ln, hy / ln, hz / ln
        d = ggx_d(self.ax, self.ay, hx, hy, hz)
        vo = smith_v(self.ax, self.ay, ox, oy, oz)
        pdf = d / (2.0 * (oz + vo))
        return np.where((iz > 0) & (oz > 0), pdf, np.float32(0.0)).astype(np.float32)
