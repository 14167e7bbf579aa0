"""The film's pixel filter, sampled by importance: each camera sample lands at a raster offset drawn from the
filter's profile (separable in x and y) and counts with weight 1 in its own pixel, as Cycles filters, so the
image is the filtered image without weights, negative lobes or extra rays.

Filters (Blender's names and widths, in pixels): "BOX" (always 1 px wide), "GAUSSIAN" (width w: a Gaussian of
standard deviation w/4 cut at ±1.5 w), "BLACKMAN_HARRIS" (width w: the four-term window over ±w). Offsets are
relative to the pixel's lower-left corner, so a box filter gives [0, 1)."""
from __future__ import annotations

import numpy as np

TABLE_SIZE = 1024
FILTERS = ("BOX", "GAUSSIAN", "BLACKMAN_HARRIS")


def support(kind: str, width: float) -> float:
    """The filter's full support in pixels (the offsets span ±support / 2 about the pixel centre)."""
    w = max(float(width), 1e-3)
    return {"BOX": 1.0, "GAUSSIAN": 3.0 * w, "BLACKMAN_HARRIS": 2.0 * w}.get(kind, 1.0)


def profile(kind: str, width: float, v: np.ndarray) -> np.ndarray:
    """The filter's value at distances v (pixels) from the centre, within the support (float64)."""
    s = support(kind, width)
    v = np.abs(np.asarray(v, np.float64))
    if kind == "GAUSSIAN":
        return np.exp(-2.0 * (6.0 * v / s) ** 2)  # exp(-v² / 2σ²) with σ = width / 4
    if kind == "BLACKMAN_HARRIS":
        t = 2.0 * np.pi * (v / s + 0.5)
        return 0.35875 - 0.48829 * np.cos(t) + 0.14128 * np.cos(2 * t) - 0.01168 * np.cos(3 * t)
    return np.ones_like(v)


def _inverse_cdf(kind: str, width: float) -> np.ndarray:
    """(TABLE_SIZE,) float64: offsets from the pixel centre at uniform quantiles i / (TABLE_SIZE - 1)."""
    s = support(kind, width)
    v = np.linspace(-s / 2, s / 2, 4097)
    f = np.abs(profile(kind, width, v))
    cdf = np.concatenate([[0.0], np.cumsum((f[1:] + f[:-1]) * 0.5 * np.diff(v))])
    cdf /= cdf[-1]
    return np.interp(np.linspace(0.0, 1.0, TABLE_SIZE), cdf, v)


class PixelFilter:
    """A filter ``kind`` of ``width`` pixels; :meth:`offsets` maps uniform numbers to raster offsets."""

    def __init__(self, kind: str = "BOX", width: float = 1.0):
        self.kind = kind if kind in FILTERS else "BOX"
        self.width = 1.0 if self.kind == "BOX" else max(float(width), 1e-3)
        self.box = self.kind == "BOX"
        self.table = None if self.box else (_inverse_cdf(self.kind, self.width) + 0.5).astype(np.float32)

    @property
    def reach(self) -> float:
        """How far beyond its own pixel a sample may land, in pixels."""
        return max(0.0, support(self.kind, self.width) / 2 - 0.5)

    def offsets(self, u: np.ndarray) -> np.ndarray:
        """Raster offsets (float32, same shape as ``u``) from the pixel's lower-left corner for uniform u in [0, 1):
        u itself for the box filter, else the filter's inverse CDF (linear between table entries)."""
        if self.box:
            return u
        x = np.asarray(u, np.float32) * np.float32(TABLE_SIZE - 1)
        i = np.minimum(x.astype(np.int64), TABLE_SIZE - 2)
        t = x - i
        lo, hi = self.table[i], self.table[i + 1]
        return (lo + (hi - lo) * t).astype(np.float32)

    def __eq__(self, other) -> bool:
        return isinstance(other, PixelFilter) and (self.kind, self.width) == (other.kind, other.width)

    def __hash__(self) -> int:
        return hash((self.kind, self.width))

    def __repr__(self) -> str:
        return f"PixelFilter({self.kind!r}, {self.width})"
