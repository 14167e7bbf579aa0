"""Input, texture and vector nodes as vectorized operations (Cycles' semantics, float32): hit attributes (Texture
Coordinate, Geometry, UV Map, Object Info, Color Attribute), Fresnel and Layer Weight, Mapping, Image Texture
(Closest / Linear / Cubic, Repeat / Extend / Clip / Mirror), Noise (fBM and the multifractal types, 1D-4D, with
distortion), White Noise, Checker, Gradient, and the baked curves of Color Ramp, RGB Curves and Float Curve.
Floats are (n,) or 0-d, vectors and colours (3, n) or (3, 1). Every operation is ``op(attrs, params, *inputs)``."""
from __future__ import annotations

import numpy as np

from . import noise
from ..textures import MissingImage, UdimImage, decoded, missing_lookup, per_tile
from .hashing import hash_floats, hash_floats_to_color
from .ops_math import _dot, _normalize, f32, safe_div

_F = np.float32


def attribute(attrs, params):
    """A hit attribute by name (:class:`~.attributes.HitAttributes`); zeros where the mesh lacks it (UV tangents)."""
    got = attrs.get(params["name"])
    return np.zeros((3, len(attrs)), np.float32) if got is None else got


def camera_coords(attrs, params, position):
    """Texture Coordinate > Camera: the position in the camera's frame, x right, y up, +z forward (scene units)."""
    c2w = np.asarray(params["camera"].cam_to_world, np.float64)
    w2c = np.linalg.inv(c2w).astype(np.float32)
    p = np.broadcast_to(f32(position), (3, len(attrs)))
    c = w2c[:3, :3] @ p + w2c[:3, 3:4]
    return np.stack([c[0], c[1], -c[2]]).astype(np.float32)


def window_coords(attrs, params, position):
    """Texture Coordinate > Window: the position's place in the full frame, [0, 1]² from the bottom left, z 0."""
    from ...geometry.camera import project
    cam = params["camera"]
    raster, _depth = project(cam, np.broadcast_to(f32(position), (3, len(attrs))))
    z = np.zeros(len(attrs), np.float32)
    return np.stack([raster[:, 0] / np.float32(cam.width), raster[:, 1] / np.float32(cam.height), z]).astype(
        np.float32)


def _fresnel_dielectric(cosi, eta):
    c = np.abs(cosi)
    g = eta * eta - 1 + c * c
    ok = g > 0
    g = np.sqrt(np.where(ok, g, _F(1)))
    a = safe_div(g - c, g + c)
    b = safe_div(c * (g + c) - 1, c * (g - c) + 1)
    return np.where(ok, _F(0.5) * a * a * (1 + b * b), _F(1)).astype(np.float32)


def fresnel(attrs, params, ior, normal):
    """Fresnel node: the dielectric reflectance at the angle between the view and ``normal``; the IOR inverted on a
    back face."""
    eta = np.maximum(f32(ior), _F(1e-5))
    back = attrs.get("backfacing") > 0
    eta = np.where(back, 1 / eta, eta)
    return _fresnel_dielectric(_dot(attrs.get("incoming"), f32(normal)), eta)


def wireframe(attrs, params, size):
    """Wireframe node: 1 where the hit lies within half of ``size`` of a line through one of its triangle's edges,
    else 0 (world units; with ``params["pixel_size"]`` Size counts pixels: times the width of the pixel's footprint
    there). Edges are the triangles' (a quad shows its diagonal, as Cycles renders triangles); a world
    has no edges (0)."""
    prim = getattr(attrs, "prim", None)
    if prim is None:
        return np.zeros(len(attrs), np.float32)
    corners = np.take(attrs.tris.verts, prim, axis=0)  # (n, 3 corners, 3)
    p = attrs.get("position")
    half = _F(0.5) * f32(size)
    if params.get("pixel_size"):  # Size in pixels: the pixel's width at the hit
        half = half * attrs.get("footprint")
    limit = half * half
    near = np.zeros(len(prim), bool)
    for i in range(3):
        a = corners[:, i].T
        edge = corners[:, (i + 1) % 3].T - a
        c = np.cross(edge.T, (p - a).T).T  # |edge x (p - a)|² = |edge|² · distance² to the edge's line
        near |= _dot(c, c) < _dot(edge, edge) * limit
    return near.astype(np.float32)


def layer_weight(attrs, params, blend, normal):
    """Layer Weight node: (Fresnel, Facing) for a Blend in [0, 1]."""
    blend = f32(blend)
    back = attrs.get("backfacing") > 0
    cosi = _dot(attrs.get("incoming"), f32(normal))
    eta = np.maximum(1 - blend, _F(1e-5))
    eta = np.where(back, eta, 1 / eta)
    fres = _fresnel_dielectric(cosi, eta)
    f = np.abs(cosi)
    b = np.clip(blend, 0, 1 - 1e-5)
    expo = np.where(b < 0.5, 2 * b, 0.5 / (1 - b))
    facing = np.where(blend != 0.5, np.power(np.maximum(f, 0), expo), f)
    return fres, f32(1 - facing)


def euler_matrix(rot):
    """Rows of Blender's XYZ Euler rotation R = Rz · Ry · Rx, as nine arrays (r00, r01, ..., r22)."""
    rx, ry, rz = f32(rot)[0], f32(rot)[1], f32(rot)[2]
    cx, cy, cz, sx, sy, sz = np.cos(rx), np.cos(ry), np.cos(rz), np.sin(rx), np.sin(ry), np.sin(rz)
    return (cy * cz, sy * sx * cz - cx * sz, sy * cx * cz + sx * sz,
            cy * sz, sy * sx * sz + cx * cz, sy * cx * sz - sx * cz,
            -sy, cy * sx, cy * cx)


def _rotate(m, v, transpose=False):
    if transpose:
        m = (m[0], m[3], m[6], m[1], m[4], m[7], m[2], m[5], m[8])
    return np.stack(np.broadcast_arrays(m[0] * v[0] + m[1] * v[1] + m[2] * v[2], m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
                                        m[6] * v[0] + m[7] * v[1] + m[8] * v[2])).astype(np.float32)


def mapping(attrs, params, vector, location, rotation, scale):
    """Mapping node: Point R(v S) + L, Texture Rᵀ(v - L) / S, Vector R(v S), Normal normalize(R(v / S))."""
    v, loc, s = f32(vector), f32(location), f32(scale)
    m = euler_matrix(rotation)
    kind = params.get("type", "POINT")
    if kind == "POINT":
        return f32(_rotate(m, v * s) + loc)
    if kind == "TEXTURE":
        return safe_div(_rotate(m, v - loc, transpose=True), s)
    if kind == "VECTOR":
        return _rotate(m, v * s)
    return _normalize(_rotate(m, safe_div(v, s)))


def vector_rotate(attrs, params, vector, center, axis, angle, rotation):
    """Vector Rotate node: about an axis (Axis, X, Y, Z) by Angle, or by an XYZ Euler; Invert rotates back."""
    v = f32(vector) - f32(center)
    kind = params.get("type", "AXIS_ANGLE")
    sign = _F(-1) if params.get("invert") else _F(1)
    if kind == "EULER_XYZ":
        out = _rotate(euler_matrix(rotation), v, transpose=bool(params.get("invert")))
        return f32(out + f32(center))
    ax = {"X_AXIS": np.array([[1], [0], [0]], np.float32), "Y_AXIS": np.array([[0], [1], [0]], np.float32),
          "Z_AXIS": np.array([[0], [0], [1]], np.float32)}.get(kind)
    ax = _normalize(f32(axis)) if ax is None else ax
    a = sign * f32(angle)
    c, s = np.cos(a), np.sin(a)
    # Rodrigues: v c + (k x v) s + k (k · v)(1 - c)
    kxv = np.stack(np.broadcast_arrays(ax[1] * v[2] - ax[2] * v[1], ax[2] * v[0] - ax[0] * v[2],
                                       ax[0] * v[1] - ax[1] * v[0]))
    out = v * c + kxv * s + ax * (_dot(ax, v) * (1 - c))
    is_zero = (_dot(ax, ax) == 0) if kind == "AXIS_ANGLE" else np.zeros((), bool)
    return f32(np.where(is_zero, v, out) + f32(center))


# -- images --------------------------------------------------------------------------------------------------
def _wrap_index(i, size, extension):
    """(index into the image, valid) for integer texel coordinates under an extension mode."""
    if extension == "REPEAT":
        return np.mod(i, size), None
    if extension == "EXTEND":
        return np.clip(i, 0, size - 1), None
    if extension == "MIRROR":
        period = 2 * size
        m = np.mod(i, period)
        return np.where(m < size, m, period - 1 - m), None
    valid = (i >= 0) & (i < size)  # CLIP: texels outside the image are black and transparent
    return np.clip(i, 0, size - 1), valid


def _bspline(t):
    t2, t3 = t * t, t * t * t
    return ((1 - t) ** 3 / 6, (3 * t3 - 6 * t2 + 4) / 6, (-3 * t3 + 3 * t2 + 3 * t + 1) / 6, t3 / 6)


def sample_image(image: np.ndarray, u, v, interpolation: str, extension: str) -> np.ndarray:
    """(n, c) texels of an (h, w, c) image (row 0 at the bottom) at texture coordinates (u, v) (n,) each; a UDIM set
    (textures.UdimImage) per tile, each tile with ``extension``."""
    if isinstance(image, UdimImage):
        return per_tile(image, np.asarray(u, np.float64), np.asarray(v, np.float64),
                        lambda t, tu, tv: sample_image(t, tu, tv, interpolation, extension), image.shape[2])
    if isinstance(image, MissingImage):
        return missing_lookup(image, len(np.atleast_1d(u)))
    return decoded(image, _sample_texels(np.asarray(image), u, v, interpolation, extension))


def _sample_texels(image: np.ndarray, u, v, interpolation: str, extension: str) -> np.ndarray:
    """(n, c) texels of a plain (h, w, c) array at (u, v), interpolated as they are stored."""
    h, w = image.shape[:2]
    u = np.where(np.isfinite(u), u, 0).astype(np.float64)
    v = np.where(np.isfinite(v), v, 0).astype(np.float64)
    if interpolation == "Closest":
        if extension == "CLIP":
            inside = (u >= 0) & (u < 1) & (v >= 0) & (v < 1)
        x, _ = _wrap_index(np.floor(u * w).astype(np.int64), w, extension)
        y, _ = _wrap_index(np.floor(v * h).astype(np.int64), h, extension)
        out = image[y, x].astype(np.float32)
        return out * inside[:, None] if extension == "CLIP" else out
    x = u * w - 0.5
    y = v * h - 0.5
    x0, y0 = np.floor(x), np.floor(y)
    fx, fy = (x - x0).astype(np.float32), (y - y0).astype(np.float32)
    x0, y0 = x0.astype(np.int64), y0.astype(np.int64)
    if interpolation in {"Cubic", "Smart"}:
        offs, wx, wy = (-1, 0, 1, 2), _bspline(fx), _bspline(fy)
    else:
        offs, wx, wy = (0, 1), (1 - fx, fx), (1 - fy, fy)
    out = np.zeros((len(u), image.shape[2]), np.float32)
    cols = [_wrap_index(x0 + o, w, extension) for o in offs]
    for oy, wyk in zip(offs, wy):
        yi, yok = _wrap_index(y0 + oy, h, extension)
        for (xi, xok), wxk in zip(cols, wx):
            weight = wxk * wyk
            if yok is not None:
                weight = weight * (yok & xok)
            out += image[yi, xi] * weight[:, None]
    return out


def image_texture(attrs, params, vector):
    """Image Texture node: (Color (3, n), Alpha (n,)) at the vector's (x, y)."""
    vec = np.broadcast_to(f32(vector), (3, len(attrs)))
    textures = attrs.textures
    interp, ext = params.get("interpolation", "Linear"), params.get("extension", "REPEAT")
    color = sample_image(textures[params["tex"]], vec[0], vec[1], interp, ext).T
    alpha_tex = params.get("alpha_tex", -1)
    if alpha_tex >= 0:
        alpha = sample_image(textures[alpha_tex], vec[0], vec[1], interp, ext)[:, 0]
    else:
        alpha = np.ones(len(attrs), np.float32)
        if ext == "CLIP" and not isinstance(textures[params["tex"]], MissingImage):
            # an image without alpha is opaque inside and transparent outside
            alpha = sample_image(np.ones((*textures[params["tex"]].shape[:2], 1), np.float32), vec[0], vec[1],
                                 interp, ext)[:, 0]
    return np.ascontiguousarray(color, np.float32), alpha.astype(np.float32)


def environment_texture(attrs, params, vector):
    """Environment Texture node (equirectangular): the image at the direction ``vector``'s longitude and latitude
    (u = 1/2 - atan2(y, x) / 2π, v = 1/2 + atan2(z, √(x² + y²)) / π), wrapping in u."""
    d = np.broadcast_to(f32(vector), (3, len(attrs)))
    u = _F(0.5) - np.arctan2(d[1], d[0]) / _F(2 * np.pi)
    v = _F(0.5) + np.arctan2(d[2], np.hypot(d[0], d[1])) / _F(np.pi)
    image = attrs.textures[params["tex"]]
    return np.ascontiguousarray(sample_image(image, u, v, params.get("interpolation", "Linear"), "REPEAT").T,
                                dtype=np.float32)


# -- procedural textures --------------------------------------------------------------------------------------
def _coords(dims: int, vector, w, scale):
    s = f32(scale)
    v = f32(vector) * s
    ws = f32(w) * s
    return {1: [ws], 2: [v[0], v[1]], 3: [v[0], v[1], v[2]], 4: [v[0], v[1], v[2], ws]}[dims]


def noise_texture(attrs, params, vector, w, scale, detail, roughness, lacunarity, off, gain, distortion):
    """Noise Texture node: (Fac (n,), Color (3, n))."""
    dims = params.get("dims", 3)
    p = _coords(dims, vector, w, scale)
    dist = f32(distortion)
    if np.any(dist != 0):
        p = [p[k] + noise.snoise(*[p[j] + noise.offset(k, dims)[j] for j in range(dims)]) * dist
             for k in range(dims)]
    kind, norm = params.get("type", "FBM"), bool(params.get("normalize", True))

    def value(q):
        return noise.fractal(kind, q, detail, roughness, lacunarity, off, gain, norm)
    fac = value(p)
    if not params.get("color", True):
        return fac, np.stack([fac, fac, fac])
    second = value([p[j] + noise.offset(dims, dims)[j] for j in range(dims)])
    third = value([p[j] + noise.offset(dims + 1, dims)[j] for j in range(dims)])
    return fac, np.stack(np.broadcast_arrays(fac, second, third)).astype(np.float32)


def white_noise(attrs, params, vector, w):
    """White Noise Texture node: (Value (n,), Color (3, n)), hashes of the coordinates' float bits."""
    dims = params.get("dims", 3)
    v = f32(vector)
    keys = {1: [f32(w)], 2: [v[0], v[1]], 3: [v[0], v[1], v[2]], 4: [v[0], v[1], v[2], f32(w)]}[dims]
    return hash_floats(*keys), hash_floats_to_color(*keys)


def checker(attrs, params, vector, color1, color2, scale):
    """Checker Texture node: (Color, Fac)."""
    p = (f32(vector) * f32(scale) + _F(1e-6)) * _F(0.999999)
    xi, yi, zi = (np.abs(np.floor(p[k])).astype(np.int64) % 2 for k in range(3))
    first = (xi == yi) == (zi == 1)
    fac = first.astype(np.float32)
    return f32(np.where(first, f32(color1), f32(color2))), fac


def gradient(attrs, params, vector):
    """Gradient Texture node: (Color, Fac), Fac clamped to [0, 1]."""
    p = f32(vector)
    x, y = p[0], p[1]
    kind = params.get("type", "LINEAR")
    if kind == "LINEAR":
        f = x
    elif kind == "QUADRATIC":
        f = np.maximum(x, 0) ** 2
    elif kind == "EASING":
        r = np.clip(x, 0, 1)
        f = 3 * r * r - 2 * r * r * r
    elif kind == "DIAGONAL":
        f = (x + y) * _F(0.5)
    elif kind == "RADIAL":
        f = np.arctan2(y, x) / _F(2 * np.pi) + _F(0.5)
    else:
        r = np.maximum(_F(0.999999) - np.sqrt(_dot(p, p)), 0)
        f = r * r if kind == "QUADRATIC_SPHERE" else r
    fac = np.clip(f32(f), 0, 1).astype(np.float32)
    return np.stack([fac, fac, fac]), fac


# -- baked curves -----------------------------------------------------------------------------------------------
def _lookup(table: np.ndarray, f, interpolate: bool, extrapolate: bool) -> np.ndarray:
    """A (k, c) table over [0, 1] at f (n,) (Cycles' ramp lookup): entries at i / (k - 1), linear between them
    (or the lower entry), linear beyond the ends when ``extrapolate`` (else the end entries)."""
    k = len(table) - 1
    f = f32(f)
    x = np.clip(f, 0, 1) * k
    i = np.clip(x.astype(np.int64), 0, k)
    t = (x - i).astype(np.float32)
    lo = table[i]
    if interpolate:
        hi = table[np.minimum(i + 1, k)]
        lo = lo + (hi - lo) * t[..., None]
    if extrapolate:
        below = (f < 0)[..., None]
        above = (f > 1)[..., None]
        lo = np.where(below, table[0] + (table[0] - table[1]) * (-f * k)[..., None], lo)
        lo = np.where(above, table[k] + (table[k] - table[k - 1]) * ((f - 1) * k)[..., None], lo)
    return lo.astype(np.float32)


def color_ramp(attrs, params, fac):
    """Color Ramp node: (Color (3, n), Alpha (n,)) from its table of (k, 4) RGBA entries."""
    fac = f32(fac)
    got = _lookup(params["table"], fac.reshape(-1), bool(params.get("interpolate", True)), False)
    got = got.reshape(*fac.shape, 4)
    return np.ascontiguousarray(np.moveaxis(got[..., :3], -1, 0)), np.ascontiguousarray(got[..., 3])


def rgb_curves(attrs, params, fac, color):
    """RGB Curves node: each channel through its (k,) table over [lo, hi], mixed with the input by Fac."""
    c = f32(color)
    lo, hi = params.get("range", (0.0, 1.0))
    out = []
    for ch in range(3):
        x = (c[ch] - _F(lo)) / _F(max(hi - lo, 1e-12))
        shape = np.shape(x)
        out.append(_lookup(params["tables"][ch][:, None], np.reshape(x, -1), True,
                           bool(params.get("extrapolate", True)))[:, 0].reshape(shape))
    curved = np.stack(np.broadcast_arrays(*out)).astype(np.float32)
    return f32(c + f32(fac) * (curved - c))


def float_curve(attrs, params, fac, value):
    """Float Curve node: the value through its table over [lo, hi], mixed with the input by Factor."""
    v = f32(value)
    lo, hi = params.get("range", (0.0, 1.0))
    x = (v - _F(lo)) / _F(max(hi - lo, 1e-12))
    curved = _lookup(params["table"][:, None], np.reshape(x, -1), True,
                     bool(params.get("extrapolate", True)))[:, 0].reshape(np.shape(x))
    return f32(v + f32(fac) * (curved - v))


OPERATIONS = {
    "attribute": attribute, "camera_coords": camera_coords, "window_coords": window_coords, "fresnel": fresnel,
    "layer_weight": layer_weight, "mapping": mapping, "vector_rotate": vector_rotate, "image": image_texture,
    "environment": environment_texture, "noise": noise_texture, "white_noise": white_noise,
    "checker": checker, "gradient": gradient, "color_ramp": color_ramp, "rgb_curves": rgb_curves,
    "float_curve": float_curve, "wireframe": wireframe,
}
#: operations that read the hits: never folded into constants at export
READS_HITS = frozenset({"attribute", "fresnel", "layer_weight", "image", "environment", "camera_coords",
                        "window_coords", "wireframe"})
