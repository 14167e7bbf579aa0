"""Cycles' Gabor Texture (sparse Gabor convolution, Lagae et al. 2009, with Tavernier et al. 2019's stratified
impulses and Tricard et al. 2019's phasor outputs), vectorized over points, so that a Gabor Texture gives the same
pattern as in Cycles.

The plane (2D) or space (3D) is cut into unit cells; each cell holds 8 impulses, impulse i of cell c drawing its
random orientation offset, its centre in the cell and its sign (±1, each with probability 1/2) from the lookup3 hashes
of the float bits of (c, 3i), (c, 3i + 1) and (c, 3i + 2). An impulse adds sign · w(d) · (cos θ, sin θ) at offset d
from its centre, w(d) = exp(-π|d|²) · (1/2 + cos(π|d|²)/2) (a Gaussian windowed to zero at |d| = 1) and
θ = 2π F (d · the impulse's unit orientation). A point sums the phasors of the impulses in its cell and the cells
around it (3ᵈ cells, in Cycles' order, so float32 sums round alike). Orientation: 2D the base angle plus
(hash - 1/2) · π · isotropy; 3D the base direction's inclination and azimuth each plus hash · π · isotropy
(isotropy = 1 - Anisotropy). Outputs with the phasor p and n = 6 σ (σ = 1 in 2D, √(1 / √2) in 3D): Value
p.y / (2n) + 1/2, Phase (atan2(p.y, p.x) + π) / 2π, Intensity |p| / n."""
from __future__ import annotations

import numpy as np

from .hashing import hash_floats

_F = np.float32
IMPULSES = 8
#: points per batch of the (cells, impulses, points) arrays
CHUNK = 8192
SIGMA = {2: _F(1.0), 3: np.sqrt(_F(IMPULSES) * _F(0.5) * (_F(1.0) / (_F(4.0) * np.sqrt(_F(2.0))))).astype(np.float32)}


def _kernel(pos: list, freq_vec: list):
    """Phasor (re, im) of impulses at offsets ``pos`` (list of d arrays) with frequency vectors ``freq_vec``."""
    d2 = pos[0] * pos[0] + pos[1] * pos[1]
    if len(pos) == 3:
        d2 = d2 + pos[2] * pos[2]
    pi = _F(np.pi)
    envelope = np.exp(-pi * d2) * (_F(0.5) + _F(0.5) * np.cos(pi * d2))
    dot = pos[0] * freq_vec[0] + pos[1] * freq_vec[1]
    if len(pos) == 3:
        dot = dot + pos[2] * freq_vec[2]
    angle = _F(2.0) * pi * dot
    return envelope * np.cos(angle), envelope * np.sin(angle), d2


def _orientation_3d(base: list, isotropy, seed: list) -> list:
    """The impulses' unit orientations (3 arrays) about ``base`` (unit, 3 arrays) by the seeds' hashes."""
    ox, oy, oz = base
    inclination = np.arccos(oz)
    azimuth = np.where(oy < 0, _F(-1.0), _F(1.0)) * np.arccos(ox / np.sqrt(ox * ox + oy * oy))
    x, y, z, w = seed
    pi = _F(np.pi)
    inclination = inclination + hash_floats(x, y, z, w) * pi * isotropy
    azimuth = azimuth + hash_floats(z, x, w, y) * pi * isotropy
    turned = [np.sin(inclination) * np.cos(azimuth), np.sin(inclination) * np.sin(azimuth), np.cos(inclination)]
    keep = isotropy == 0
    return [np.where(keep, b, t).astype(np.float32) for b, t in zip(base, turned)]


def _phasor(coords: list, frequency, isotropy, orientation) -> tuple:
    """The summed phasor (re, im) (n,) at ``coords`` (d arrays (n,), scaled)."""
    d = len(coords)
    n = coords[0].shape[0]
    cell = [np.floor(c).astype(np.float32) for c in coords]
    local = [(c - f).astype(np.float32) for c, f in zip(coords, cell)]
    offsets = np.array([t[::-1] for t in np.ndindex(*(3,) * d)], np.float32) - _F(1.0)  # last axis outermost
    lead = (len(offsets), IMPULSES, 1)
    imp = np.arange(IMPULSES, dtype=np.float32).reshape(1, IMPULSES, 1) * _F(3.0)
    here = [cell[k][None, None, :] + offsets[:, k].reshape(len(offsets), 1, 1) for k in range(d)]  # (m, 1, n)
    here = [np.broadcast_to(h, (len(offsets), IMPULSES, n)) for h in here]
    pos0 = [local[k][None, None, :] - offsets[:, k].reshape(len(offsets), 1, 1) for k in range(d)]
    keys = [np.broadcast_to(imp + s, (len(offsets), IMPULSES, n)) for s in (_F(0), _F(1), _F(2))]
    if d == 2:
        x, y = here
        orient = orientation + (hash_floats(x, y, keys[0]) - _F(0.5)) * _F(np.pi) * isotropy
        center = [hash_floats(x, y, keys[1]), hash_floats(keys[1], x, y)]
        sign_h = hash_floats(x, y, keys[2])
        freq_vec = [frequency * np.cos(orient), frequency * np.sin(orient)]
    else:
        x, y, z = here
        o = _orientation_3d(orientation, isotropy, [x, y, z, keys[0]])
        k1 = keys[1]
        center = [hash_floats(x, y, z, k1), hash_floats(z, x, k1, y), hash_floats(k1, z, y, x)]
        sign_h = hash_floats(x, y, z, keys[2])
        freq_vec = [frequency * o[0], frequency * o[1], frequency * o[2]]
    pos = [p - c for p, c in zip(pos0, center)]
    re, im, d2 = _kernel(pos, freq_vec)
    sign = np.where(sign_h < _F(0.5), _F(-1.0), _F(1.0))
    near = d2 < _F(1.0)
    re = np.where(near, sign * re, _F(0.0)).astype(np.float32)
    im = np.where(near, sign * im, _F(0.0)).astype(np.float32)
    sum_re = np.zeros(n, np.float32)
    sum_im = np.zeros(n, np.float32)
    for m in range(len(offsets)):  # the cells in Cycles' order, each its impulses in order
        cell_re = np.zeros(n, np.float32)
        cell_im = np.zeros(n, np.float32)
        for i in range(IMPULSES):
            cell_re = cell_re + re[m, i]
            cell_im = cell_im + im[m, i]
        sum_re = sum_re + cell_re
        sum_im = sum_im + cell_im
    return sum_re, sum_im


def gabor(dims: int, coords: list, frequency, anisotropy, orientation_2d, orientation_3d: list) -> tuple:
    """(Value, Phase, Intensity) (n,) float32 of the Gabor Texture at ``coords`` (``dims`` arrays (n,), already
    times Scale); the parameters per point or constant; ``orientation_3d`` unnormalized (3 arrays)."""
    coords = [np.asarray(c, np.float32) for c in coords]
    n = coords[0].shape[0]
    freq = np.maximum(_F(0.001), np.broadcast_to(np.asarray(frequency, np.float32), (n,)))
    iso = _F(1.0) - np.clip(np.broadcast_to(np.asarray(anisotropy, np.float32), (n,)), _F(0), _F(1))
    if dims == 2:
        orient = np.broadcast_to(np.asarray(orientation_2d, np.float32), (n,))
    else:
        o = [np.broadcast_to(np.asarray(v, np.float32), (n,)) for v in orientation_3d]
        ln = np.sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2])
        orient = [v / ln for v in o]
    re = np.empty(n, np.float32)
    im = np.empty(n, np.float32)
    with np.errstate(all="ignore"):
        for lo in range(0, n, CHUNK):
            sl = slice(lo, lo + CHUNK)
            o = orient[sl] if dims == 2 else [v[sl] for v in orient]
            re[sl], im[sl] = _phasor([c[sl] for c in coords], freq[sl], iso[sl], o)
        norm = _F(6.0) * SIGMA[dims]
        value = (im / norm) * _F(0.5) + _F(0.5)
        phase = (np.arctan2(im, re) + _F(np.pi)) / (_F(2.0) * _F(np.pi))
        intensity = np.sqrt(re * re + im * im) / norm
    return value.astype(np.float32), phase.astype(np.float32), intensity.astype(np.float32)


def gabor_texture(attrs, params, vector, scale, frequency, anisotropy, orientation_2d, orientation_3d):
    """Gabor Texture node: (Value, Phase, Intensity) (n,) at ``vector`` (3, n) times Scale; params["dims"] 2 or 3."""
    n = len(attrs) if attrs is not None else 1
    v = np.broadcast_to(np.asarray(vector, np.float32).reshape(3, -1), (3, n)) * np.asarray(scale, np.float32)
    dims = params.get("dims", 2)
    o3 = np.broadcast_to(np.asarray(orientation_3d, np.float32).reshape(3, -1), (3, n))
    flat = [np.ravel(np.broadcast_to(np.asarray(x, np.float32), (n,))) for x in (frequency, anisotropy,
                                                                                  orientation_2d)]
    out = gabor(dims, [v[0], v[1]] if dims == 2 else [v[0], v[1], v[2]], *flat, [o3[0], o3[1], o3[2]])
    return out if attrs is not None else tuple(np.float32(x[0]) for x in out)


OPERATIONS = {"gabor_texture": gabor_texture}
