"""Blender's Sky Texture as Cycles evaluates it: scene-linear Rec.709 radiance (W·sr⁻¹·m⁻²) towards directions.

Three of its models are computed: Multiple Scattering (the default; sky_atmosphere.py) and Single Scattering
(sky_nishita.py), each a radiance table over directions relative to the sun, read bilinearly, plus the sun's disc
with limb darkening; Hosek / Wilkie (Hosek and Wilkie 2012: their CIE XYZ datasets, data/sky_hosek.json, a
quintic Bézier over the sun's elevation blended linearly in turbidity and ground albedo; radiance scaled by 2π/683
as Blender scales it); and Preetham (Preetham,
Shirley and Smits 1999: the Perez sky-luminance and chromaticity distributions of turbidity, scaled by 0.06 as
Blender scales them). Directions are z up; the node's Sun Elevation and Rotation place the sun as Blender does
(rotation about z, measured clockwise from +y seen from above). CIE XYZ goes to Rec.709 through the D65 matrix of
Blender's colour configuration, negative components clamped to 0.
"""
from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np

from . import sky_atmosphere, sky_nishita

#: CIE XYZ (D65) -> scene-linear Rec.709
XYZ_TO_REC709 = np.array([[3.2409699, -1.5373832, -0.4986108],
                          [-0.9692436, 1.8759675, 0.0415551],
                          [0.0556301, -0.2039770, 1.0569715]], np.float32)
#: the smallest Sun Size Cycles renders (radians)
MIN_SUN_SIZE = 0.0005
_LIMB_DARKENING = 0.6


def wrap_sun(elevation: float, rotation: float) -> tuple[float, float]:
    """(elevation in [-π/2, π/2], the sky's azimuth offset in [0, 2π]) of a sun at ``elevation`` and ``rotation``
    radians however far animated: past the zenith the sun comes down on the other side."""
    e = math.fmod(elevation, 2 * math.pi)
    if abs(e) >= math.pi:
        e -= math.copysign(2 * math.pi, e)
    if e >= math.pi / 2 or e <= -math.pi / 2:
        e = math.copysign(math.pi, e) - e
        rotation += math.pi
    r = math.fmod(rotation, 2 * math.pi)
    if r < 0:
        r += 2 * math.pi
    return e, 2 * math.pi - r


@dataclass(frozen=True)
class AtmosphereSky:
    """The Multiple Scattering sky: ``table`` CIE XYZ (256, 512, 3) (sky_atmosphere.sky_table), the sun placed by
    ``elevation`` / ``azimuth`` (wrap_sun's), its disc (``sun_size`` radians, None: no disc) of radiance between
    ``sun_bottom`` and ``sun_top`` (XYZ) times ``intensity``, hidden below ``-horizon_dip``."""
    table: np.ndarray = field(repr=False)
    elevation: float
    azimuth: float
    sun_size: float | None
    sun_bottom: np.ndarray = field(repr=False)
    sun_top: np.ndarray = field(repr=False)
    intensity: float
    horizon_dip: float

    @staticmethod
    def build(model: str, sun_disc: bool, sun_size: float, intensity: float, elevation: float, rotation: float,
              altitude: float, air: float, aerosol: float, ozone: float) -> "AtmosphereSky":
        """From the node's settings: ``model`` "MULTIPLE_SCATTERING" or "SINGLE_SCATTERING", angles in radians,
        ``altitude`` in metres, densities 1 = Earth's."""
        e, azimuth = wrap_sun(elevation, rotation)
        size = max(float(sun_size), MIN_SUN_SIZE)
        if model == "SINGLE_SCATTERING":
            bottom, top = sky_nishita.sun_colors(e, size, altitude, air, aerosol)
            table = sky_nishita.sky_table(e, altitude, air, aerosol, ozone)
        else:
            bottom, top = sky_atmosphere.sun_colors(e, size, altitude, air, aerosol, ozone)
            table = sky_atmosphere.sky_table(e, altitude, air, aerosol, ozone)
        return AtmosphereSky(table, e, azimuth, size if sun_disc else None, bottom, top, float(intensity),
                             sky_atmosphere.earth_intersection_angle(altitude))

    def sun_direction(self) -> np.ndarray:
        """Unit direction (3,) towards the sun's centre."""
        ce = math.cos(self.elevation)
        return np.array([-ce * math.sin(self.azimuth), ce * math.cos(self.azimuth), math.sin(self.elevation)],
                        np.float32)

    def xyz(self, d: np.ndarray, sun: bool = True) -> np.ndarray:
        """CIE XYZ radiance (3, n) towards directions ``d`` (3, n) (``sun`` False: without the sun's disc)."""
        d = np.asarray(d, np.float32)
        z = np.clip(d[2], -1, 1)
        elevation = np.float32(math.pi / 2) - np.arccos(z)
        phi = np.arctan2(d[1], d[0])
        u = np.mod((-phi - np.float32(math.pi / 2) + np.float32(self.azimuth)) / np.float32(2 * math.pi), 1.0)
        v = np.copysign(np.sqrt(np.abs(elevation) * np.float32(2 / math.pi)), elevation) * 0.5 + 0.5
        out = _bilinear_extend(self.table, u, v)
        if self.sun_size is not None and sun:
            sun = self.sun_direction()
            ln = np.sqrt((d * d).sum(axis=0))
            unit = d / np.maximum(ln, np.float32(1e-30))
            a, b = unit - sun[:, None], unit + sun[:, None]
            angle = 2 * np.arctan2(np.sqrt((a * a).sum(axis=0)), np.sqrt((b * b).sum(axis=0)))
            half = np.float32(self.sun_size / 2)
            inside = (angle < half) & (elevation > -self.horizon_dip)
            if inside.any():
                t = ((elevation[inside] - np.float32(self.elevation)) / np.float32(self.sun_size) + 0.5)[None]
                limb = 1 - _LIMB_DARKENING * (1 - np.sqrt(np.maximum(1 - (angle[inside] / half) ** 2, 0)))
                color = self.sun_bottom[:, None] + (self.sun_top - self.sun_bottom)[:, None] * t
                out[:, inside] += color * (np.float32(self.intensity) * limb)
        return out

    def radiance(self, d: np.ndarray, sun: bool = True) -> np.ndarray:
        """Scene-linear Rec.709 radiance (3, n) towards directions ``d`` (3, n) (``sun`` False: without the sun's
        disc)."""
        return np.maximum(XYZ_TO_REC709 @ self.xyz(d, sun), 0).astype(np.float32)

    def sun_cone(self):
        """(unit direction (3,), half-angle in radians) of the sun's disc, or None without one: where a baked
        image of this sky must be integrated finer than its texels."""
        return None if self.sun_size is None else (self.sun_direction(), self.sun_size / 2)


@dataclass(frozen=True)
class PreethamSky:
    """The Preetham sky: Perez coefficients (3, 5) for luminance Y and chromaticities x, y, their zenith values
    divided by the distribution at the zenith (3,), the sun's polar angle and azimuth (Cycles' convention:
    atan2(x, y))."""
    perez: np.ndarray = field(repr=False)
    zenith: np.ndarray = field(repr=False)
    sun_theta: float
    sun_phi: float

    @staticmethod
    def build(sun_direction, turbidity: float) -> "PreethamSky":
        d = np.asarray(sun_direction, np.float64)
        d = d / max(np.linalg.norm(d), 1e-30)
        theta, phi = math.acos(max(-1.0, min(1.0, d[2]))), math.atan2(d[0], d[1])
        t = float(turbidity)
        chi = (4 / 9 - t / 120) * (math.pi - 2 * theta)
        lum = ((4.0453 * t - 4.9710) * math.tan(chi) - 0.2155 * t + 2.4192) * 0.06
        th = np.array([theta ** 3, theta ** 2, theta, 1.0])
        cx = np.array([[0.00166, -0.00375, 0.00209, 0], [-0.02903, 0.06377, -0.03202, 0.00394],
                       [0.11693, -0.21196, 0.06052, 0.25886]]) @ th
        cy = np.array([[0.00275, -0.00610, 0.00317, 0], [-0.04214, 0.08970, -0.04153, 0.00516],
                       [0.15346, -0.26756, 0.06670, 0.26688]]) @ th
        zen_x = cx[0] * t * t + cx[1] * t + cx[2]
        zen_y = cy[0] * t * t + cy[1] * t + cy[2]
        perez = np.array([[0.1787, -1.4630, -0.3554, 0.4275, -0.0227, 5.3251, 0.1206, -2.5771, -0.0670, 0.3703],
                          [-0.0193, -0.2592, -0.0665, 0.0008, -0.0004, 0.2125, -0.0641, -0.8989, -0.0033, 0.0452],
                          [-0.0167, -0.2608, -0.0950, 0.0092, -0.0079, 0.2102, -0.0441, -1.6537, -0.0109, 0.0529]])
        coeffs = perez[:, 0::2] * t + perez[:, 1::2]
        zenith = np.array([lum, zen_x, zen_y]) / np.array([_perez(c, 0.0, theta) for c in coeffs])
        return PreethamSky(coeffs.astype(np.float32), zenith.astype(np.float32), theta, phi)

    def xyz(self, d: np.ndarray) -> np.ndarray:
        theta, gamma = _sky_angles(d, self.sun_theta, self.sun_phi)
        big_y, x, y = (self.zenith[i] * _perez(self.perez[i], theta, gamma) for i in range(3))
        safe_y = np.where(y != 0, y, 1)
        X = np.where(y != 0, x / safe_y * big_y, 0)
        Z = np.where((y != 0) & (big_y != 0), (1 - x - y) / safe_y * big_y, 0)
        return np.stack([X, big_y, Z]).astype(np.float32)

    def radiance(self, d: np.ndarray, sun: bool = True) -> np.ndarray:
        return np.maximum(XYZ_TO_REC709 @ self.xyz(d), 0).astype(np.float32)

    def sun_cone(self):
        return None


@lru_cache(maxsize=1)
def _hosek_data():
    with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "sky_hosek.json")) as f:
        d = json.load(f)
    return (np.asarray(d["config"], np.float64).reshape(3, 2, 10, 6, 9),
            np.asarray(d["radiance"], np.float64).reshape(3, 2, 10, 6))


def _hosek_cook(data: np.ndarray, turbidity: float, albedo: float, elevation: float) -> np.ndarray:
    """The model's values for one sky: ``data`` (3, 2, 10, 6, ...) blended over the Bézier control points at
    (elevation / (π/2))^(1/3), then linearly in albedo and turbidity (1..10)."""
    s = (max(elevation, 0.0) / (math.pi / 2)) ** (1 / 3)
    bernstein = np.array([math.comb(5, i) * (1 - s) ** (5 - i) * s ** i for i in range(6)])
    curve = np.tensordot(data, bernstein, axes=([3], [0]))  # (3, 2, 10, ...)
    low = int(turbidity)
    rem = turbidity - low
    out = (1 - albedo) * (1 - rem) * curve[:, 0, low - 1] + albedo * (1 - rem) * curve[:, 1, low - 1]
    if low < 10:
        out = out + (1 - albedo) * rem * curve[:, 0, low] + albedo * rem * curve[:, 1, low]
    return out


@dataclass(frozen=True)
class HosekSky:
    """The Hosek / Wilkie sky: nine parameters per XYZ channel (3, 9), the channels' radiances (3,), the sun's
    polar angle and azimuth (Cycles' convention, as PreethamSky)."""
    config: np.ndarray = field(repr=False)
    scale: np.ndarray = field(repr=False)
    sun_theta: float
    sun_phi: float

    @staticmethod
    def build(sun_direction, turbidity: float, albedo: float) -> "HosekSky":
        d = np.asarray(sun_direction, np.float64)
        d = d / max(np.linalg.norm(d), 1e-30)
        theta = min(max(math.acos(max(-1.0, min(1.0, d[2]))), 0.0), math.pi / 2)
        phi = math.atan2(d[0], d[1])
        t = min(max(float(turbidity), 1.0), 10.0)
        a = float(albedo)
        config, radiance = _hosek_data()
        elevation = math.pi / 2 - theta
        return HosekSky(_hosek_cook(config, t, a, elevation).astype(np.float32),
                        _hosek_cook(radiance, t, a, elevation).astype(np.float32), theta, phi)

    def xyz(self, d: np.ndarray) -> np.ndarray:
        theta, gamma = _sky_angles(d, self.sun_theta, self.sun_phi)
        ct, cg = np.cos(theta), np.cos(gamma)
        c = self.config[:, :, None]
        ray = cg * cg
        mie = (1 + ray) / np.power(1 + c[:, 8] * c[:, 8] - 2 * c[:, 8] * cg, np.float32(1.5))
        value = (1 + c[:, 0] * np.exp(c[:, 1] / (ct + np.float32(0.01)))) * (
            c[:, 2] + c[:, 3] * np.exp(c[:, 4] * gamma) + c[:, 5] * ray + c[:, 6] * mie + c[:, 7] * np.sqrt(ct))
        return (value * self.scale[:, None]).astype(np.float32)

    def radiance(self, d: np.ndarray, sun: bool = True) -> np.ndarray:
        return (np.maximum(XYZ_TO_REC709 @ self.xyz(d), 0) * np.float32(2 * math.pi / 683)).astype(np.float32)

    def sun_cone(self):
        return None


def _sky_angles(d: np.ndarray, sun_theta: float, sun_phi: float):
    """(polar angle clamped just above the horizon, angle to the sun) (n,) of directions ``d`` (3, n), as the
    analytic skies read them."""
    d = np.asarray(d, np.float32)
    theta = np.arccos(np.clip(d[2], -1, 1))
    phi = np.float32(math.pi / 2) - np.arctan2(d[1], d[0])
    cos_g = (np.sin(theta) * np.float32(math.sin(sun_theta)) * np.cos(phi - np.float32(sun_phi))
             + np.cos(theta) * np.float32(math.cos(sun_theta)))
    gamma = np.arccos(np.clip(cos_g, -1, 1))
    return np.minimum(theta, np.float32(math.pi / 2 - 0.001)), gamma


@lru_cache(maxsize=8)
def hosek_sky(sun_direction: tuple, turbidity: float, albedo: float) -> HosekSky:
    """HosekSky.build, kept for the next frame or viewport update."""
    return HosekSky.build(sun_direction, turbidity, albedo)


@lru_cache(maxsize=8)
def atmosphere_sky(*settings) -> AtmosphereSky:
    """AtmosphereSky.build of the node's settings, kept for the next frame or viewport update."""
    return AtmosphereSky.build(*settings)


@lru_cache(maxsize=8)
def preetham_sky(sun_direction: tuple, turbidity: float) -> PreethamSky:
    """PreethamSky.build, kept for the next frame or viewport update."""
    return PreethamSky.build(sun_direction, turbidity)


def _perez(c, theta, gamma):
    """The Perez distribution (1 + A e^(B / cos θ)) (1 + C e^(D γ) + E cos² γ)."""
    cg = np.cos(gamma)
    return (1 + c[0] * np.exp(c[1] / np.cos(theta))) * (1 + c[2] * np.exp(c[3] * gamma) + c[4] * cg * cg)


def _bilinear_extend(table: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(3, n) bilinear lookup of ``table`` (h, w, 3) at texture coordinates u, v in [0, 1] (texel centres at
    (i + 0.5) / w, rows bottom-up), the edge texels extended outwards."""
    h, w = table.shape[:2]
    x, y = u * np.float32(w) - 0.5, v * np.float32(h) - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0).astype(np.float32), (y - y0).astype(np.float32)
    x0, y0 = x0.astype(np.intp), y0.astype(np.intp)
    xa, xb = np.clip(x0, 0, w - 1), np.clip(x0 + 1, 0, w - 1)
    ya, yb = np.clip(y0, 0, h - 1), np.clip(y0 + 1, 0, h - 1)
    bottom = table[ya, xa] * (1 - fx)[:, None] + table[ya, xb] * fx[:, None]
    top = table[yb, xa] * (1 - fx)[:, None] + table[yb, xb] * fx[:, None]
    return (bottom * (1 - fy)[:, None] + top * fy[:, None]).T.astype(np.float32)
