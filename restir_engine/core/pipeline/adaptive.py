"""Adaptive sampling as Cycles schedules it: pixels whose noise estimate fell under the Noise Threshold stop taking
samples, and the passes that follow trace only the pixels still active.

The noise estimate of a pixel compares the mean of all its samples, I, with the mean of a fixed half of them, A
(its samples n = 0, 1, 2 ... with an odd count of set bits in ``n & 0xAAAAAAAA``: two of every aligned four),
both scene-linear RGB: e = Σ_c |I_c − A_c| / (1e-4 + r(S)), S = Σ_c I_c, r(S) = √S below 1 and S above (relative
noise in bright pixels, absolute-like in dark ones). The film keeps A's sum (twice the half's samples, "aux") and
each pixel's sample count ("count").

Schedule: a check after every STEP-th sample once more than the minimum samples are done; a pixel converges when
e < CHECK_SCALE · threshold; the pixels still unconverged then spread one pixel along rows and then columns (their
neighbours, stopped or not, take samples again), so a converged region's edge is not left noisier than its
inside. The frame ends when no pixel is left or at the sample count.
"""
from __future__ import annotations

import math

import numpy as np

STEP = 16           # samples between convergence checks
CHECK_SCALE = 5.0   # a pixel converges when its estimate is under this many times the threshold
HALF_BITS = np.uint32(0xAAAAAAAA)
MIN_FLOOR = 4       # automatic minimum samples: at least this many


def threshold_for(threshold: float, samples: int) -> float:
    """The noise threshold in use: the setting, or (0 = automatic) 1/samples, at least 0.001."""
    return float(threshold) if threshold > 0 else max(0.001, 1.0 / max(1, int(samples)))


def min_samples_for(min_samples: int, threshold: float) -> int:
    """Samples every pixel takes before the first check: the setting, or (0 = automatic) ⌈16 / threshold^0.3⌉; at
    least MIN_FLOOR either way."""
    if min_samples > 0:
        return max(MIN_FLOOR, int(min_samples))
    return max(MIN_FLOOR, int(math.ceil(16.0 / threshold ** 0.3)))


def in_half(sample_index: np.ndarray) -> np.ndarray:
    """(n,) bool: whether a pixel's sample number ``sample_index`` (0-based, integer array) is in the half set A
    (an odd count of set bits in sample_index & 0xAAAAAAAA)."""
    x = np.asarray(sample_index).astype(np.uint32) & HALF_BITS
    for shift in (16, 8, 4, 2, 1):
        x ^= x >> np.uint32(shift)
    return (x & np.uint32(1)).astype(bool)


def noise_estimate(total: np.ndarray, half: np.ndarray, count: np.ndarray) -> np.ndarray:
    """(...,) float64: the noise estimate e of pixels with RGB sum ``total`` (..., 3), twice the half set's sum
    ``half`` (..., 3) and ``count`` samples (...,)."""
    inv = 1.0 / np.maximum(count, 1.0)
    mean = total * inv[..., None]
    diff = np.abs(mean - half * inv[..., None]).sum(axis=-1)
    s = mean.sum(axis=-1)
    norm = np.where(s < 1.0, np.sqrt(np.maximum(s, 0.0)), s)
    return diff / (1e-4 + norm)


def spread(unconverged: np.ndarray) -> np.ndarray:
    """(h, w) bool: ``unconverged`` grown by one pixel along rows, then along columns (a 3x3 square)."""
    out = unconverged.copy()
    out[:, 1:] |= unconverged[:, :-1]
    out[:, :-1] |= unconverged[:, 1:]
    rows = out.copy()
    out[1:, :] |= rows[:-1, :]
    out[:-1, :] |= rows[1:, :]
    return out


class AdaptiveSampling:
    """Which window pixels (h, w) the next passes sample, for a frame of ``samples`` with the settings' threshold
    and minimum. ``active`` is None while every pixel takes samples, else (h * w,) bool."""

    def __init__(self, w: int, h: int, samples: int, threshold: float, min_samples: int):
        self.w, self.h, self.samples = int(w), int(h), int(samples)
        self.threshold = threshold_for(threshold, samples)
        self.min_samples = min_samples_for(min_samples, self.threshold)
        self.stopped = np.zeros((self.h, self.w), bool)
        self.active = None
        self.finished = False
        self.checks: list[tuple[int, float]] = []  # (samples done, share of pixels still active) after each check

    def next_check(self, done: int) -> int | None:
        """The sample count after which the next check runs (``done`` samples rendered so far), or None."""
        first = self.min_samples + 2  # a check follows sample number s (0-based) with s > min and s % STEP == STEP - 1
        at = max(first, done + 1)
        at = -(-at // STEP) * STEP
        return at if at < self.samples else None

    def cap(self, done: int, batch: int) -> int:
        """``batch`` cut so that a pass ends at the next check."""
        at = self.next_check(done)
        return batch if at is None else max(1, min(batch, at - done))

    def due(self, done: int) -> bool:
        return done < self.samples and done > self.min_samples + 1 and done % STEP == 0

    def check(self, film, done: int) -> None:
        """Stop the pixels of ``film`` (pipeline.film.Film with the "count" and "aux" sums) that converged, spread
        the unconverged ones and set :attr:`active`."""
        acc = film.acc
        total = acc["emit"] + acc["direct"] + acc["indirect"]
        e = noise_estimate(total, acc["aux"], acc["count"])
        self.stopped |= e < CHECK_SCALE * self.threshold
        keep = spread(~self.stopped)
        self.stopped &= ~keep
        share = float(keep.mean())
        self.checks.append((int(done), share))
        self.finished = not keep.any()
        self.active = None if keep.all() else keep.ravel()

    def pixels(self) -> np.ndarray | None:
        """The window pixels (row-major) the next pass samples, or None for every pixel."""
        return None if self.active is None else np.flatnonzero(self.active)

    def stats(self) -> dict:
        return {"threshold": self.threshold, "min_samples": self.min_samples, "checks": list(self.checks)}
