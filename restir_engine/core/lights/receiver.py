"""What a lamp's radiance is multiplied by towards a receiver: the spot cone's attenuation, the Light Falloff node's
distance factor and the colour of a node texture that varies over the lamp (lights/lamp_textures.py). Every estimator
that meets a lamp applies :func:`receiver_factor` (light sampling, BSDF hits on lamps, ReSTIR DI's targets and
shading); a lamp with any of them is receiver-dependent (scene.Lamps.receiver_dependent)."""
from __future__ import annotations

import numpy as np

from ..sampling import cols, dot, norm
from ..scene import Lamps
from .lamp_textures import lamp_texture_factor


def spot_factor(lamps: Lamps, lamp_tri: np.ndarray, p: np.ndarray, q: np.ndarray | None = None) -> np.ndarray:
    """Receiver-dependent factor (n,) of lamp triangles' radiance seen from points p ((3, n) rows): the spot cone's
    attenuation (Cycles' smoothstep blend) of the direction from the light point q to p, times the lamp's Light
    Falloff, d^k · d² / (s + d²) (the last factor only where s > 0) with d the distance from p to q ((3, n); None:
    the lamp's centre)."""
    cos_cut = lamps.spot_cos[lamp_tri]
    out = np.ones(len(lamp_tri), np.float32)
    spot = np.flatnonzero(cos_cut > -1.5)
    if spot.size:  # the cone about the direction from the light point (Cycles' spot_light_to_local(-D))
        tri = lamp_tri[spot]
        d = np.take(p, spot, axis=1) - (lamps.spot_center[tri].T if q is None else np.take(q, spot, axis=1))
        d /= np.maximum(norm(d), 1e-30)
        t = dot(d, lamps.spot_axis[tri].T)
        sm = lamps.spot_smooth[tri]
        cut = cos_cut[spot]
        x = np.where(sm > 0, (t - cut) / np.maximum(sm, 1e-12), np.where(t > cut, 1.0, 0.0))
        x = np.clip(x, 0.0, 1.0)
        out[spot] = x * x * (3 - 2 * x)
    k, s = (a[lamp_tri] for a in lamps.falloff_terms())
    off = np.flatnonzero((k != 0) | (s > 0))
    if off.size:
        tri = lamp_tri[off]
        at = lamps.spot_center[tri].T if q is None else np.take(q, off, axis=1)
        d = norm(np.take(p, off, axis=1) - at).astype(np.float32)
        d2 = d * d
        f = np.power(d, k[off]) * np.where(s[off] > 0, d2 / np.maximum(s[off] + d2, np.float32(1e-30)), np.float32(1))
        out[off] *= f.astype(np.float32)
    return out


def texture_factor(lamps: Lamps, lamp_tri: np.ndarray, p: np.ndarray, q: np.ndarray) -> np.ndarray | None:
    """Colour factor (3, n) of lamp triangles ``lamp_tri`` whose node graph varies over the lamp
    (lights/lamp_textures.py) at light points q seen from receivers p ((3, n) rows), 1 for the others; None where
    none of them is textured."""
    lt = lamps.textured
    if lt is None or not len(lamp_tri):
        return None
    sel = np.flatnonzero(lt.textured(lamp_tri))
    if not sel.size:
        return None
    out = np.ones((3, len(lamp_tri)), np.float32)
    t = lamp_tri[sel]
    normals = np.ascontiguousarray(lamps.tris.normals[t, 0].T)
    out[:, sel] = lamp_texture_factor(lt, t, cols(p, sel), cols(q, sel), normals)
    return out


def receiver_factor(lamps: Lamps, lamp_tri: np.ndarray, p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """What the radiance of lamp triangles ``lamp_tri`` at light points q is multiplied by towards receivers p
    ((3, n) rows): :func:`spot_factor` (n,), times :func:`texture_factor` (then (3, n)) where a lamp is textured."""
    f = spot_factor(lamps, lamp_tri, p, q)
    tex = texture_factor(lamps, lamp_tri, p, q)
    return f if tex is None else tex * f
