"""IES photometric profiles (IESNA LM-63 files) as Cycles reads them for the IES Texture node.

A profile is a table of luminous intensities over vertical angles (0 = straight down the light's -Z axis, 180 = up)
and horizontal angles (about the axis). Photometric types A and B are turned into type C's frame, and the
symmetries a file may declare by its horizontal range (one value for all, one quadrant, one half) are mirrored out to
the full 0-360 range, as Cycles does. Intensities are in candela times the file's multiplier and ballast factors,
converted to Blender's light units with the luminous efficacy of the D65 illuminant and the 4π of a lamp's power:
1 cd -> 4π / 177.83.

A lookup (:func:`evaluate`) takes a direction in the light's space: vertical angle acos(-z), horizontal angle
atan2(x, y) + π; the table is interpolated by Catmull-Rom cubics, vertically then horizontally (an end's missing
neighbour repeats the end, or comes from across the pole or the 0/360 seam where Cycles' float32 test finds the table
reaching it), zero outside its range, never negative.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

#: candela -> the node's units: 4π / (the luminous efficacy of D65, 177.83 lm/W)
CANDELA_TO_WATT = 4.0 * np.pi / 177.83
#: the value Cycles gives a lookup in a profile it could not read
UNREADABLE = 100.0

_F = np.float32
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


class IesError(ValueError):
    """An IES text that is not a readable LM-63 profile."""


@dataclass(frozen=True)
class IesTable:
    """``h`` (nh,) and ``v`` (nv,) ascending angles in radians; ``values`` (nh, nv) float32 intensities in the node's
    units."""

    h: np.ndarray
    v: np.ndarray
    values: np.ndarray


def _numbers(text: str) -> list:
    return [float(x) for x in _NUMBER.findall(text)]


def _close(a: float, b: float) -> bool:
    return abs(a - b) < 1e-4


def parse(text: str) -> IesTable:
    """The profile of an LM-63 text (any revision: keyword lines, TILT=NONE / INCLUDE / a file name). Raises
    :class:`IesError`."""
    at = text.find("TILT=")
    if at < 0:
        raise IesError("no TILT= line (not an IES LM-63 file)")
    line_end = text.find("\n", at)
    tilt = text[at + 5:line_end if line_end >= 0 else len(text)].strip()
    rest = text[line_end + 1:] if line_end >= 0 else ""
    nums = _numbers(rest)
    pos = 0
    if tilt.upper().startswith("INCLUDE"):
        if len(nums) < 2:
            raise IesError("truncated TILT=INCLUDE block")
        pos = 2 + 2 * int(nums[1])  # lamp-to-luminaire geometry, count, then angles and factors
    head = nums[pos:pos + 13]
    if len(head) < 13:
        raise IesError("truncated header")
    multiplier, nv, nh, kind = head[2], int(head[3]), int(head[4]), int(head[5])
    factor = multiplier * head[10] * head[11] * CANDELA_TO_WATT
    if kind not in (1, 2, 3):
        raise IesError(f"photometric type {kind} (expected 1 = C, 2 = B or 3 = A)")
    if nv < 1 or nh < 1:
        raise IesError(f"{nv} vertical and {nh} horizontal angles")
    body = nums[pos + 13:]
    if len(body) < nv + nh + nv * nh:
        raise IesError(f"{len(body)} numbers for {nv} x {nh} angles and intensities")
    v = list(body[:nv])
    h = list(body[nv:nv + nh])
    values = [list(np.array(body[nv + nh + i * nv:nv + nh + (i + 1) * nv]) * factor) for i in range(nh)]
    if kind == 1:
        h, v, values = _type_c(h, v, values)
    elif kind == 2:
        h, v, values = _type_b(h, v, values)
    else:
        h, v, values = _type_a(h, v, values)
    return IesTable(_radians(h), _radians(v), np.array(values, np.float32))


def _radians(degrees) -> np.ndarray:
    """Degrees -> radians in float32 arithmetic (x · (π / 180), each step rounded to float32), as Cycles converts
    the table's angles: the wrap tests of :func:`evaluate` depend on those exact values."""
    return (np.array(degrees, np.float32) * (_F(np.pi) / _F(180.0))).astype(np.float32)


def _type_c(h, v, values):
    """Type C: horizontal angles about the vertical axis; a range of 90-270 is turned to 0-180; one angle, one
    quadrant or one half mirrored out to 0-360; a table stopping one step short of 360 closed with its 0 column."""
    if _close(h[0], 90.0):
        h = [a - 90.0 for a in h]
    if len(h) == 1:
        h, values = [0.0, 360.0], [values[0], values[0]]
    if _close(h[-1], 90.0):
        h = h + [180.0 - a for a in h[-2::-1]]
        values = values + values[-2::-1]
    if _close(h[-1], 180.0):
        h = h + [360.0 - a for a in h[-2::-1]]
        values = values + values[-2::-1]
    if len(h) > 1 and _close(h[0], 0.0) and not _close(h[-1], 360.0):
        gap = 360.0 - h[-1]
        if _close(h[-1] - h[-2], gap) or _close(h[1] - h[0], gap):
            h, values = h + [360.0], values + [values[0]]
    return h, v, values


def _type_a(h, v, values):
    """Type A: vertical angles from the horizon (-90..90) shifted to 0..180; horizontal -90..90 mapped onto type C's
    270..90 (a 0..90 range mirrored to the negative side)."""
    v = [a + 90.0 for a in v]
    new_h = [180.0 - a for a in h[::-1]]
    new_values = values[::-1]
    if _close(h[0], 0.0):
        new_h += [180.0 + a for a in h[1:]]
        new_values += values[1:]
    return new_h, v, new_values


def _type_b(h, v, values):
    """Type B (polar axis horizontal): the two angle sets swapped (the light may be turned to face its axis), each
    0..90 range mirrored to -90..90, then shifted to 0..180."""
    values = [list(col) for col in zip(*values)]
    h, v = v, h
    if _close(h[0], 0.0):
        values = values[:0:-1] + values
        h = [90.0 - a for a in h[:0:-1]] + [90.0 + a for a in h]
    else:
        h = [a + 90.0 for a in h]
    if _close(v[0], 0.0):
        values = [list(col[:0:-1]) + list(col) for col in values]
        v = [90.0 - a for a in v[:0:-1]] + [90.0 + a for a in v]
    else:
        v = [a + 90.0 for a in v]
    return h, v, values


def _cubic(a, b, c, d, x):
    """Catmull-Rom through b (x = 0) and c (x = 1), a and d the points before and after."""
    return 0.5 * (((d + 3.0 * (b - c) - a) * x + (2.0 * a - 5.0 * b + 4.0 * c - d)) * x + (c - a)) * x + b


def _cell(angles: np.ndarray, x: np.ndarray):
    """Index i (n,) of the interval [angles[i], angles[i + 1]] holding x (the first whose end reaches x) and the
    fraction of x in it."""
    i = np.clip(np.searchsorted(angles, x, side="left") - 1, 0, max(len(angles) - 2, 0))
    lo, hi = angles[i], angles[np.minimum(i + 1, len(angles) - 1)]
    frac = np.where(hi != lo, (x - lo) / np.where(hi != lo, hi - lo, 1.0), 0.0)
    return i, frac.astype(np.float32)


def evaluate(table: IesTable | None, vector: np.ndarray) -> np.ndarray:
    """Intensity (n,) float32 of ``table`` towards directions ``vector`` (3, n) in the light's space (normalized
    here); :data:`UNREADABLE` everywhere without a table."""
    vec = np.asarray(vector, np.float32)
    n = vec.shape[1]
    if table is None:
        return np.full(n, UNREADABLE, np.float32)
    ln = np.sqrt((vec * vec).sum(axis=0))
    d = vec / np.where(ln > 0, ln, 1.0)
    v_ang = np.arccos(np.clip(-d[2], -1.0, 1.0)).astype(np.float32)
    h_ang = (np.arctan2(d[0], d[1]) + np.float32(np.pi)).astype(np.float32)
    h, v, vals = table.h, table.v, table.values
    nh, nv = len(h), len(v)
    inside = (v_ang >= v[0]) & (v_ang < v[-1]) & (h_ang >= h[0]) & (h_ang < h[-1])
    if nh < 2 or nv < 2 or not inside.any():
        return np.zeros(n, np.float32)
    # wrap where the table reaches a pole or closes the circle, compared in float32 as Cycles compares: 2π - 1e-7 and
    # π - 1e-7 round to 2π and π there, so a table ending at exactly 360° (180°) does not wrap its cubic's ends
    wrap_h = bool(h[0] < _F(1e-7)) and bool(h[-1] > _F(2 * np.pi) - _F(1e-7))
    wrap_vlo, wrap_vhi = bool(v[0] < _F(1e-7)), bool(v[-1] > _F(np.pi) - _F(1e-7))
    hi_, hf = _cell(h, h_ang)
    vi_, vf = _cell(v, v_ang)

    def column(col):
        """The vertical cubic at (vi_, vf) in horizontal columns ``col`` (n,)."""
        b = vals[col, vi_]
        c = vals[col, np.minimum(vi_ + 1, nv - 1)]
        a = np.where(vi_ > 0, vals[col, np.maximum(vi_ - 1, 0)], vals[col, min(1, nv - 1)] if wrap_vlo else b)
        d_ = np.where(vi_ + 2 < nv, vals[col, np.minimum(vi_ + 2, nv - 1)], vals[col, max(nv - 2, 0)] if wrap_vhi
                      else c)
        return _cubic(a, b, c, d_, vf)
    b = column(hi_)
    c = column(np.minimum(hi_ + 1, nh - 1))
    a = column(np.maximum(hi_ - 1, 0))
    a = np.where(hi_ > 0, a, column(np.full(n, nh - 2)) if wrap_h else b)
    d_ = column(np.minimum(hi_ + 2, nh - 1))
    d_ = np.where(hi_ + 2 < nh, d_, column(np.full(n, 1 % nh)) if wrap_h else b)
    out = np.maximum(_cubic(a, b, c, d_, hf), 0.0)
    return np.where(inside, out, 0.0).astype(np.float32)
