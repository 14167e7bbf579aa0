"""Panoramic cameras as Blender 5 defines them: equirectangular (latitude / longitude ranges), fisheye equidistant,
fisheye equisolid, fisheye lens polynomial, mirror ball and central cylindrical. Each maps the frame's (u, v) in
[0, 1]² (u to the right, v up) to a view direction and back (for reprojection in temporal reuse).

Directions are built in the panorama's own frame, where x is the view direction (the camera's -Z), y the camera's
-X and z its +Y (the mirror ball: x right, -y ahead, z up), then turned into the camera's frame (x right, y up,
-z forward). Points of the frame outside the
projection's image (beyond a fisheye's circle) see nothing: black, as in Cycles."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

KINDS = ("EQUIRECTANGULAR", "FISHEYE_EQUIDISTANT", "FISHEYE_EQUISOLID", "FISHEYE_LENS_POLYNOMIAL", "MIRRORBALL",
         "CENTRAL_CYLINDRICAL")


@dataclass(frozen=True)
class Panorama:
    kind: str
    fov: float = np.pi                 # fisheye field of view (radians)
    lens: float = 10.5                 # fisheye equisolid focal length (mm)
    sensor: tuple = (36.0, 18.0)       # the sensor's width and height in mm, fitted to the frame's aspect
    latitude: tuple = (-np.pi / 2, np.pi / 2)
    longitude: tuple = (-np.pi, np.pi)
    polynomial: tuple = (0.0, 0.0, 0.0, 0.0, 0.0)  # fisheye lens polynomial k0..k4 (θ = -Σ kᵢ rⁱ, r in mm)
    cylinder: tuple = (-np.pi, np.pi, -1.0, 1.0, 1.0)  # central cylindrical u range, v range, radius

    # -- directions ---------------------------------------------------------------------------------------------
    def directions(self, u, v) -> tuple[np.ndarray, np.ndarray]:
        """(camera-space unit directions (3, n) float32, valid (n,) bool) of frame points (u, v)."""
        u, v = np.asarray(u, np.float64), np.asarray(v, np.float64)
        valid = np.ones(u.shape, bool)
        if self.kind == "EQUIRECTANGULAR":
            (lat0, lat1), (lon0, lon1) = self.latitude, self.longitude
            phi = u * (lon0 - lon1) - lon0
            theta = v * (lat0 - lat1) + np.pi / 2 - lat0
            d = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])
        elif self.kind == "CENTRAL_CYLINDRICAL":
            u0, u1, v0, v1, radius = self.cylinder
            phi = u * (u0 - u1) - u0
            h = v0 + v * (v1 - v0)
            d = np.stack([np.cos(phi), np.sin(phi), h / max(radius, 1e-9)])
        elif self.kind == "MIRRORBALL":
            x, z = 2 * u - 1, 2 * v - 1
            r2 = x * x + z * z
            valid = r2 <= 1
            y = -np.sqrt(np.maximum(1 - r2, 0))
            n = np.stack([x, y, z])
            incoming = np.array([0.0, -1.0, 0.0])[:, None]
            d = 2 * (n * incoming).sum(axis=0) * n - incoming  # the ball's own frame: x right, -y ahead, z up
            d = d / np.maximum(np.linalg.norm(d, axis=0), 1e-30)
            return np.stack([d[0], d[2], d[1]]).astype(np.float32), valid & np.isfinite(d).all(axis=0)
        else:  # fisheyes: a radius on the image -> an angle from the view axis
            if self.kind == "FISHEYE_EQUIDISTANT":
                x, y = 2 * (u - 0.5), 2 * (v - 0.5)
                r = np.hypot(x, y)
                valid = r <= 1
                theta = r * self.fov / 2
            else:
                x, y = (u - 0.5) * self.sensor[0], (v - 0.5) * self.sensor[1]
                r = np.hypot(x, y)
                if self.kind == "FISHEYE_EQUISOLID":
                    valid = r <= 2 * self.lens * np.sin(self.fov / 4)
                    theta = 2 * np.arcsin(np.clip(r / (2 * self.lens), -1, 1))
                else:
                    k = self.polynomial
                    theta = -(k[0] + k[1] * r + k[2] * r ** 2 + k[3] * r ** 3 + k[4] * r ** 4)
                    valid = np.abs(theta) <= self.fov / 2
            phi = np.arccos(np.clip(np.where(r > 0, x / np.where(r > 0, r, 1), 0), -1, 1)) * np.where(y < 0, -1, 1)
            d = np.stack([np.cos(theta), -np.cos(phi) * np.sin(theta), np.sin(phi) * np.sin(theta)])
        d = d / np.maximum(np.linalg.norm(d, axis=0), 1e-30)
        cam = np.stack([-d[1], d[2], -d[0]])  # panorama frame -> camera frame
        return cam.astype(np.float32), valid & np.isfinite(cam).all(axis=0)

    # -- back to the frame --------------------------------------------------------------------------------------
    def frame_points(self, cam_dirs) -> tuple[np.ndarray, np.ndarray]:
        """(u, v) float64 of camera-space directions (3, n) (any length) and whether they lie on the image."""
        c = np.asarray(cam_dirs, np.float64)
        d = np.stack([c[0], c[2], c[1]]) if self.kind == "MIRRORBALL" else np.stack([-c[2], -c[0], c[1]])
        d = d / np.maximum(np.linalg.norm(d, axis=0), 1e-30)
        if self.kind == "EQUIRECTANGULAR":
            (lat0, lat1), (lon0, lon1) = self.latitude, self.longitude
            phi, theta = np.arctan2(d[1], d[0]), np.arccos(np.clip(d[2], -1, 1))
            u, v = (phi + lon0) / (lon0 - lon1), (theta - np.pi / 2 + lat0) / (lat0 - lat1)
        elif self.kind == "CENTRAL_CYLINDRICAL":
            u0, u1, v0, v1, radius = self.cylinder
            phi = np.arctan2(d[1], d[0])
            flat = np.hypot(d[0], d[1])
            h = d[2] / np.maximum(flat, 1e-30) * radius
            u, v = (phi + u0) / (u0 - u1), (h - v0) / (v1 - v0)
        elif self.kind == "MIRRORBALL":
            incoming = np.array([0.0, -1.0, 0.0])[:, None]
            n = d + incoming  # the ball's normal halves the angle between the view and the reflection
            n = n / np.maximum(np.linalg.norm(n, axis=0), 1e-30)
            u, v = (n[0] + 1) / 2, (n[2] + 1) / 2
        else:
            theta = np.arccos(np.clip(d[0], -1, 1))
            phi = np.arctan2(d[2], -d[1])
            if self.kind == "FISHEYE_EQUIDISTANT":
                r = theta / (self.fov / 2)
                u, v = r * np.cos(phi) / 2 + 0.5, r * np.sin(phi) / 2 + 0.5
            else:
                if self.kind == "FISHEYE_EQUISOLID":
                    r = 2 * self.lens * np.sin(theta / 2)
                else:
                    r = self._polynomial_radius(theta)
                u, v = r * np.cos(phi) / self.sensor[0] + 0.5, r * np.sin(phi) / self.sensor[1] + 0.5
        ok = (u >= 0) & (u <= 1) & (v >= 0) & (v <= 1)
        return u, v, ok & np.isfinite(u) & np.isfinite(v)

    def _polynomial_radius(self, theta):
        """r (mm) with -Σ kᵢ rⁱ = θ, by Newton's method from the equidistant guess."""
        k = self.polynomial
        r = np.where(abs(k[1]) > 1e-12, -theta / (k[1] if k[1] else 1.0), theta)
        for _ in range(8):
            f = -(k[0] + k[1] * r + k[2] * r ** 2 + k[3] * r ** 3 + k[4] * r ** 4) - theta
            df = -(k[1] + 2 * k[2] * r + 3 * k[3] * r ** 2 + 4 * k[4] * r ** 3)
            r = r - f / np.where(np.abs(df) > 1e-12, df, 1e-12)
        return r
