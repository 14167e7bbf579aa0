"""Cycles' Perlin noise and its fractal sums in 1-4 dimensions, vectorized over points: the same lattice hashes,
gradients, fade curve, scale factors and fractal recurrences, so a Noise Texture gives the same pattern as in
Cycles. Coordinates are float32 arrays of one shape; results float32 of that shape."""
from __future__ import annotations

import numpy as np

from .hashing import hash_floats, hash_uint

_F = np.float32
#: the signed noise's scale per dimension (so that it spans about [-1, 1])
SCALE = (None, _F(0.25), _F(0.6616), _F(0.9820), _F(0.8344))


def _fade(t):
    return t * t * t * (t * (t * _F(6.0) - _F(15.0)) + _F(10.0))


def _neg(v, bit):
    return np.where(bit != 0, -v, v)


def _grad1(h, x):
    h = h & np.uint32(15)
    g = _F(1.0) + (h & np.uint32(7)).astype(np.float32)
    return _neg(g, h & np.uint32(8)) * x


def _grad2(h, x, y):
    h = h & np.uint32(7)
    lo = h < 4
    u = np.where(lo, x, y)
    v = _F(2.0) * np.where(lo, y, x)
    return _neg(u, h & np.uint32(1)) + _neg(v, h & np.uint32(2))


def _grad3(h, x, y, z):
    h = h & np.uint32(15)
    u = np.where(h < 8, x, y)
    vt = np.where((h == 12) | (h == 14), x, z)
    v = np.where(h < 4, y, vt)
    return _neg(u, h & np.uint32(1)) + _neg(v, h & np.uint32(2))


def _grad4(h, x, y, z, w):
    h = h & np.uint32(31)
    u = np.where(h < 24, x, y)
    v = np.where(h < 16, y, z)
    s = np.where(h < 8, z, w)
    return _neg(u, h & np.uint32(1)) + _neg(v, h & np.uint32(2)) + _neg(s, h & np.uint32(4))


_GRAD = (None, _grad1, _grad2, _grad3, _grad4)
_MASK = (None, 15, 7, 15, 31)


def _gradient_tables(dim: int) -> np.ndarray:
    """(dim, mask + 1) float32: each gradient as its coefficients on the fractional coordinates (the gradient
    functions are linear in them, with coefficients 0, ±1, ±2 or ±(1..8)), so a corner's value is a sum of
    products of table entries (exact: the same float32 result as the branches)."""
    h = np.arange(_MASK[dim] + 1, dtype=np.uint32)
    eye = np.eye(dim, dtype=np.float32)
    return np.stack([_GRAD[dim](h, *[np.full(h.shape, eye[k, j]) for j in range(dim)]) for k in range(dim)]
                    ).astype(np.float32)


_TABLES = (None,) + tuple(_gradient_tables(d) for d in (1, 2, 3, 4))


def perlin(*coords) -> np.ndarray:
    """Raw (unscaled) Perlin noise at points of 1-4 coordinates: gradients at the lattice corners hashed from their
    integer coordinates, blended multilinearly (first axis innermost) with the quintic fade. Every corner is hashed
    and weighed in one pass over a leading axis of the 2ᵈ corners (corner c has bit k of c set where it lies one
    cell up along axis k)."""
    dim = len(coords)
    corners = 1 << dim
    cells, fracs, fades = [], [], []
    for c in coords:
        c = np.asarray(c, np.float32)
        f = np.floor(c)
        cells.append(f.astype(np.int64).astype(np.int32).view(np.uint32))
        fr = (c - f).astype(np.float32)
        fracs.append(fr)
        fades.append(_fade(fr))
    shape = np.broadcast_shapes(*[f.shape for f in fracs])
    up = ((np.arange(corners)[:, None] >> np.arange(dim)[None]) & 1).reshape((corners, dim) + (1,) * len(shape))
    table, mask = _TABLES[dim], np.uint32(_MASK[dim])
    with np.errstate(over="ignore"):
        keys = [cells[k] + up[:, k].astype(np.uint32) for k in range(dim)]  # (corners, ...)
    h = (hash_uint(*keys) & mask).astype(np.intp)
    v = None
    for k in range(dim):
        term = np.take(table[k], h) * (fracs[k] - up[:, k].astype(np.float32))
        v = term if v is None else v + term
    # blend along axis 0 first (pairs of corners differing in bit 0), then axis 1, ...: bit 0 is the last of the
    # corner axes once they are split into (2,) * dim
    v = v.reshape((2,) * dim + shape)
    for k in range(dim):
        lo, hi = v[(slice(None),) * (dim - 1 - k) + (0,)], v[(slice(None),) * (dim - 1 - k) + (1,)]
        v = lo + fades[k] * (hi - lo)
    return np.asarray(v, np.float32)


def snoise(*coords) -> np.ndarray:
    """Signed noise in about [-1, 1] (Cycles' snoise: coordinates wrapped by fmod 1e5, with half a cell added
    beyond 1e6 for precision; non-finite results are 0)."""
    dim = len(coords)
    wrapped = []
    for c in coords:
        c = np.asarray(c, np.float32)
        corr = _F(0.5) * (np.abs(c) >= _F(1e6)).astype(np.float32)
        wrapped.append((np.fmod(c, _F(1e5)) + corr).astype(np.float32))
    r = perlin(*wrapped)
    r = np.where(np.isfinite(r), r, _F(0.0))
    return (SCALE[dim] * r).astype(np.float32)


def offset(seed: float, dim: int) -> list:
    """Cycles' random coordinate offsets for seed ``seed``: 100 + 100 · hash, per axis (1D: hash of the seed)."""
    if dim == 1:
        return [_F(100.0) + _F(100.0) * hash_floats(np.float32(seed))]
    return [_F(100.0) + _F(100.0) * hash_floats(np.float32(seed), np.float32(k)) for k in range(dim)]


def fractal(kind: str, coords: list, detail, roughness, lacunarity, off, gain, normalize: bool) -> np.ndarray:
    """Fractal sums of signed noise over octaves at coords · lacunarityⁱ (Cycles' noise types): "FBM" (normalized to
    [0, 1] when ``normalize``), "MULTIFRACTAL", "HETERO_TERRAIN", "HYBRID_MULTIFRACTAL", "RIDGED_MULTIFRACTAL".
    ``detail`` (octaves beyond the first, fraction blends the last), ``roughness`` (amplitude ratio), ``off``,
    ``gain`` are per point or constant."""
    coords = [np.asarray(c, np.float32) for c in coords]
    if all(np.ndim(x) == 0 for x in (detail, roughness, lacunarity, off, gain)):
        return _fractal_uniform(kind, coords, float(detail), float(roughness), float(lacunarity), float(off),
                                float(gain), normalize)
    return _fractal_masked(kind, coords, detail, roughness, lacunarity, off, gain, normalize)


def _fractal_masked(kind, coords, detail, roughness, lacunarity, off, gain, normalize):
    """:func:`fractal` with per-point parameters: the octave loop with a mask of the points still summing."""
    shape = np.broadcast_shapes(*[c.shape for c in coords], *[np.shape(x) for x in (detail, roughness, lacunarity,
                                                                                      off, gain)])
    coords = [np.broadcast_to(c, shape) for c in coords]
    detail = np.clip(np.broadcast_to(np.asarray(detail, np.float32), shape), 0, 15)
    rough = np.maximum(np.broadcast_to(np.asarray(roughness, np.float32), shape), 0)
    lac = np.broadcast_to(np.asarray(lacunarity, np.float32), shape)
    off = np.broadcast_to(np.asarray(off, np.float32), shape)
    gain = np.broadcast_to(np.asarray(gain, np.float32), shape)
    n = np.floor(detail).astype(np.int32)
    rmd = (detail - np.floor(detail)).astype(np.float32)
    top = int(n.max()) if n.size else 0
    scale = np.ones(shape, np.float32)
    amp = np.ones(shape, np.float32)

    def octave(i_scale):
        return snoise(*[c * i_scale for c in coords])

    if kind == "FBM":
        total = np.zeros(shape, np.float32)
        maxamp = np.zeros(shape, np.float32)
        for i in range(top + 1):
            on = i <= n
            t = octave(scale)
            total = np.where(on, total + t * amp, total)
            maxamp = np.where(on, maxamp + amp, maxamp)
            amp = np.where(on, amp * rough, amp)
            scale = np.where(on, scale * lac, scale)
        t = octave(scale) if (rmd > 0).any() else np.zeros(shape, np.float32)
        total2 = total + t * amp
        if normalize:
            a = _F(0.5) * total / maxamp + _F(0.5)
            b = _F(0.5) * total2 / (maxamp + amp) + _F(0.5)
        else:
            a, b = total, total2
        return np.where(rmd != 0, a + rmd * (b - a), a).astype(np.float32)
    if kind == "MULTIFRACTAL":
        value = np.ones(shape, np.float32)
        for i in range(top + 1):
            on = i <= n
            value = np.where(on, value * (amp * octave(scale) + _F(1.0)), value)
            amp = np.where(on, amp * rough, amp)
            scale = np.where(on, scale * lac, scale)
        if (rmd > 0).any():
            value = np.where(rmd != 0, value * (rmd * amp * octave(scale) + _F(1.0)), value)
        return value.astype(np.float32)
    if kind == "HETERO_TERRAIN":
        value = off + octave(scale)
        scale = scale * lac
        for i in range(1, top + 1):
            on = i <= n
            amp = np.where(on, amp * rough, amp)
            value = np.where(on, value + (octave(scale) + off) * amp * value, value)
            scale = np.where(on, scale * lac, scale)
        if (rmd > 0).any():
            amp2 = amp * rough
            value = np.where(rmd != 0, value + rmd * (octave(scale) + off) * amp2 * value, value)
        return value.astype(np.float32)
    if kind == "HYBRID_MULTIFRACTAL":
        value = np.zeros(shape, np.float32)
        weight = np.ones(shape, np.float32)
        for i in range(top + 1):
            on = (i <= n) & (weight > _F(0.001))
            weight = np.where(on, np.minimum(weight, _F(1.0)), weight)
            signal = (octave(scale) + off) * amp
            value = np.where(on, value + weight * signal, value)
            weight = np.where(on, weight * gain * signal, weight)
            amp = np.where(on, amp * rough, amp)
            scale = np.where(on, scale * lac, scale)  # (a point whose weight fell to 0.001 has stopped)
        last = (rmd != 0) & (weight > _F(0.001))
        if last.any():
            w = np.minimum(weight, _F(1.0))
            value = np.where(last, value + rmd * w * (octave(scale) + off) * amp, value)
        return value.astype(np.float32)
    if kind == "RIDGED_MULTIFRACTAL":
        signal = off - np.abs(octave(scale))
        signal = signal * signal
        value = signal.copy()
        weight = np.ones(shape, np.float32)
        for i in range(1, top + 1):
            on = i <= n
            scale = np.where(on, scale * lac, scale)
            weight = np.where(on, np.clip(signal * gain, 0, 1), weight)
            s = off - np.abs(octave(scale))
            s = s * s * weight
            amp = np.where(on, amp * rough, amp)
            value = np.where(on, value + s * amp, value)
            signal = np.where(on, s, signal)
        return value.astype(np.float32)
    raise ValueError(f"unknown noise type {kind!r}")


def _fractal_uniform(kind, coords, detail, roughness, lacunarity, off, gain, normalize):
    """:func:`fractal` with every parameter constant (the usual case): the octave loop without per-point masks
    (the same arithmetic in float32, so the same values)."""
    detail = min(max(detail, 0.0), 15.0)
    rough = _F(max(roughness, 0.0))
    lac, off, gain = _F(lacunarity), _F(off), _F(gain)
    n = int(np.floor(detail))
    rmd = _F(detail - np.floor(detail))
    scale, amp = _F(1.0), _F(1.0)

    if kind in {"FBM", "MULTIFRACTAL", "HETERO_TERRAIN"}:
        # every octave's noise in one pass: the octaves' scales 1, lac, lac², ... (float32, in sequence), the
        # fraction's octave included, along a new leading axis
        scales = [scale]
        for _i in range(n + (1 if rmd != 0 else 0)):
            scales.append(scales[-1] * lac)
        lead = (len(scales),) + (1,) * max(np.ndim(c) for c in coords)
        sc = np.array(scales, np.float32).reshape(lead)
        noise = snoise(*[c * sc for c in coords])
        octave = iter(noise).__next__
    if kind == "FBM":
        total, maxamp = _F(0.0), _F(0.0)
        for _i in range(n + 1):
            total = total + octave() * amp
            maxamp = maxamp + amp
            amp = amp * rough
        if normalize:
            a = _F(0.5) * total / maxamp + _F(0.5)
        else:
            a = total
        if rmd != 0:
            total2 = total + octave() * amp
            b = _F(0.5) * total2 / (maxamp + amp) + _F(0.5) if normalize else total2
            a = a + rmd * (b - a)
        return np.asarray(a, np.float32)
    if kind == "MULTIFRACTAL":
        value = _F(1.0)
        for _i in range(n + 1):
            value = value * (amp * octave() + _F(1.0))
            amp = amp * rough
        if rmd != 0:
            value = value * (rmd * amp * octave() + _F(1.0))
        return np.asarray(value, np.float32)
    if kind == "HETERO_TERRAIN":
        value = off + octave()
        for _i in range(1, n + 1):
            amp = amp * rough
            value = value + (octave() + off) * amp * value
        if rmd != 0:
            value = value + rmd * (octave() + off) * (amp * rough) * value
        return np.asarray(value, np.float32)
    # hybrid and ridged keep per-point state (a weight): the masked loop
    shape = np.broadcast_shapes(*[c.shape for c in coords])
    return _fractal_masked(kind, coords, np.full(shape, detail, np.float32), roughness, lacunarity, off, gain,
                           normalize)
