"""Converter nodes as vectorized operations (Cycles' semantics, float32): Math, Vector Math, Mix (float, vector,
colour with every blend mode), Map Range, Clamp, Invert, RGB to BW, Gamma, Bright/Contrast, Hue/Saturation/Value,
Separate and Combine (XYZ, RGB/HSV/HSL), the implicit socket conversions, and the small steps the exporter uses to
build material fields (the Principled F0, a colour times a strength). Floats are (n,) or 0-d, vectors and colours
(3, n) or (3, 1); results broadcast. Every operation is ``op(attrs, params, *inputs)``."""
from __future__ import annotations

import numpy as np

_F = np.float32
PI = _F(np.pi)
#: Rec. 709 luminance (Blender's default scene-linear space), the colour -> float conversion
LUMA = np.array([0.2126, 0.7152, 0.0722], np.float32).reshape(3, 1)


def f32(x):
    return np.asarray(x, np.float32)


def safe_div(a, b):
    b = f32(b)
    return np.where(b != 0, f32(a) / np.where(b != 0, b, _F(1)), _F(0)).astype(np.float32)


def luminance(c):
    c = f32(c)
    return (LUMA[0] * c[0] + LUMA[1] * c[1] + LUMA[2] * c[2]).astype(np.float32)


def _pow(a, b):
    """Cycles' safe power: 0 for a negative base with a non-integer exponent, and for a zero base."""
    a, b = np.broadcast_arrays(f32(a), f32(b))
    bad = ((a < 0) & (b != np.trunc(b))) | (a == 0)
    out = np.power(np.where(bad, _F(1), a), b)
    return np.where(bad, np.where((a == 0) & (b == 0), _F(1), _F(0)), out).astype(np.float32)


def _wrap(v, hi, lo):
    r = f32(hi) - f32(lo)
    return np.where(r != 0, v - r * np.floor(safe_div(v - lo, r)), lo).astype(np.float32)


def _smooth_min(a, b, c):
    c = f32(c)
    h = safe_div(np.maximum(c - np.abs(a - b), 0), c)
    return np.where(c != 0, np.minimum(a, b) - h * h * h * c * _F(1 / 6), np.minimum(a, b)).astype(np.float32)


def _fract(a):
    return a - np.floor(a)


def _fmod(a, b):
    b = f32(b)
    return np.where(b != 0, np.fmod(a, np.where(b != 0, b, _F(1))), _F(0)).astype(np.float32)


MATH = {
    "ADD": lambda a, b, c: a + b, "SUBTRACT": lambda a, b, c: a - b, "MULTIPLY": lambda a, b, c: a * b,
    "DIVIDE": lambda a, b, c: safe_div(a, b), "MULTIPLY_ADD": lambda a, b, c: a * b + c,
    "POWER": lambda a, b, c: _pow(a, b),
    "LOGARITHM": lambda a, b, c: np.where((a > 0) & (b > 0), safe_div(np.log(np.maximum(a, 1e-38)),
                                                                       np.log(np.maximum(b, 1e-38))), _F(0)),
    "SQRT": lambda a, b, c: np.where(a > 0, np.sqrt(np.maximum(a, 0)), _F(0)),
    "INVERSE_SQRT": lambda a, b, c: np.where(a > 0, 1 / np.sqrt(np.where(a > 0, a, _F(1))), _F(0)),
    "ABSOLUTE": lambda a, b, c: np.abs(a), "EXPONENT": lambda a, b, c: np.exp(a),
    "MINIMUM": lambda a, b, c: np.minimum(a, b), "MAXIMUM": lambda a, b, c: np.maximum(a, b),
    "LESS_THAN": lambda a, b, c: (a < b).astype(np.float32), "GREATER_THAN": lambda a, b, c: (a > b).astype(np.float32),
    "SIGN": lambda a, b, c: np.sign(a),
    "COMPARE": lambda a, b, c: (np.abs(a - b) <= np.maximum(c, _F(1e-5))).astype(np.float32),
    "SMOOTH_MIN": lambda a, b, c: _smooth_min(a, b, c), "SMOOTH_MAX": lambda a, b, c: -_smooth_min(-a, -b, c),
    "ROUND": lambda a, b, c: np.floor(a + _F(0.5)), "FLOOR": lambda a, b, c: np.floor(a),
    "CEIL": lambda a, b, c: np.ceil(a), "TRUNC": lambda a, b, c: np.trunc(a), "FRACT": lambda a, b, c: _fract(a),
    "MODULO": lambda a, b, c: _fmod(a, b),
    "FLOORED_MODULO": lambda a, b, c: np.where(b != 0, a - np.floor(safe_div(a, b)) * b, _F(0)),
    "WRAP": lambda a, b, c: _wrap(a, b, c), "SNAP": lambda a, b, c: np.floor(safe_div(a, b)) * b,
    "PINGPONG": lambda a, b, c: np.where(b != 0, np.abs(_fract(safe_div(a - b, b * 2)) * b * 2 - b), _F(0)),
    "SINE": lambda a, b, c: np.sin(a), "COSINE": lambda a, b, c: np.cos(a), "TANGENT": lambda a, b, c: np.tan(a),
    "ARCSINE": lambda a, b, c: np.arcsin(np.clip(a, -1, 1)), "ARCCOSINE": lambda a, b, c: np.arccos(np.clip(a, -1, 1)),
    "ARCTANGENT": lambda a, b, c: np.arctan(a), "ARCTAN2": lambda a, b, c: np.arctan2(a, b),
    "SINH": lambda a, b, c: np.sinh(a), "COSH": lambda a, b, c: np.cosh(a), "TANH": lambda a, b, c: np.tanh(a),
    "RADIANS": lambda a, b, c: a * (PI / 180), "DEGREES": lambda a, b, c: a * (180 / PI),
}


def math(attrs, params, a, b, c):
    out = f32(MATH[params["op"]](f32(a), f32(b), f32(c)))
    return np.clip(out, 0, 1).astype(np.float32) if params.get("clamp") else out


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _normalize(a):
    ln = np.sqrt(_dot(a, a))
    return np.where(ln != 0, a / np.where(ln != 0, ln, _F(1)), _F(0)).astype(np.float32)


def _cross(a, b):
    return np.stack(np.broadcast_arrays(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                                        a[0] * b[1] - a[1] * b[0]))


def _refract(i, n, eta):
    d = _dot(n, i)
    k = _F(1) - eta * eta * (_F(1) - d * d)
    return np.where(k < 0, _F(0), eta * i - (eta * d + np.sqrt(np.maximum(k, 0))) * n)


VECTOR = {
    "ADD": lambda a, b, c, s: a + b, "SUBTRACT": lambda a, b, c, s: a - b, "MULTIPLY": lambda a, b, c, s: a * b,
    "DIVIDE": lambda a, b, c, s: safe_div(a, b), "MULTIPLY_ADD": lambda a, b, c, s: a * b + c,
    "CROSS_PRODUCT": lambda a, b, c, s: _cross(a, b),
    "PROJECT": lambda a, b, c, s: safe_div(_dot(a, b), _dot(b, b)) * b,
    "REFLECT": lambda a, b, c, s: a - 2 * _dot(_normalize(b), a) * _normalize(b),
    "REFRACT": lambda a, b, c, s: _refract(a, _normalize(b), s),
    "FACEFORWARD": lambda a, b, c, s: np.where(_dot(c, b) < 0, a, -a),
    "SCALE": lambda a, b, c, s: a * s, "NORMALIZE": lambda a, b, c, s: _normalize(a),
    "SNAP": lambda a, b, c, s: np.floor(safe_div(a, b)) * b, "FLOOR": lambda a, b, c, s: np.floor(a),
    "CEIL": lambda a, b, c, s: np.ceil(a), "MODULO": lambda a, b, c, s: _fmod(a, b),
    "WRAP": lambda a, b, c, s: _wrap(a, b, c), "FRACTION": lambda a, b, c, s: _fract(a),
    "ABSOLUTE": lambda a, b, c, s: np.abs(a), "POWER": lambda a, b, c, s: _pow(a, b),
    "SIGN": lambda a, b, c, s: np.sign(a),
    "MINIMUM": lambda a, b, c, s: np.minimum(a, b), "MAXIMUM": lambda a, b, c, s: np.maximum(a, b),
    "SINE": lambda a, b, c, s: np.sin(a), "COSINE": lambda a, b, c, s: np.cos(a),
    "TANGENT": lambda a, b, c, s: np.tan(a),
}
VECTOR_VALUE = {"DOT_PRODUCT": lambda a, b: _dot(a, b), "DISTANCE": lambda a, b: np.sqrt(_dot(a - b, a - b)),
                "LENGTH": lambda a, b: np.sqrt(_dot(a, a))}


def vector_math(attrs, params, a, b, c, s):
    """(vector, value): the value output of Dot Product, Distance and Length, the vector output otherwise."""
    a, b, c, s = f32(a), f32(b), f32(c), f32(s)
    op = params["op"]
    if op in VECTOR_VALUE:
        return np.zeros((3, 1), np.float32), f32(VECTOR_VALUE[op](a, b))
    return f32(VECTOR[op](a, b, c, s)), _F(0)


def mix_float(attrs, params, t, a, b):
    t = f32(t)
    if params.get("clamp_factor", True):
        t = np.clip(t, 0, 1)
    return f32(a + t * (f32(b) - a))


def mix_vector(attrs, params, t, a, b):
    """Mix of vectors by a float factor (uniform) or per component by a vector factor."""
    return mix_float(attrs, params, t, f32(a), f32(b))


def rgb_to_hsv(c):
    c = f32(c)
    r, g, b = c[0], c[1], c[2]
    cmax = np.maximum(np.maximum(r, g), b)
    cmin = np.minimum(np.minimum(r, g), b)
    delta = cmax - cmin
    s = np.where(cmax != 0, safe_div(delta, cmax), _F(0))
    cr, cg, cb = (safe_div(cmax - x, delta) for x in (r, g, b))
    h = np.where(r == cmax, cb - cg, np.where(g == cmax, _F(2) + cr - cb, _F(4) + cg - cr)) / _F(6)
    h = np.where(h < 0, h + 1, h)
    h = np.where(s != 0, h, _F(0))
    return np.stack(np.broadcast_arrays(h, s, cmax)).astype(np.float32)


def hsv_to_rgb(hsv):
    h, s, v = (f32(x) for x in hsv)
    h = np.where(h == 1, _F(0), h) * 6
    i = np.floor(h)
    f = h - i
    p, q, t = v * (1 - s), v * (1 - s * f), v * (1 - s * (1 - f))
    i = np.broadcast_to(i, np.broadcast_shapes(np.shape(i), np.shape(v), np.shape(s)))
    cases = [(v, t, p), (q, v, p), (p, v, t), (p, q, v), (t, p, v), (v, p, q)]
    out = [np.select([i == k for k in range(5)], [cs[ch] for cs in cases[:5]], cases[5][ch]) for ch in range(3)]
    grey = s == 0
    return np.stack(np.broadcast_arrays(*[np.where(grey, v, o) for o in out])).astype(np.float32)


def rgb_to_hsl(c):
    c = f32(c)
    r, g, b = c[0], c[1], c[2]
    cmax = np.maximum(np.maximum(r, g), b)
    cmin = np.minimum(np.minimum(r, g), b)
    lum = (cmax + cmin) / 2
    d = cmax - cmin
    s = np.where(lum > 0.5, safe_div(d, 2 - cmax - cmin), safe_div(d, cmax + cmin))
    h = np.where(cmax == r, safe_div(g - b, d) + np.where(g < b, _F(6), _F(0)),
                 np.where(cmax == g, safe_div(b - r, d) + 2, safe_div(r - g, d) + 4)) / 6
    same = cmax == cmin
    return np.stack(np.broadcast_arrays(np.where(same, 0, h), np.where(same, 0, s), lum)).astype(np.float32)


def _hue_to_rgb(p, q, t):
    t = np.where(t < 0, t + 1, t)
    t = np.where(t > 1, t - 1, t)
    return np.where(t < 1 / 6, p + (q - p) * 6 * t, np.where(t < 0.5, q, np.where(t < 2 / 3,
                                                                                 p + (q - p) * (2 / 3 - t) * 6, p)))


def hsl_to_rgb(hsl):
    h, s, lum = (f32(x) for x in hsl)
    q = np.where(lum < 0.5, lum * (1 + s), lum + s - lum * s)
    p = 2 * lum - q
    rgb = [_hue_to_rgb(p, q, h + 1 / 3), _hue_to_rgb(p, q, h), _hue_to_rgb(p, q, h - 1 / 3)]
    return np.stack(np.broadcast_arrays(*[np.where(s == 0, lum, x) for x in rgb])).astype(np.float32)


def _blend(mode, t, a, b):
    tm = 1 - t
    if mode == "MIX":
        return a + t * (b - a)
    if mode == "ADD":
        return a + t * b
    if mode == "MULTIPLY":
        return a * (tm + t * b)
    if mode == "SCREEN":
        return 1 - (tm + t * (1 - b)) * (1 - a)
    if mode == "OVERLAY":
        return np.where(a < 0.5, a * (tm + 2 * t * b), 1 - (tm + 2 * t * (1 - b)) * (1 - a))
    if mode == "SUBTRACT":
        return a - t * b
    if mode == "DIVIDE":
        return np.where(b != 0, tm * a + t * safe_div(a, b), a)
    if mode == "DIFFERENCE":
        return a + t * (np.abs(a - b) - a)
    if mode == "EXCLUSION":
        return np.maximum(a + t * (a + b - 2 * a * b - a), 0)
    if mode == "DARKEN":
        return a + t * (np.minimum(a, b) - a)
    if mode == "LIGHTEN":
        return a + t * (np.maximum(a, b) - a)
    if mode == "DODGE":
        d = 1 - t * b
        return np.where(a != 0, np.where(d <= 0, _F(1), np.minimum(safe_div(a, d), 1)), a)
    if mode == "BURN":
        d = tm + t * b
        return np.where(d <= 0, _F(0), np.clip(1 - safe_div(1 - a, d), 0, 1))
    if mode == "SOFT_LIGHT":
        scr = 1 - (1 - b) * (1 - a)
        return tm * a + t * ((1 - a) * b * a + a * scr)
    if mode == "LINEAR_LIGHT":
        return a + t * (2 * b - 1)
    ha, hb = rgb_to_hsv(a), rgb_to_hsv(b)
    if mode == "HUE":
        return np.where(hb[1] != 0, a + t * (hsv_to_rgb(np.stack(np.broadcast_arrays(hb[0], ha[1], ha[2]))) - a), a)
    if mode == "SATURATION":
        return np.where(ha[1] != 0, hsv_to_rgb(np.stack(np.broadcast_arrays(ha[0], tm * ha[1] + t * hb[1], ha[2]))),
                        a)
    if mode == "VALUE":
        return hsv_to_rgb(np.stack(np.broadcast_arrays(ha[0], ha[1], tm * ha[2] + t * hb[2])))
    if mode == "COLOR":
        return np.where(hb[1] != 0, a + t * (hsv_to_rgb(np.stack(np.broadcast_arrays(hb[0], hb[1], ha[2]))) - a), a)
    raise ValueError(f"unknown blend mode {mode!r}")


def mix_color(attrs, params, t, a, b):
    t = f32(t)
    if params.get("clamp_factor", True):
        t = np.clip(t, 0, 1)
    a, b = f32(a), f32(b)
    out = f32(np.broadcast_to(_blend(params.get("blend", "MIX"), t, a, b), np.broadcast_shapes(a.shape, b.shape,
                                                                                             t.shape)))
    return np.clip(out, 0, 1).astype(np.float32) if params.get("clamp_result") else out


def _smoothstep(e0, e1, x):
    t = np.clip(safe_div(x - e0, e1 - e0), 0, 1)
    return t * t * (3 - 2 * t)


def _smootherstep(e0, e1, x):
    t = np.clip(safe_div(x - e0, e1 - e0), 0, 1)
    return t * t * t * (t * (t * 6 - 15) + 10)


def map_range(attrs, params, value, a, b, c, d, steps):
    """Map Range (float or per component): Linear, Stepped, Smooth Step, Smoother Step; Clamp for the first two."""
    value, a, b, c, d, steps = (f32(x) for x in (value, a, b, c, d, steps))
    kind = params.get("interpolation", "LINEAR")
    if kind in {"LINEAR", "STEPPED"}:
        f = safe_div(value - a, b - a)
        if kind == "STEPPED":
            f = np.where(steps > 0, np.floor(f * (steps + 1)) / np.where(steps > 0, steps, _F(1)), _F(0))
    elif kind == "SMOOTHSTEP":
        f = np.where(a > b, 1 - _smoothstep(b, a, value), _smoothstep(a, b, value))
    else:
        f = np.where(a > b, 1 - _smootherstep(b, a, value), _smootherstep(a, b, value))
    out = c + f * (d - c)
    out = np.where(a != b, out, _F(0))
    if params.get("clamp") and kind in {"LINEAR", "STEPPED"}:
        out = np.clip(out, np.minimum(c, d), np.maximum(c, d))
    return f32(out)


def clamp(attrs, params, value, lo, hi):
    value, lo, hi = f32(value), f32(lo), f32(hi)
    if params.get("type", "MINMAX") == "RANGE":
        lo, hi = np.minimum(lo, hi), np.maximum(lo, hi)
    return f32(np.minimum(np.maximum(value, lo), hi))


def invert(attrs, params, fac, color):
    return f32(color + f32(fac) * (1 - 2 * f32(color)))


def gamma(attrs, params, color, g):
    color = f32(color)
    return f32(np.where(color > 0, np.power(np.maximum(color, 0), f32(g)), color))


def bright_contrast(attrs, params, color, bright, contrast):
    a = 1 + f32(contrast)
    b = f32(bright) - f32(contrast) * _F(0.5)
    return f32(np.maximum(a * f32(color) + b, 0))


def hue_saturation(attrs, params, hue, sat, val, fac, color):
    color = f32(color)
    hsv = rgb_to_hsv(color)
    h = _fract(hsv[0] + f32(hue) + _F(0.5))
    s = np.clip(hsv[1] * f32(sat), 0, 1)
    v = hsv[2] * f32(val)
    out = hsv_to_rgb(np.stack(np.broadcast_arrays(h, s, v)))
    return f32(np.maximum(color + f32(fac) * (out - color), 0))


def separate(attrs, params, v):
    v = f32(v)
    mode = params.get("mode", "RGB")
    if mode == "HSV":
        v = rgb_to_hsv(v)
    elif mode == "HSL":
        v = rgb_to_hsl(v)
    return v[0], v[1], v[2]


def combine(attrs, params, x, y, z):
    v = np.stack(np.broadcast_arrays(f32(x), f32(y), f32(z))).astype(np.float32)
    mode = params.get("mode", "RGB")
    if mode == "HSV":
        return hsv_to_rgb(v)
    if mode == "HSL":
        return hsl_to_rgb(v)
    return v


def principled_f0(attrs, params, ior, level):
    """The dielectric F0 of the Principled BSDF: ((η - 1)/(η + 1))² · 2 · Specular IOR Level, in [0, 1]."""
    ior = f32(ior)
    r = safe_div(ior - 1, ior + 1)
    return f32(np.clip(r * r * 2 * np.maximum(f32(level), 0), 0, 1))


def aniso_aspect(attrs, params, anisotropy):
    """A GGX lobe's anisotropic aspect from a BSDF's anisotropy (params "glossy": the Glossy BSDF's mapping, else
    the Principled BSDF's; core/materials/anisotropy.py)."""
    from ..anisotropy import glossy_aspect, principled_aspect
    return (glossy_aspect if params.get("glossy") else principled_aspect)(f32(anisotropy))


def blackbody(attrs, params, temperature):
    """Blackbody node: the colour of a black body at ``temperature`` kelvin (luminance 1, core/lights/blackbody)."""
    from ...lights.blackbody import blackbody_rgb
    t = f32(temperature)
    got = blackbody_rgb(t)
    return got.reshape(3, 1) if np.ndim(t) == 0 else got


_WAVELENGTH = None


def _wavelength_table():
    """(nanometres (n,), rgb (n, 3)) float64: Blender's Wavelength node colours (data/wavelength.json, written by
    scripts/make_wavelength_table.py), read on first use."""
    global _WAVELENGTH
    if _WAVELENGTH is None:
        import json
        import os
        path = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "data", "wavelength.json")
        with open(path) as f:
            data = json.load(f)
        _WAVELENGTH = np.asarray(data["nanometres"], np.float64), np.asarray(data["rgb"], np.float64)
    return _WAVELENGTH


def wavelength(attrs, params, nanometres):
    """Wavelength node: the scene-linear Rec.709 colour Blender gives light of ``nanometres`` (its table, linear
    between whole nanometres; black outside it)."""
    nm_table, rgb = _wavelength_table()
    x = np.asarray(nanometres, np.float64)
    got = np.stack([np.interp(x, nm_table, rgb[:, c], left=0.0, right=0.0) for c in range(3)]).astype(np.float32)
    return got.reshape(3, 1) if np.ndim(x) == 0 else got


OPERATIONS = {
    "blackbody": blackbody, "wavelength": wavelength,
    "math": math, "vector_math": vector_math, "mix_float": mix_float, "mix_vector": mix_vector,
    "mix_color": mix_color, "map_range": map_range, "clamp": clamp, "invert": invert, "gamma": gamma,
    "bright_contrast": bright_contrast, "hue_saturation": hue_saturation, "separate": separate, "combine": combine,
    "rgb_to_bw": lambda attrs, params, c: luminance(c),
    "color_to_float": lambda attrs, params, c: luminance(c),
    "vector_to_float": lambda attrs, params, v: f32((f32(v)[0] + f32(v)[1] + f32(v)[2]) / 3),
    "float_to_vector": lambda attrs, params, x: f32(np.stack(np.broadcast_arrays(f32(x), f32(x), f32(x)))),
    "principled_f0": principled_f0, "aniso_aspect": aniso_aspect,
    "scale": lambda attrs, params, c, s: f32(f32(c) * f32(s)),
    "multiply": lambda attrs, params, a, b: f32(f32(a) * f32(b)),
    "add": lambda attrs, params, a, b: f32(f32(a) + f32(b)),
    "one_minus": lambda attrs, params, a: f32(1 - f32(a)),
    "saturate": lambda attrs, params, a: f32(np.clip(f32(a), 0, 1)),
    "reciprocal": lambda attrs, params, a: f32(1 / np.maximum(f32(a), np.float32(1e-6))),
}
