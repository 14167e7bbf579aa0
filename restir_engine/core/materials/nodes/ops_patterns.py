"""Pattern textures as vectorized operations, Cycles' formulas in float32: Voronoi (:mod:`.voronoi`), Wave, Magic
and Brick. Floats are (n,) or 0-d, vectors and colours (3, n) or (3, 1); every operation is
``op(attrs, params, *inputs)``."""
from __future__ import annotations

import numpy as np

from . import noise
from .ops_math import f32, safe_div
from .voronoi import voronoi

_F = np.float32
_TWO_PI = _F(2 * np.pi)


def voronoi_texture(attrs, params, vector, w, scale, detail, roughness, lacunarity, smoothness, exponent,
                    randomness):
    """Voronoi Texture node: (Distance, Color (3, n), Position (3, n), W, Radius)."""
    dims = params.get("dims", 3)
    s = f32(scale)
    v, ws = f32(vector) * s, f32(w) * s
    coords = {1: [ws], 2: [v[0], v[1]], 3: [v[0], v[1], v[2]], 4: [v[0], v[1], v[2], ws]}[dims]
    dist, color, pos, radius = voronoi(params.get("feature", "F1"), params.get("metric", "EUCLIDEAN"), coords,
                                       detail, roughness, lacunarity, smoothness, exponent, randomness,
                                       bool(params.get("normalize", False)))
    shape = np.broadcast_shapes(*[np.shape(c) for c in coords])
    zero = np.zeros(shape, np.float32)
    if pos is None:
        position, w_out = np.zeros((3, *shape), np.float32), zero
    else:
        pos = [safe_div(p, s) for p in pos]
        xyz = [zero, zero, zero] if dims == 1 else ([pos[0], pos[1], zero] if dims == 2 else pos[:3])
        position = np.stack(np.broadcast_arrays(*xyz)).astype(np.float32)
        w_out = pos[0] if dims == 1 else (pos[3] if dims == 4 else zero)
    return (zero if dist is None else dist, np.zeros((3, *shape), np.float32) if color is None else color,
            position, f32(w_out), zero if radius is None else radius)


def wave_texture(attrs, params, vector, scale, distortion, detail, detail_scale, detail_roughness, phase):
    """Wave Texture node: (Color (3, n), Fac) for bands or rings along an axis, a sine, saw or triangle profile,
    with fBM distortion."""
    p = (f32(vector) * f32(scale) + _F(1e-6)) * _F(0.999999)
    direction = params.get("direction", "X")
    if params.get("type", "BANDS") == "BANDS":
        n = (p[0] + p[1] + p[2]) * _F(10) if direction == "DIAGONAL" else p["XYZ".index(direction)] * _F(20)
    else:
        keep = {"X": (0, 1, 1), "Y": (1, 0, 1), "Z": (1, 1, 0)}.get(direction, (1, 1, 1))
        n = np.sqrt(sum(p[k] * p[k] for k in range(3) if keep[k])) * _F(20)
    n = n + f32(phase)
    dist = f32(distortion)
    if np.any(dist != 0):
        q = p * f32(detail_scale)
        fbm = noise.fractal("FBM", [q[0], q[1], q[2]], detail, detail_roughness, _F(2), _F(0), _F(1), True)
        n = n + dist * (fbm * _F(2) - _F(1))
    profile = params.get("profile", "SIN")
    if profile == "SIN":
        f = _F(0.5) + _F(0.5) * np.sin(n - _F(np.pi / 2))
    elif profile == "SAW":
        q = n / _TWO_PI
        f = q - np.floor(q)
    else:
        q = n / _TWO_PI
        f = np.abs(q - np.floor(q + _F(0.5))) * _F(2)
    f = f32(f)
    return np.stack(np.broadcast_arrays(f, f, f)).astype(np.float32), f


def magic_texture(attrs, params, vector, scale, distortion):
    """Magic Texture node: (Color (3, n), Fac), the nested sines and cosines of ``depth`` levels. Blender 5.2
    wraps the scaled coordinates into [0, 2π) (``params["wrap_scaled"]``), earlier versions the unscaled ones."""
    v, s = f32(vector), f32(scale)
    if params.get("wrap_scaled", True):
        p = np.fmod(v * s, _TWO_PI) * _F(5)
    else:
        p = np.fmod(v, _TWO_PI) * (_F(5) * s)
    x = np.sin(p[0] + p[1] + p[2])
    y = np.cos(-p[0] + p[1] - p[2])
    z = -np.cos(-p[0] - p[1] + p[2])
    depth, dist = int(params.get("depth", 2)), f32(distortion)
    if depth > 0:
        x, y, z = x * dist, y * dist, z * dist
        y = -np.cos(x - y + z) * dist
        steps = ((1, "x", lambda x, y, z: np.cos(x - y - z)), (2, "z", lambda x, y, z: np.sin(-x - y - z)),
                 (3, "x", lambda x, y, z: -np.cos(-x + y - z)), (4, "y", lambda x, y, z: -np.sin(-x + y + z)),
                 (5, "y", lambda x, y, z: -np.cos(-x + y + z)), (6, "x", lambda x, y, z: np.cos(x + y + z)),
                 (7, "z", lambda x, y, z: np.sin(x + y - z)), (8, "x", lambda x, y, z: -np.cos(-x - y + z)),
                 (9, "y", lambda x, y, z: -np.sin(x - y + z)))
        for level, axis, fn in steps:
            if depth <= level:
                break
            got = fn(x, y, z) * dist
            x, y, z = (got, y, z) if axis == "x" else ((x, got, z) if axis == "y" else (x, y, got))
    if np.any(dist != 0):
        two = np.where(dist != 0, dist * _F(2), _F(1))
        x, y, z = x / two, y / two, z / two
    color = np.stack(np.broadcast_arrays(_F(0.5) - x, _F(0.5) - y, _F(0.5) - z)).astype(np.float32)
    return color, f32((color[0] + color[1] + color[2]) / _F(3))


def _brick_noise(n):
    """Blender's integer noise of a brick's (row, column) key -> float32 in [0, 1)."""
    with np.errstate(over="ignore"):
        n = (n.astype(np.uint32) + np.uint32(1013)) & np.uint32(0x7FFFFFFF)
        n = (n >> np.uint32(13)) ^ n
        nn = (n * (n * n * np.uint32(60493) + np.uint32(19990303)) + np.uint32(1376312589)) & np.uint32(0x7FFFFFFF)
    return _F(0.5) * (nn.astype(np.float32) / _F(1073741824.0))


def brick_texture(attrs, params, vector, color1, color2, mortar, scale, mortar_size, mortar_smooth, bias,
                  brick_width, row_height):
    """Brick Texture node: (Color (3, n), Fac = the mortar's share), with row offset and squash."""
    p = f32(vector) * f32(scale)
    width, height = f32(brick_width), f32(row_height)
    row = np.floor(safe_div(p[1], height)).astype(np.int64)
    offset = np.zeros(np.shape(row), np.float32)
    off_freq, squash_freq = int(params.get("offset_frequency", 2)), int(params.get("squash_frequency", 2))
    if off_freq and squash_freq:
        width = np.where(np.fmod(row, squash_freq) != 0, width, width * _F(params.get("squash", 1.0)))
        offset = np.where(np.fmod(row, off_freq) != 0, _F(0), width * _F(params.get("offset", 0.5)))
    col = np.floor(safe_div(p[0] + offset, width)).astype(np.int64)
    x = (p[0] + offset) - width * col
    y = p[1] - height * row
    key = ((row << 16) + (col & 0xFFFF)) & 0xFFFFFFFF
    tint = np.clip(_brick_noise(key) + f32(bias), 0, 1)
    edge = np.minimum(np.minimum(x, y), np.minimum(width - x, height - y))
    size, smooth = f32(mortar_size), f32(mortar_smooth)
    e = 1 - safe_div(edge, size)
    t = safe_div(e, smooth)
    soft = np.where(e < smooth, t * t * (_F(3) - _F(2) * t), _F(1))
    fac = np.where(edge >= size, _F(0), np.where(smooth == 0, _F(1), soft)).astype(np.float32)
    c1, c2 = f32(color1), f32(color2)
    base = np.where(fac != 1, c1 * (1 - tint) + c2 * tint, c1)
    return f32(base * (1 - fac) + f32(mortar) * fac), fac


OPERATIONS = {"voronoi": voronoi_texture, "wave": wave_texture, "magic": magic_texture, "brick": brick_texture}
