"""The atmosphere behind Blender's Sky Texture of type Single Scattering (Nishita's model as Blender 2.90+ computes
it): the clear sky's radiance over view directions, and the sun's radiance seen through the air.

Air (Rayleigh scattering, scale height 8 km), aerosols (Mie scattering 2e-5 m⁻¹ with extinction 1.11 times that,
scale height 1.2 km, the Cornette-Shanks phase of g = 0.76) and ozone (absorption in a tent 10-40 km up) over a
sphere of radius 6360 km under 60 km of atmosphere, at 21 wavelengths (data/sky_spectra.json) mapped to CIE XYZ by
the CIE 1931 functions: light scattered once, in 32 midpoint steps along the view ray, each lit through the optical
depth to the sun by 8-point Gauss-Laguerre quadrature (nodes scaled so the last lies inside the atmosphere), unless
the ground hides the sun. Below the horizon the table repeats the horizon's row, faded as (1 - 2.5 sin|e|)³ over
the first 0.41 rad.

Units: metres. The table (TABLE_HEIGHT, TABLE_WIDTH, 3) holds CIE XYZ radiance with Blender's own placement of
its texels, which the Sky Texture reads with the Multiple Scattering table's lookup (sky.AtmosphereSky): column x
at longitude 2πx/w - π from the sun's side (the sun at longitude 0), row y at latitude π/2 (2y/h - 1)²
(rows bottom-up; the lower half mirrored in latitude for the fade).
"""
from __future__ import annotations

import json
import os
from functools import lru_cache

import numpy as np

from .sky_atmosphere import TABLE_HEIGHT, TABLE_WIDTH, in_parts

EARTH_RADIUS = 6360e3
ATMOSPHERE_RADIUS = 6420e3
_RAYLEIGH_SCALE, _MIE_SCALE = 8e3, 1.2e3
_MIE = 2e-5
_MIE_EXTINCTION = 1.11
_G = 0.76
_STEPS = 32
_QUADRATURE = 8
_STEP_LAMBDA = 20.0


@lru_cache(maxsize=1)
def _spectra():
    with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "sky_spectra.json")) as f:
        d = json.load(f)
    return (np.asarray(d["irradiance"]), np.asarray(d["rayleigh"]), np.asarray(d["ozone"]),
            np.asarray(d["cmf_xyz"]) * _STEP_LAMBDA)


@lru_cache(maxsize=1)
def _quadrature():
    """Gauss-Laguerre nodes of ∫ g(x) dx over [0, 25] (8 points; the weights carry e^x), as fractions of a ray."""
    x, w = np.polynomial.laguerre.laggauss(_QUADRATURE)
    end = 25.0
    return x / end, w * np.exp(x) / end


def _altitude(altitude_m: float) -> float:
    return float(np.clip(altitude_m, 1.0, 59999.0))


def _densities(height: np.ndarray) -> np.ndarray:
    """(..., 3) relative densities of air, aerosols and ozone at ``height`` metres above the ground."""
    return np.stack([np.exp(-height / _RAYLEIGH_SCALE), np.exp(-height / _MIE_SCALE),
                     np.maximum(0.0, 1.0 - np.abs(height - 25000.0) / 15000.0)], axis=-1)


def _to_atmosphere_top(p: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Distance (n,) from points ``p`` (n, 3) inside the atmosphere along unit ``d`` (n, 3) or (3,) to its top."""
    b = 2 * (p * d).sum(axis=-1)
    c = (p * p).sum(axis=-1) - ATMOSPHERE_RADIUS ** 2
    return (-b + np.sqrt(np.maximum(b * b - 4 * c, 0.0))) / 2


def _optical_depth(p: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Optical depth factors (n, 3) (air, aerosols, ozone: metres of sea-level density) from ``p`` (n, 3) along
    ``d`` (3,) to the top of the atmosphere."""
    nodes, weights = _quadrature()
    length = _to_atmosphere_top(p, d)
    pts = p[:, None, :] + (nodes[None, :, None] * length[:, None, None]) * d
    height = np.sqrt((pts * pts).sum(axis=-1)) - EARTH_RADIUS
    return (_densities(height) * weights[None, :, None]).sum(axis=1) * length[:, None]


def _sees_ground(p: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Whether the ray from ``p`` (n, 3) along ``d`` (3,) meets the ground (n,)."""
    if d[2] >= 0:
        return np.zeros(len(p), bool)
    b = 2 * (p @ d)
    c = (p * p).sum(axis=-1) - EARTH_RADIUS ** 2
    return b * b - 4 * c >= 0


def _scattered(dirs: np.ndarray, sun: np.ndarray, altitude: float, scale: np.ndarray) -> np.ndarray:
    """Spectral radiance (n, 21) scattered once towards a viewer at ``altitude`` m looking along ``dirs`` (n, 3);
    ``scale``: the densities of air, aerosols and ozone (3,)."""
    irradiance, rayleigh, ozone, _cmf = _spectra()
    origin = np.array([0.0, 0.0, EARTH_RADIUS + altitude])
    length = _to_atmosphere_top(np.broadcast_to(origin, dirs.shape), dirs)
    seg = length / _STEPS
    mu = dirs @ sun
    phase_r = 0.1875 / np.pi * (1 + mu * mu)
    phase_m = 3 * (1 - _G * _G) * (1 + mu * mu) / (8 * np.pi * (2 + _G * _G) * (1 + _G * _G - 2 * _G * mu) ** 1.5)
    extinction = np.stack([rayleigh, np.full(21, _MIE_EXTINCTION * _MIE), ozone])  # (3, 21)
    depth = np.zeros((len(dirs), 3))
    spectrum = np.zeros((len(dirs), 21))
    for i in range(_STEPS):
        p = origin + dirs * ((i + 0.5) * seg)[:, None]
        height = np.sqrt((p * p).sum(axis=1)) - EARTH_RADIUS
        density = scale * _densities(height)
        depth += seg[:, None] * density
        lit = ~_sees_ground(p, sun)
        if not lit.any():
            continue
        total = depth[lit] + scale * _optical_depth(p[lit], sun)
        attenuation = np.exp(-(total @ extinction))
        scattering = (phase_r[lit] * density[lit, 0])[:, None] * rayleigh + \
            (phase_m[lit] * density[lit, 1] * _MIE)[:, None]
        spectrum[lit] += attenuation * scattering * irradiance * seg[lit, None]
    return spectrum


def sky_table(sun_elevation: float, altitude_m: float, air: float, aerosol: float, ozone: float) -> np.ndarray:
    """The sky's CIE XYZ radiance table (TABLE_HEIGHT, TABLE_WIDTH, 3) float32 (the module's placement)."""
    cmf = _spectra()[3]
    w, h = TABLE_WIDTH, TABLE_HEIGHT
    half_w, half_h = w // 2, h // 2
    sun = np.array([np.cos(sun_elevation), 0.0, np.sin(sun_elevation)])
    lat = np.pi / 2 * (np.arange(h) / half_h - 1.0) ** 2
    lon = 2 * np.pi / w * np.arange(half_w) - np.pi
    la, lo = np.meshgrid(lat[half_h:], lon, indexing="ij")
    dirs = np.stack([np.cos(la) * np.cos(lo), np.cos(la) * np.sin(lo), np.sin(la)], axis=-1).reshape(-1, 3)
    scale = np.array([air, aerosol, ozone], np.float64)
    upper = in_parts(lambda part: _scattered(part, sun, _altitude(altitude_m), scale) @ cmf,
                     dirs).reshape(h - half_h, half_w, 3)
    table = np.empty((h, w, 3))
    table[half_h:, :half_w] = upper
    table[half_h:, half_w:] = upper[:, ::-1]
    z = np.sin(lat[:half_h])
    fade = np.where(z < 0.4, (1 - 2.5 * z) ** 3, 0.0)
    table[:half_h] = table[half_h][None] * fade[:, None, None]
    return np.ascontiguousarray(table, np.float32)


def sun_colors(sun_elevation: float, sun_size: float, altitude_m: float, air: float, aerosol: float) -> np.ndarray:
    """CIE XYZ radiance (2, 3) of the sun's disc at its lowest and highest points (``sun_size``: its angular
    diameter, radians); black while the disc's top is below the horizon."""
    irradiance, rayleigh, _ozone, cmf = _spectra()
    half = sun_size / 2
    solid_angle = 2 * np.pi * (1 - np.cos(half))
    if sun_elevation + half <= 0:
        return np.zeros((2, 3), np.float32)
    e = np.maximum(np.array([sun_elevation - half, sun_elevation + half]), 0.0)
    origin = np.array([[0.0, 0.0, EARTH_RADIUS + _altitude(altitude_m)]])
    out = []
    for elevation in e:
        depth = _optical_depth(origin, np.array([np.cos(elevation), 0.0, np.sin(elevation)]))[0]
        tau = rayleigh * depth[0] * air + _MIE_EXTINCTION * _MIE * depth[1] * aerosol
        out.append((irradiance * np.exp(-tau) / solid_angle) @ cmf)
    return np.asarray(out, np.float32)
