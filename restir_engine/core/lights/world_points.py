"""The world as light points, so ReSTIR DI reservoirs can hold world samples beside lamp and emitter points.

A reservoir sample is a point, reused at every pixel in area measure (restir/di.py). The world's light arrives
from infinitely far away, so it is placed on a sphere S of radius R = DISTANCE x the scene's bounding radius r about
the scene's centre c: the point y = c + R ω(b1, b2) (sphere coordinates as lights.sphere_direction) faces inward
(normal -ω) and emits the world's radiance L(y) = world.radiance(ω) (W·sr⁻¹·m⁻², scene-linear). A world sample is
then a light point like any other: target G = cos θ_s cos θ_l / d², BSDF pdf p_ω cos θ_l / d², one shadow ray to y.
Every pdf and Jacobian is exact on S, so the estimator is unbiased for this sphere; a receiver x sees y in the
direction (y - x)/|y - x|, which differs from ω by at most r/R = 1/DISTANCE = 1e-4 rad (a 4k environment image's
texel is 1.5e-3 rad wide).

Candidates (di.initial_ris): a direction ω_x drawn from the world's own distribution at the receiver (an image by its
2-D table, a constant world by the cosine about the normal, world.World.sample) gives the point where the ray
x + t ω_x leaves S, with area pdf p_ω(ω_x) cos θ_l / d²; every BSDF candidate ray gives the point where it leaves S
(occluded or not, so the BSDF technique's density is its pdf everywhere), with the BSDF's pdf.

Points are kept as float32 sphere coordinates (b1, b2) like sphere lamps' points: directions are resolved to
about 1e-7 rad, except within 5e-4 rad of straight down (b1 near 1), where they are snapped coarser.
"""
from __future__ import annotations

import numpy as np

from .sphere import sphere_coords, sphere_direction
from .world import World

DISTANCE = 1e4    # R / r
MAX_RADIUS = 1e9  # m: keeps d⁴ (the diffuse target's denominator, target.py) inside float32


class WorldSphere:
    """The world ``world`` (world.World) on a sphere about ``center`` (3,) m of radius ``DISTANCE`` x
    ``scene_radius`` m."""

    def __init__(self, world: World, center, scene_radius: float):
        self.world = world
        self.center = np.asarray(center, np.float64).reshape(3)
        self.radius = float(min(MAX_RADIUS, DISTANCE * max(float(scene_radius), 1e-3)))
        self._c32 = self.center.astype(np.float32)[:, None]

    def points(self, b1: np.ndarray, b2: np.ndarray):
        """Positions (3, n), unit normals (3, n) (inward) and radiance (3, n) of the sphere's points (b1, b2)."""
        w = sphere_direction(b1, b2)
        pos = w * np.float32(self.radius)
        pos += self._c32
        return pos, -w, self.world.radiance(w)

    def exit_coords(self, o: np.ndarray, d: np.ndarray):
        """Sphere coordinates (b1, b2) of the points where rays o + t d ((3, n), unit d, o inside) leave S."""
        oc = o.astype(np.float64) - self.center[:, None]
        dd = d.astype(np.float64)
        b = np.einsum("ij,ij->j", oc, dd)
        c = np.einsum("ij,ij->j", oc, oc) - self.radius * self.radius
        t = -b + np.sqrt(np.maximum(b * b - c, 0.0))
        y = oc + t * dd
        y /= np.maximum(np.sqrt(np.einsum("ij,ij->j", y, y)), 1e-300)
        return sphere_coords(y)

    def sample(self, p: np.ndarray, frame, u1: np.ndarray, u2: np.ndarray):
        """World candidates for receivers at p (3, n) with shading frames ``frame`` = (normal, tangent, bitangent):
        sphere coordinates (b1, b2) of points drawn by the world's own distribution (directions from p)."""
        d, _pdf, _le = self.world.sample(u1, u2, frame)
        return self.exit_coords(p, d)

    def pdf_area(self, p: np.ndarray, normal: np.ndarray, pos: np.ndarray, cos_l: np.ndarray | None = None):
        """Area-measure density (n,) on S with which :meth:`sample` at receivers p (3, n) of shading normal
        ``normal`` (3, n) draws the points ``pos`` (3, n): p_ω(ω_x) |cos θ_l| / d², ω_x = (pos - p)/d."""
        v = pos - p
        d2 = np.einsum("ij,ij->j", v, v)
        d = np.sqrt(np.maximum(d2, np.float32(1e-30)))
        w = v / d
        if cos_l is None:  # the inward normal at pos is (c - pos)/R: cos θ_l = ω_x · (pos - c)/R
            cos_l = np.einsum("ij,ij->j", w, (pos - self._c32) / np.float32(self.radius))
        return (self.world.pdf(w, normal) * np.abs(cos_l) / np.maximum(d2, np.float32(1e-30))).astype(np.float32)
