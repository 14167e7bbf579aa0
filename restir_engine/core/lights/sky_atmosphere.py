"""The atmosphere behind Blender's Sky Texture of type Multiple Scattering: radiance of the clear sky (without the
sun's disc) over view directions, and the sun's radiance seen through the air.

The model is F. García Liñán's (master's thesis, 2022; the atmosphere Blender 5 ships): Earth's air as molecules
(Rayleigh scattering, ozone absorption) and aerosols (Henyey-Greenstein, g = 0.8) over a sphere of radius 6371 km
under 100 km of atmosphere, rendered at four wavelengths (630, 560, 490 and 430 nm) whose radiances map to CIE XYZ
through a fitted 4x3 matrix; single scattering integrated along the view ray in 64 midpoint steps (each step's
in-scattering integrated analytically over the step, as Hillaire's Frostbite sky), the light scattered more than
once approximated by a fit plus the ground's isotropic bounce (albedo 0.3), and the transmittance to the sun read
from a 256 x 64 table over (cos of the sun's zenith angle, altitude) built in 64 midpoint steps. The model's
constants are its published parameters; the code is a vectorized evaluation of that description.

Units: lengths in km, extinction in km⁻¹. The table holds CIE XYZ radiance (the unit the Sky Texture outputs before
its conversion to scene-linear RGB) over a 512 x 256 grid: u = azimuth / 2π from the sun's side (the sun at
azimuth π), v with elevation = sign(l) l² π/2 for l = 2v - 1 (more rows near the horizon), rows bottom-up.
"""
from __future__ import annotations

import numpy as np

from ..parallel.pool import run_chunks

EARTH_RADIUS = 6371.0
ATMOSPHERE_THICKNESS = 100.0
ATMOSPHERE_RADIUS = EARTH_RADIUS + ATMOSPHERE_THICKNESS
TABLE_WIDTH, TABLE_HEIGHT = 512, 256
_STEPS = 64
_T_WIDTH, _T_HEIGHT = 256, 64

_SUN_IRRADIANCE = np.array([1.679, 1.828, 1.986, 1.307])
_MOLECULAR_SCATTERING = np.array([6.605e-3, 1.067e-2, 1.842e-2, 3.156e-2])
_OZONE_CROSS_SECTION = np.array([3.472e-25, 3.914e-25, 1.349e-25, 11.03e-27])
_OZONE_DOBSON = 334.5
_AEROSOL_ABSORPTION = np.array([2.8722e-24, 4.6168e-24, 7.9706e-24, 1.3578e-23])
_AEROSOL_SCATTERING = np.array([1.5908e-22, 1.7711e-22, 2.0942e-22, 2.4033e-22])
_AEROSOL_DENSITY, _AEROSOL_BACKGROUND, _AEROSOL_HEIGHT = 1.3681e20, 2e6, 0.73
_AEROSOL_G = 0.8
_GROUND_ALBEDO = 0.3
_MULTIPLE_FIT = 0.02 * np.array([0.217, 0.347, 0.594, 1.0])
#: radiance at the four wavelengths -> CIE XYZ (rows: wavelengths)
_SPECTRAL_XYZ = np.array([[53.386917738564668, 22.981337506691025, 0.0],
                          [43.904844466369358, 71.347795700053394, 0.102506867965741],
                          [1.6137278251608962, 18.422960591455485, 31.742921188390806],
                          [20.762668673810577, 2.3614213523314369, 110.48009643252140]])


def altitude_km(altitude_m: float) -> float:
    """The viewer's altitude above the ground in km from the node's metres (kept within 1 m .. 99.999 km)."""
    return float(np.clip(altitude_m, 1.0, 99999.0)) / 1000.0


def earth_intersection_angle(altitude_m: float) -> float:
    """How far below the horizon (radians) the ground starts as seen from ``altitude_m`` metres (the sun's disc is
    hidden below it)."""
    return float(np.pi / 2 - np.arcsin(EARTH_RADIUS / (EARTH_RADIUS + altitude_m / 1000.0)))


class Atmosphere:
    """The air's densities (1 = Earth's average) and what follows from them: collision coefficients by altitude and
    the table of transmittance to the sun."""

    def __init__(self, air: float, aerosol: float, ozone: float):
        self.air, self.aerosol, self.ozone = float(air), float(aerosol), float(ozone)
        u = np.arange(_T_WIDTH) / (_T_WIDTH - 1)
        v = np.arange(_T_HEIGHT) / (_T_HEIGHT - 1)
        cos_t, height = np.meshgrid(u * 2 - 1, v, indexing="xy")
        self.transmittance_table = self.transmittance(cos_t.ravel(), height.ravel()).reshape(_T_HEIGHT, _T_WIDTH, 4)

    def coefficients(self, h: np.ndarray):
        """(scattering by molecules, scattering by aerosols, extinction) (n, 4) km⁻¹ at altitudes ``h`` (n,) km."""
        molecular = _MOLECULAR_SCATTERING * (np.exp(-0.07771971 * np.power(h, 1.16364243)) * self.air)[:, None]
        log_h = np.log(np.maximum(h, 1e-4))
        ozone = 3.78547397e20 * np.exp(-(log_h - 3.22261) ** 2 * 5.55555555 - log_h) * self.ozone
        absorption = (_OZONE_CROSS_SECTION * _OZONE_DOBSON) * ozone[:, None]
        density = (_AEROSOL_DENSITY * (np.exp(-h / _AEROSOL_HEIGHT) + _AEROSOL_BACKGROUND / _AEROSOL_DENSITY)
                   * self.aerosol)[:, None]
        aerosol_scattering = _AEROSOL_SCATTERING * density
        return molecular, aerosol_scattering, molecular + absorption + aerosol_scattering + _AEROSOL_ABSORPTION * density

    def transmittance(self, cos_zenith: np.ndarray, height: np.ndarray) -> np.ndarray:
        """Transmittance (n, 4) from normalized altitudes ``height`` (n,) (0 ground, 1 the atmosphere's top) to the
        sun at zenith cosines ``cos_zenith`` (n,), integrated in midpoint steps."""
        cos_zenith = np.asarray(cos_zenith, np.float64)
        r = EARTH_RADIUS + np.asarray(height, np.float64) * ATMOSPHERE_THICKNESS
        sin_z = np.sqrt(np.maximum(1 - cos_zenith ** 2, 0))
        t_end = _leave_sphere(r * cos_zenith, r * r, ATMOSPHERE_RADIUS)
        step = t_end / _STEPS
        depth = np.zeros((len(r), 4))
        for i in range(_STEPS):
            t = (i + 0.5) * step
            x, z = -sin_z * t, r + cos_zenith * t
            h = np.maximum(np.sqrt(x * x + z * z) - EARTH_RADIUS, 0.0)
            depth += self.coefficients(h)[2] * step[:, None]
        return np.exp(-depth)

    def _lookup(self, cos_zenith: np.ndarray, height: np.ndarray) -> np.ndarray:
        """The transmittance table read bilinearly (n, 4)."""
        x = (_T_WIDTH - 1) * np.clip(cos_zenith * 0.5 + 0.5, 0, 1)
        y = (_T_HEIGHT - 1) * np.clip(height, 0, 1)
        x1, y1 = x.astype(np.intp), y.astype(np.intp)
        dx, dy = np.minimum(x1 + 1, _T_WIDTH - 1) - x1, (np.minimum(y1 + 1, _T_HEIGHT - 1) - y1) * _T_WIDTH
        fx, fy = (x - x1)[:, None], (y - y1)[:, None]
        flat = self.transmittance_table.reshape(-1, 4)
        i = y1 * _T_WIDTH + x1
        a, b, c, d = flat.take(i, 0), flat.take(i + dx, 0), flat.take(i + dy, 0), flat.take(i + dy + dx, 0)
        bottom = a + (b - a) * fx
        return bottom + (c + (d - c) * fx - bottom) * fy

    @staticmethod
    def _linear(line: np.ndarray, x: np.ndarray) -> np.ndarray:
        """One row or column (m, 4) of the table read linearly at positions ``x`` (n,) in texels."""
        x1 = x.astype(np.intp)
        a, b = line.take(x1, 0), line.take(np.minimum(x1 + 1, len(line) - 1), 0)
        return a + (b - a) * (x - x1)[:, None]

    def _multiple(self, cos_zenith: np.ndarray, height: np.ndarray, r: np.ndarray) -> np.ndarray:
        """Radiance (n, 4) per unit sun irradiance and scattering coefficient that reaches a point by more than
        one scattering: the fit of the atmosphere's own, plus the sunlit ground's isotropic bounce."""
        omega = 2 * np.pi * (1 - np.sqrt(np.maximum(1 - (EARTH_RADIUS / r) ** 2, 0)))  # the ground's solid angle
        table = self.transmittance_table
        to_ground = self._linear(table[0], (_T_WIDTH - 1) * np.clip(cos_zenith * 0.5 + 0.5, 0, 1))
        overhead = table[:, -1]
        ground_to_point = overhead[0] / self._linear(overhead, (_T_HEIGHT - 1) * np.clip(height, 0, 1))
        ground = (omega * cos_zenith / (4 * np.pi))[:, None] * (_GROUND_ALBEDO / np.pi) * to_ground * ground_to_point
        fit = _MULTIPLE_FIT / (1 + 5 * np.exp(-17.92 * cos_zenith))[:, None]
        return fit + ground

    def sky(self, sun_elevation: float, altitude: float, directions: np.ndarray) -> np.ndarray:
        """CIE XYZ radiance (n, 3) scattered towards a viewer ``altitude`` km above the ground looking along unit
        ``directions`` (n, 3) (z up), the sun at ``sun_elevation`` radians towards -x (the sun's disc left out)."""
        d = np.asarray(directions, np.float64)
        sun = np.array([-np.cos(sun_elevation), 0.0, np.sin(sun_elevation)])
        r0 = EARTH_RADIUS + altitude
        b = r0 * d[:, 2]
        ground = _hit_sphere_from_outside(b, r0 * r0, EARTH_RADIUS)
        t_end = np.where(ground < 0, _leave_sphere(b, r0 * r0, ATMOSPHERE_RADIUS), ground)
        cos_sun = -(d @ sun)
        molecular_phase = 3 / (16 * np.pi) * (1 + cos_sun ** 2)
        den = 1 + _AEROSOL_G ** 2 + 2 * _AEROSOL_G * cos_sun
        aerosol_phase = (1 - _AEROSOL_G ** 2) / (4 * np.pi * den * np.sqrt(den))
        dt = t_end / _STEPS
        radiance = np.zeros((len(d), 4))
        through = np.ones((len(d), 4))
        for i in range(_STEPS):
            t = (i + 0.5) * dt
            p = d * t[:, None]
            p[:, 2] += r0
            r = np.sqrt((p * p).sum(axis=1))
            h = np.maximum(r - EARTH_RADIUS, 0.0)
            height = h / ATMOSPHERE_THICKNESS
            cos_zenith = (p @ sun) / r
            molecular, aerosol, extinction = self.coefficients(h)
            to_sun = self._lookup(cos_zenith, height)
            multiple = self._multiple(cos_zenith, height, r)
            source = _SUN_IRRADIANCE * (molecular * (molecular_phase[:, None] * to_sun + multiple)
                                        + aerosol * (aerosol_phase[:, None] * to_sun + multiple))
            step_through = np.exp(-dt[:, None] * extinction)
            radiance += through * source * (1 - step_through) / np.maximum(extinction, 1e-7)
            through *= step_through
        return radiance @ _SPECTRAL_XYZ

    def sun(self, elevation: np.ndarray, altitude: float, solid_angle: float) -> np.ndarray:
        """CIE XYZ radiance (n, 3) of the sun's disc of ``solid_angle`` sr seen at ``elevation`` (n,) radians from
        ``altitude`` km: the sun's irradiance through the air, spread over the disc."""
        e = np.atleast_1d(np.asarray(elevation, np.float64))
        through = self.transmittance(np.sin(e), np.full(e.shape, altitude / ATMOSPHERE_THICKNESS))
        return (_SUN_IRRADIANCE * through / solid_angle) @ _SPECTRAL_XYZ


def sky_table(sun_elevation: float, altitude_m: float, air: float, aerosol: float, ozone: float) -> np.ndarray:
    """The sky's CIE XYZ radiance table (TABLE_HEIGHT, TABLE_WIDTH, 3) float32 (see the module's conventions); the
    two halves in azimuth mirror each other about the sun's vertical plane, so one is computed."""
    atmosphere = Atmosphere(air, aerosol, ozone)
    half = TABLE_WIDTH // 2
    cols, rows = np.meshgrid(np.arange(half), np.arange(TABLE_HEIGHT), indexing="xy")
    azimuth = 2 * np.pi * (cols.ravel() + 0.5) / TABLE_WIDTH
    lv = 2 * (rows.ravel() + 0.5) / TABLE_HEIGHT - 1
    elevation = np.copysign(lv * lv, lv) * (np.pi / 2)
    dirs = np.stack([np.cos(elevation) * np.cos(azimuth), np.cos(elevation) * np.sin(azimuth), np.sin(elevation)], 1)
    left = in_parts(lambda part: atmosphere.sky(float(sun_elevation), altitude_km(altitude_m), part),
                    dirs).reshape(TABLE_HEIGHT, half, 3)
    return np.ascontiguousarray(np.concatenate([left, left[:, ::-1]], axis=1), np.float32)


def sun_colors(sun_elevation: float, sun_size: float, altitude_m: float, air: float, aerosol: float,
               ozone: float) -> np.ndarray:
    """CIE XYZ radiance (2, 3) of the sun's disc at its lowest and highest points (``sun_size``: its angular
    diameter in radians)."""
    half = sun_size / 2
    solid_angle = 2 * np.pi * (1 - np.cos(half))
    atmosphere = Atmosphere(air, aerosol, ozone)
    return atmosphere.sun(np.array([sun_elevation - half, sun_elevation + half]), altitude_km(altitude_m),
                          solid_angle).astype(np.float32)


def in_parts(fn, dirs: np.ndarray, parts: int = 8) -> np.ndarray:
    """``fn(dirs)`` (n, 3) computed over ``parts`` slices of ``dirs`` (n, 3) on the thread pool."""
    out = np.empty((len(dirs), 3))
    step = -(-len(dirs) // parts)

    def part(span):
        out[span] = fn(dirs[span])
    run_chunks(part, [slice(a, min(len(dirs), a + step)) for a in range(0, len(dirs), step)])
    return out


def _leave_sphere(b: np.ndarray, r2: np.ndarray, radius: float) -> np.ndarray:
    """Distance along a ray from a point inside a sphere about the origin (|p|² = r2, b = p·d) to where it leaves."""
    return -b + np.sqrt(np.maximum(b * b - (r2 - radius * radius), 0.0))


def _hit_sphere_from_outside(b: np.ndarray, r2: float, radius: float) -> np.ndarray:
    """Distance to a sphere about the origin from a point outside it (-1 where the ray misses or points away)."""
    c = r2 - radius * radius
    disc = b * b - c
    hit = (disc >= 0) & ~((c > 0) & (b > 0))
    return np.where(hit, -b - np.sqrt(np.maximum(disc, 0.0)), -1.0)
