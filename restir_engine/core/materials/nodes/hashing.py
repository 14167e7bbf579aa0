"""Bob Jenkins' lookup3 hash over uint32 keys, vectorized, as Cycles hashes texture lattice points and coordinates:
``a = b = c = 0xdeadbeef + 4 n + 13`` for n keys, the keys added to a, b, c (a fourth after one ``mix`` round), then
``final``; the result is c. Float keys hash their IEEE-754 bits; a hash becomes a float in [0, 1] as
float32(h) · 2⁻³². Every array is uint32 and wraps."""
from __future__ import annotations

import numpy as np

_U = np.uint32


def _rot(x: np.ndarray, k: int) -> np.ndarray:
    return (x << _U(k)) | (x >> _U(32 - k))


def _final(a, b, c):
    c ^= b
    c -= _rot(b, 14)
    a ^= c
    a -= _rot(c, 11)
    b ^= a
    b -= _rot(a, 25)
    c ^= b
    c -= _rot(b, 16)
    a ^= c
    a -= _rot(c, 4)
    b ^= a
    b -= _rot(a, 14)
    c ^= b
    c -= _rot(b, 24)
    return c


def _mix(a, b, c):
    a -= c
    a ^= _rot(c, 4)
    c += b
    b -= a
    b ^= _rot(a, 6)
    a += c
    c -= b
    c ^= _rot(b, 8)
    b += a
    a -= c
    a ^= _rot(c, 16)
    c += b
    b -= a
    b ^= _rot(a, 19)
    a += c
    c -= b
    c ^= _rot(b, 4)
    b += a
    return a, b, c


def hash_uint(*keys) -> np.ndarray:
    """lookup3 of 1-4 uint32 keys (arrays of one shape, or broadcastable) -> uint32."""
    keys = np.broadcast_arrays(*[np.asarray(k).astype(np.uint32) for k in keys])
    n = len(keys)
    with np.errstate(over="ignore"):
        init = np.full(keys[0].shape, 0xDEADBEEF + (n << 2) + 13, np.uint32)
        a, b, c = init.copy(), init.copy(), init
        a += keys[0]
        if n > 1:
            b += keys[1]
        if n > 2:
            c += keys[2]
        if n > 3:
            a, b, c = _mix(a, b, c)
            a += keys[3]
        return _final(a, b, c)


def to_unit(h: np.ndarray) -> np.ndarray:
    """uint32 hash -> float32 in [0, 1] (float32(h) · 2⁻³², which may round to 1)."""
    return h.astype(np.float32) * np.float32(1.0 / 4294967296.0)


def float_bits(x) -> np.ndarray:
    """The IEEE-754 bits of float32 values as uint32."""
    x = np.asarray(x, np.float32)
    return np.ascontiguousarray(x).view(np.uint32).reshape(x.shape)


def hash_floats(*xs) -> np.ndarray:
    """Cycles' hash_floatN_to_float: lookup3 of the float32 bits of 1-4 values -> float32 in [0, 1]."""
    xs = np.broadcast_arrays(*[np.asarray(x, np.float32) for x in xs])
    return to_unit(hash_uint(*[float_bits(x) for x in xs]))


def hash_floats_to_color(*xs) -> np.ndarray:
    """Cycles' hash_floatN_to_float3 -> (3, ...) float32: for one to three keys, h(k), h(k, 1), h(k, 2); for four,
    h(x, y, z, w), h(z, x, w, y), h(w, z, y, x)."""
    xs = np.broadcast_arrays(*[np.asarray(x, np.float32) for x in xs])
    if len(xs) == 4:
        x, y, z, w = xs
        return np.stack([hash_floats(x, y, z, w), hash_floats(z, x, w, y), hash_floats(w, z, y, x)])
    one, two = np.ones_like(xs[0]), np.full_like(xs[0], 2.0)
    return np.stack([hash_floats(*xs), hash_floats(*xs, one), hash_floats(*xs, two)])


# -- PCG (Jarzynski and Olano's permuted congruential hashes of integer vectors; Voronoi in 2-4D) ---------------
_PCG_MUL, _PCG_ADD = np.int32(1664525), np.int32(1013904223)


def _pcg_mix(v: list) -> None:
    """One mixing round, in place (int32 wrap-around)."""
    if len(v) == 2:
        v[0] += v[1] * _PCG_MUL
        v[1] += v[0] * _PCG_MUL
    elif len(v) == 3:
        v[0] += v[1] * v[2]
        v[1] += v[2] * v[0]
        v[2] += v[0] * v[1]
    else:
        v[0] += v[1] * v[3]
        v[1] += v[2] * v[0]
        v[2] += v[0] * v[1]
        v[3] += v[1] * v[2]


def pcg(*cells) -> list:
    """PCG of 2-4 int32 cell coordinates (arrays of one shape) -> that many float32 arrays in [0, 1)."""
    with np.errstate(over="ignore"):
        v = [np.asarray(c, np.int32) * _PCG_MUL + _PCG_ADD for c in np.broadcast_arrays(*cells)]
        _pcg_mix(v)
        v = [x ^ (x >> np.int32(16)) for x in v]  # arithmetic shift of the signed value
        _pcg_mix(v)
    return [(x & np.int32(0x7FFFFFFF)).astype(np.float32) * np.float32(1.0 / 2147483648.0) for x in v]


def pcg_color(*cells) -> np.ndarray:
    """A cell's colour (3, ...): 2D cells as the 3D hash of (x, y, 0), 4D cells the first three of their hash."""
    if len(cells) == 2:
        cells = (*cells, np.zeros_like(np.asarray(cells[0], np.int32)))
    return np.stack(pcg(*cells)[:3])
