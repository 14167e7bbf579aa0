"""The world (background) as a light: a constant radiance or an equirectangular environment image, with importance
sampling for next-event estimation (solid-angle pdfs, MIS against BSDF sampling in the path tracer).

Radiance is W·sr⁻¹·m⁻², scene-linear. Image convention (Cycles' equirectangular mapping): for a direction d in the
texture's frame, u = 1/2 - atan2(d_y, d_x)/(2π), v = 1 - acos(d_z)/π; the image's row 0 is its bottom (v = 0,
straight down). ``rotation`` maps world directions into the texture's frame (a Mapping node's rotation).
``camera_view`` (colour, image[, graph]): what camera rays see where that differs from the light (a world graph
reading Light Path > Is Camera Ray). ``graph`` (a :class:`WorldGraph`): the node program the image was baked from,
evaluated exactly for the radiance of a direction (camera rays, BSDF rays that miss, sampled directions) while the
image gives the sampling density (unbiased: the image is non-zero wherever the graph's sky is); a Sky Texture's sun
discs, left out of the image, are sampled uniformly over their cones in a mixture with it, each by its power's share.
Sampling an image picks a texel with probability ∝ its luminance times sin θ (one cumulative table over the texels),
then a uniform point in it: pdf_ω = p(texel) · w h / (2π² sin θ), θ the direction's own polar angle. The luminance is taken
as the largest of each texel and its 8 neighbours, so bilinear lookups never light a direction of pdf 0. A constant
world is sampled by the cosine about the receiver's normal (pdf cos⁺θ/π): for a diffuse receiver that is the
integrand's own shape (zero variance under an open sky, as BSDF sampling alone would be), and MIS with a glossy
BSDF's samples keeps the best of both.
"""
from __future__ import annotations

import numpy as np

from dataclasses import dataclass, field

from ..materials.textures import sample_bilinear
from ..sampling import cosine_hemisphere, to_world

LUM = np.array([0.2126, 0.7152, 0.0722], np.float32)


@dataclass
class WorldGraph:
    """A world's Background as a node program of the direction (outputs "color" and "strength"; core/materials/
    nodes) with the images it reads, as camera rays (``camera_ray``) or other rays see it; ``color`` / ``strength``:
    the values of whichever of the two is constant (not among the program's outputs)."""
    program: object
    textures: list = field(repr=False)
    camera_ray: bool = False
    color: object = None
    strength: object = None
    suns: tuple = ()  # (unit direction (3,), half-angle in radians) of each sky's sun disc it reads along the direction

    def radiance(self, d: np.ndarray) -> np.ndarray:
        """Radiance (3, n) towards directions ``d`` (3, n) (need not be unit); non-finite values read 0."""
        if d.shape[1] == 0:
            return np.zeros((3, 0), np.float32)
        ln = np.sqrt((d * d).sum(axis=0))
        return self.evaluate((d / np.maximum(ln, np.float32(1e-30))).astype(np.float32))

    def evaluate(self, unit: np.ndarray, without_sun: bool = False) -> np.ndarray:
        """Radiance (3, n) towards unit directions (3, n) (``without_sun``: Sky Textures leave their sun discs
        out); non-finite values read 0."""
        from ..materials.nodes.attributes import DirectionAttributes
        n = unit.shape[1]
        out = self.program.run(DirectionAttributes(unit, self.textures, self.camera_ray, without_sun=without_sun))
        c = out["color"] if "color" in out else np.asarray(self.color, np.float32).reshape(3, 1)
        s = out["strength"] if "strength" in out else np.float32(self.strength)
        rgb = np.broadcast_to(c * s, (3, n))
        return np.where(np.isfinite(rgb), rgb, 0).astype(np.float32)


class World:
    """``color`` (3,) constant radiance (used when ``image`` is None), ``image`` (h, w, 3) radiance (strength
    applied) or None, ``rotation`` (3, 3) world -> texture frame or None, ``graph`` the image's exact source or
    None."""

    def __init__(self, color, image: np.ndarray | None = None, rotation: np.ndarray | None = None,
                 camera_view: tuple | None = None, graph: WorldGraph | None = None):
        self.camera_view = None  # what camera rays see instead (Light Path > Is Camera Ray): a World, or None
        if camera_view is not None:
            self.camera_view = World(camera_view[0], camera_view[1], rotation,
                                     graph=camera_view[2] if len(camera_view) > 2 else None)
        self.graph = graph
        self.color = np.asarray(color, np.float32).reshape(3)
        self.image = None if image is None else np.ascontiguousarray(image, np.float32)
        # Cycles lights a surface with a constant world through the rays that bounce off it (its Auto sampling
        # method does not light-sample such a world), so that light passes cut-outs as those rays do: also through
        # materials whose Transparent Shadows setting is off (geometry/accel.Accel.passed)
        self.lit_by_bounces = self.image is None
        self.rotation = None if rotation is None else np.asarray(rotation, np.float32)
        if self.image is None:
            self.mean = self.color
            self.sampled = bool((self.color > 0).any())
            return
        h, w = self.image.shape[:2]
        lum = np.maximum(self.image @ LUM, 0)
        # the largest of each texel and its 8 neighbours (a bilinear lookup reads up to one texel away), wrap in u
        lum = np.maximum(lum, np.maximum(np.roll(lum, -1, axis=1), np.roll(lum, 1, axis=1)))
        lum = np.maximum(lum, np.maximum(np.vstack([lum[1:], lum[-1:]]), np.vstack([lum[:1], lum[:-1]])))
        sin_t = np.sin(np.pi * (np.arange(h) + 0.5) / h)[:, None]
        weight = (lum * sin_t).astype(np.float64)
        total = weight.sum()
        self.sampled = bool(total > 0)
        sin_w = np.broadcast_to(sin_t, (h, w))
        self.mean = (self.image * sin_w[..., None]).sum(axis=(0, 1)) / sin_w.sum()  # solid-angle mean radiance
        if not self.sampled:
            return
        self._cdf = np.concatenate([[0.0], np.cumsum(weight.ravel())]) / total  # over texels, row-major (h w + 1,)
        self._p = weight / total                                               # texel probabilities (h, w)
        self._wh = w * h
        self._suns = self._sun_cones(total * 2 * np.pi * np.pi / self._wh)

    def _sun_cones(self, image_power: float) -> list:
        """(direction (3,), cos of the half-angle, solid angle, probability) per sun disc of the graph, sampled
        uniformly over its cone with the probability of its share of the luminous power (the disc's mean radiance
        from SUN_PROBES directions, times its solid angle) against the image's; the image keeps the rest."""
        if self.graph is None or not self.graph.suns:
            return []
        cones, powers = [], []
        k = int(np.sqrt(SUN_PROBES))
        grid = (np.arange(k) + 0.5) / k
        gu, gv = (g.ravel() for g in np.meshgrid(grid, grid))
        for direction, half in self.graph.suns:
            d = np.asarray(direction, np.float64)
            cos_half = float(np.cos(half))
            solid = 2 * np.pi * (1 - cos_half)
            probe = _cone_directions(d, cos_half, gu, gv)
            powers.append(float(np.maximum(self.graph.radiance(probe).T @ LUM, 0).mean()) * solid)
            cones.append((d, cos_half, solid))
        total = image_power + sum(powers)
        return [(d, c, solid, p / total) for (d, c, solid), p in zip(cones, powers) if p > 0]

    # -- lookups ---------------------------------------------------------------------------------------------
    def _to_texture(self, d: np.ndarray) -> np.ndarray:
        return d if self.rotation is None else (self.rotation @ d).astype(np.float32)

    def _uv(self, d: np.ndarray):
        t = self._to_texture(d)
        ln = np.sqrt((t * t).sum(axis=0))
        z = np.clip(t[2] / np.maximum(ln, 1e-30), -1.0, 1.0)
        u = 0.5 - np.arctan2(t[1], t[0]) / (2 * np.pi)
        v = 1.0 - np.arccos(z) / np.pi
        return np.mod(u, 1.0), np.clip(v, 0.0, 1.0)

    def radiance(self, d: np.ndarray, camera: bool = False) -> np.ndarray:
        """Radiance (3, n) arriving from directions d (3, n) (need not be unit); ``camera``: as camera rays see it
        (a world whose graph reads Light Path > Is Camera Ray)."""
        if camera and self.camera_view is not None:
            return self.camera_view.radiance(d)
        n = d.shape[1]
        if self.image is None:
            return np.broadcast_to(self.color[:, None], (3, n)).astype(np.float32)
        if self.graph is not None:
            return self.graph.radiance(d)
        u, v = self._uv(d)
        # v = 1 is the top row: clamp the bilinear lookup in v rather than wrap it
        h = self.image.shape[0]
        v = np.clip(v, 0.5 / h, 1 - 0.5 / h)
        return sample_bilinear(self.image, np.stack([u, v], axis=1)).T.copy()

    def pdf(self, d: np.ndarray, normal: np.ndarray | None = None) -> np.ndarray:
        """Solid-angle density (n,) of :meth:`sample` producing unit directions d (3, n) at receivers of unit
        ``normal`` (3, n) (a constant world's density depends on it)."""
        n = d.shape[1]
        if not self.sampled:
            return np.zeros(n, np.float32)
        if self.image is None:
            c = (d * normal).sum(axis=0)
            return (np.maximum(c, 0) / np.pi).astype(np.float32)
        h, w = self._p.shape
        u, v = self._uv(d)
        col = np.minimum((u * w).astype(np.intp), w - 1)
        row = np.minimum((v * h).astype(np.intp), h - 1)
        sin_t = np.maximum(np.sin(np.pi * v), 1e-6)
        pdf = self._p[row, col] * self._wh / (2 * np.pi * np.pi * sin_t)
        if self._suns:
            pdf = pdf * (1 - sum(c[3] for c in self._suns))
            ln = np.maximum(np.sqrt((d.astype(np.float64) ** 2).sum(axis=0)), 1e-30)
            for sun, cos_half, solid, p in self._suns:
                pdf = pdf + np.where(sun @ d / ln >= cos_half, p / solid, 0.0)
        return pdf.astype(np.float32)

    def sample(self, u1: np.ndarray, u2: np.ndarray, frame=None):
        """Directions (3, n) (unit, world space), their solid-angle pdf (n,) and radiance (3, n) from uniforms
        u1, u2 (n,); ``frame`` = (normal, tangent, bitangent) (3, n) each: the receivers' shading frames (used by a
        constant world)."""
        if self.image is None:
            local = cosine_hemisphere(u1.astype(np.float32), u2.astype(np.float32))
            d = to_world(local, *frame)
            d /= np.maximum(np.sqrt((d * d).sum(axis=0)), np.float32(1e-12))
            return d, (np.maximum(local[2], 0) / np.pi).astype(np.float32), self.radiance(d)
        if self._suns:
            return self._sample_with_suns(np.asarray(u1, np.float64), np.asarray(u2, np.float64))
        d, row, col, st = self._sample_image(u1, u2)
        pdf = (self._p[row, col] * self._wh / (2 * np.pi * np.pi * np.maximum(st, 1e-6))).astype(np.float32)
        return d, pdf, self.radiance(d)

    def _sample_with_suns(self, u1: np.ndarray, u2: np.ndarray):
        """:meth:`sample` of the mixture of the image and the sun discs' cones (u1 picks the part, then is
        rescaled within it); the pdf is the mixture's."""
        d = np.empty((3, len(u1)), np.float32)
        lo = 0.0
        taken = np.zeros(len(u1), bool)
        for sun, cos_half, _solid, p in self._suns:
            pick = ~taken & (u1 < lo + p)
            if pick.any():
                d[:, pick] = _cone_directions(sun, cos_half, (u1[pick] - lo) / p, u2[pick])
            taken |= pick
            lo += p
        rest = ~taken
        if rest.any():
            d[:, rest] = self._sample_image(np.clip((u1[rest] - lo) / max(1 - lo, 1e-300), 0, 1), u2[rest])[0]
        return d, self.pdf(d), self.radiance(d)

    def _sample_image(self, u1: np.ndarray, u2: np.ndarray):
        """Directions (3, n) drawn from the image's texel table, with their texels' rows and columns and the sines
        of their polar angles (n,) each."""
        h, w = self._p.shape
        flat = np.clip(np.searchsorted(self._cdf, u1, side="right") - 1, 0, h * w - 1)
        lo, hi = self._cdf[flat], self._cdf[flat + 1]
        fu = np.clip((u1 - lo) / np.maximum(hi - lo, 1e-300), 0, 1)     # u1's position within the texel's interval
        row, col = np.divmod(flat, w)
        u = (col + fu) / w
        v = (row + u2) / h
        phi = np.pi - 2 * np.pi * u
        theta = np.pi - np.pi * v
        st = np.sin(theta)
        t = np.stack([st * np.cos(phi), st * np.sin(phi), np.cos(theta)])
        d = (t if self.rotation is None else self.rotation.T.astype(np.float64) @ t).astype(np.float32)
        return d, row, col, st


#: directions probed per sun disc for its share of the sampling
SUN_PROBES = 256


def _cone_directions(axis: np.ndarray, cos_half: float, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Unit directions (3, n) uniform over the cone of ``cos_half`` about unit ``axis`` (3,) from uniforms u, v."""
    a = np.asarray(axis, np.float64)
    helper = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t = np.cross(a, helper)
    t /= np.linalg.norm(t)
    b = np.cross(a, t)
    cos_t = 1 - np.asarray(u, np.float64) * (1 - cos_half)
    sin_t = np.sqrt(np.maximum(1 - cos_t * cos_t, 0))
    phi = 2 * np.pi * np.asarray(v, np.float64)
    d = t[:, None] * (sin_t * np.cos(phi)) + b[:, None] * (sin_t * np.sin(phi)) + a[:, None] * cos_t
    return d.astype(np.float32)
