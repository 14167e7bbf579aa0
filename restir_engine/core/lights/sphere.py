"""Sphere coordinates and the cone a sphere subtends: how points on point/spot lamps' spheres and on the world's
bounding sphere (world_points.py) are named. (b1, b2) in [0, 1]²: z = 1 - 2 b1, φ = 2π b2 (uniform in area for
uniform (b1, b2)); directions are (3, n) rows."""
from __future__ import annotations

import numpy as np


def sphere_direction(b1: np.ndarray, b2: np.ndarray) -> np.ndarray:
    """Unit vectors (3, n) float32 of sphere coordinates (b1, b2): z = 1 - 2 b1, φ = 2π b2 (uniform in area for
    uniform (b1, b2))."""
    b1 = np.asarray(b1, np.float32)
    out = np.empty((3, len(b1)), np.float32)
    rxy = np.multiply(b1, np.float32(1.0) - b1)
    np.maximum(rxy, 0.0, out=rxy)
    np.sqrt(rxy, out=rxy)
    rxy *= np.float32(2.0)  # sqrt(1 - z²), accurate near the poles
    phi = np.multiply(np.asarray(b2, np.float32), np.float32(2.0 * np.pi))
    np.cos(phi, out=out[0])
    out[0] *= rxy
    np.sin(phi, out=out[1])
    out[1] *= rxy
    np.multiply(b1, np.float32(-2.0), out=out[2])
    out[2] += np.float32(1.0)
    return out


def sphere_coords(unit: np.ndarray):
    """Sphere coordinates (b1, b2) of unit vectors (3, n) (inverse of :func:`sphere_direction`)."""
    b1 = np.clip(0.5 * (1.0 - unit[2]), 0.0, 1.0)
    b2 = np.mod(np.arctan2(unit[1], unit[0]) / (2.0 * np.pi), 1.0)
    return b1.astype(np.float32), b2.astype(np.float32)


def one_minus_cos_cone(r2_over_d2: np.ndarray) -> np.ndarray:
    """1 - cos θ_max of the cone a sphere subtends, from (r/d)² < 1, without cancellation (in the input's float
    precision)."""
    x = np.asarray(r2_over_d2)
    return x / (1.0 + np.sqrt(np.maximum(0.0, 1.0 - x)))
