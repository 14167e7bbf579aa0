"""A thin lens for depth of field, as Blender's camera describes it: an aperture of ``radius`` scene units (a disk,
or a regular polygon of ``blades`` sides turned by ``rotation`` radians, squeezed horizontally by ``ratio``) in the
camera's plane, focused at ``focus`` scene units along the view axis. Each camera ray leaves from a point of the
aperture towards the point its pinhole ray meets on the plane of focus, so that plane stays sharp."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

_F = np.float32


@dataclass(frozen=True)
class Lens:
    radius: float    # aperture radius (scene units)
    focus: float     # distance of the plane of focus along the view axis (scene units)
    blades: int = 0  # aperture polygon sides (below 3: a disk)
    rotation: float = 0.0  # the polygon's rotation (radians)
    ratio: float = 1.0     # aperture aspect: the x extent is divided by it (anamorphic bokeh)

    def aperture_points(self, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Points (x, y) on the aperture (camera plane, scene units) uniform over its area, from uniform u, v."""
        u, v = np.asarray(u, np.float32), np.asarray(v, np.float32)
        if self.blades < 3:  # concentric mapping of the square onto the disk (Shirley and Chiu)
            a, b = 2 * u - 1, 2 * v - 1
            wide = np.abs(a) > np.abs(b)
            r = np.where(wide, a, b)
            safe_a = np.where(a != 0, a, _F(1))
            safe_b = np.where(b != 0, b, _F(1))
            phi = np.where(wide, _F(np.pi / 4) * b / safe_a, _F(np.pi / 2) - _F(np.pi / 4) * a / safe_b)
            phi = np.where((a == 0) & (b == 0), _F(0), phi)
            x, y = r * np.cos(phi), r * np.sin(phi)
        else:  # one of the polygon's triangles about its centre, then a uniform point in it
            n = int(self.blades)
            corner = np.minimum((u * n).astype(np.int64), n - 1)
            q = np.sqrt(u * n - corner)
            half = _F(np.pi / n)
            px = (1 - q + v * q) * np.cos(half)
            py = (1 - q - v * q) * np.sin(half)
            rot = _F(self.rotation) + corner.astype(np.float32) * _F(2 * np.pi / n)
            c, s = np.cos(rot), np.sin(rot)
            x, y = c * px - s * py, s * px + c * py
        return (x / _F(self.ratio) * _F(self.radius)).astype(np.float32), (y * _F(self.radius)).astype(np.float32)

    def rays(self, cam, o, d, tmax, u, v):
        """Pinhole rays (origins on the near plane o (3, n), unit directions d (3, n), far distances tmax (n,)) of
        camera ``cam`` -> thin-lens rays through aperture samples (u, v): from the aperture point towards the
        pinhole ray's point on the plane of focus, starting on the near clip plane, ending on the far one."""
        c2w = np.asarray(cam.cam_to_world, np.float64)
        right, up = c2w[:3, 0].astype(np.float32)[:, None], c2w[:3, 1].astype(np.float32)[:, None]
        fwd = (-c2w[:3, 2]).astype(np.float32)[:, None]
        centre = c2w[:3, 3].astype(np.float32)[:, None]
        cos_d = np.maximum((d * fwd).sum(axis=0), _F(1e-6))
        if cam.ortho:  # parallel rays: the aperture moves each ray's own start in the camera plane
            start = o - fwd * ((o - centre) * fwd).sum(axis=0)
            focus_point = start + fwd * _F(self.focus)
        else:
            start = np.broadcast_to(centre, o.shape)
            focus_point = centre + d * (_F(self.focus) / cos_d)
        lx, ly = self.aperture_points(u, v)
        lens_point = start + right * lx + up * ly
        nd = focus_point - lens_point
        nd = nd / np.maximum(np.sqrt((nd * nd).sum(axis=0)), _F(1e-30))
        cos_n = np.maximum((nd * fwd).sum(axis=0), _F(1e-6))
        near, far = _F(cam.clip_start), _F(cam.clip_end)
        origin = lens_point + nd * (near / cos_n)
        return origin.astype(np.float32), nd.astype(np.float32), ((far - near) / cos_n).astype(np.float32)
