"""Structure-of-arrays reservoirs, generic over the sample they hold.

A reservoir type lists its sample fields (``SAMPLE``: name -> dtype); every type also carries
  M      confidence (float32, number of candidates it summarizes, capped when reused)
  W      unbiased contribution weight of its sample (float32; units: 1 / the target's measure)
  p_hat  the target function of the reservoir's own pixel at its sample (float32)
The first sample field is the key: -1 marks an empty reservoir.

Resampled importance sampling (Talbot 2005; Bitterli et al. 2020, eq. 3-6): candidates y_i with resampling
weights w_i are streamed in; one is kept with probability w_i / Σw; the reservoir then has
W = Σw / (p̂(y) · D) with D = 1 for normalized weights (MIS, pairwise) or D = ΣM for the 1/M merge.
"""
from __future__ import annotations

import numpy as np

COMMON = {"M": np.float32, "W": np.float32, "p_hat": np.float32}


class Reservoirs:
    """n reservoirs of the type's fields, one contiguous array each."""

    SAMPLE: dict = {}

    def __init__(self, **arrays):
        for name in self.fields():
            setattr(self, name, arrays[name])

    @classmethod
    def fields(cls) -> tuple:
        return tuple(cls.SAMPLE) + tuple(COMMON)

    @classmethod
    def key_field(cls) -> str:
        return next(iter(cls.SAMPLE))

    @classmethod
    def empty(cls, n: int) -> "Reservoirs":
        arrays = {name: np.zeros(n, dt) for name, dt in {**cls.SAMPLE, **COMMON}.items()}
        arrays[cls.key_field()][:] = -1
        return cls(**arrays)

    @classmethod
    def allocate(cls, n: int, empty) -> "Reservoirs":
        """n reservoirs in arrays from ``empty(shape, dtype)`` (e.g. a team's shared buffers), not initialized: the
        caller writes every row."""
        return cls(**{name: empty(n, dt) for name, dt in {**cls.SAMPLE, **COMMON}.items()})

    def __len__(self) -> int:
        return len(self.M)

    @property
    def key(self) -> np.ndarray:
        return getattr(self, self.key_field())

    def has_sample(self) -> np.ndarray:
        return self.key >= 0

    def take(self, rows) -> "Reservoirs":
        """Reservoirs ``rows`` (index array or slice) as a new set."""
        return type(self)(**{name: getattr(self, name)[rows] for name in self.fields()})

    def assign(self, rows, other: "Reservoirs") -> None:
        """self[rows] = other (every field)."""
        for name in self.fields():
            getattr(self, name)[rows] = getattr(other, name)

    def replace(self, **arrays) -> "Reservoirs":
        """A set sharing this one's arrays except those given."""
        return type(self)(**{name: arrays.get(name, getattr(self, name)) for name in self.fields()})

    def clear(self, rows) -> None:
        """Empty reservoirs ``rows`` in place (their confidence M is kept)."""
        self.key[rows] = -1
        self.W[rows] = 0.0
        self.p_hat[rows] = 0.0


class Stream:
    """Weighted reservoir sampling over candidate batches, vectorized over n reservoirs.

    Each :meth:`add` offers one candidate per row (rows listed, or all rows); the kept sample of each row
    is distributed in proportion to the weights offered so far. :meth:`finish` turns the weight sum into W."""

    def __init__(self, kind: type, n: int, rng: np.random.Generator):
        self.res = kind.empty(n)
        self.w_sum = np.zeros(n, np.float32)
        self.rng = rng

    def add(self, w: np.ndarray, p_hat: np.ndarray, src: Reservoirs, src_rows=None, rows=None) -> None:
        """Offer the samples ``src[src_rows]`` (default: src row i for candidate i) with resampling weights w
        and target values p̂ (at this stream's pixels) to rows ``rows`` (default: every row, in order)."""
        w = np.asarray(w, np.float32)
        w = w * (w > 0)  # NaN and negative weights: 0 (NaN > 0 is False, NaN * 0 stays NaN: replaced below)
        if not np.isfinite(w).all():
            w[~np.isfinite(w)] = 0.0
        if rows is None:
            self.w_sum += w
            take = np.flatnonzero(self.rng.random(len(w), dtype=np.float32) * self.w_sum < w)
            dst = take
        else:
            self.w_sum[rows] += w
            take = np.flatnonzero(self.rng.random(len(w), dtype=np.float32) * self.w_sum[rows] < w)
            dst = rows[take]
        if take.size == 0:
            return
        picked = take if src_rows is None else src_rows[take]
        for name in src.SAMPLE:
            getattr(self.res, name)[dst] = getattr(src, name)[picked]
        self.res.p_hat[dst] = p_hat[take]

    def finish(self, M: np.ndarray, denom: np.ndarray | None = None) -> Reservoirs:
        """The reservoirs with confidence M and W = Σw / (p̂ · denom) (denom 1 when None); rows whose kept
        sample has p̂ = 0 (or denom = 0) are empty."""
        res = self.res
        scale = res.p_hat if denom is None else res.p_hat * denom
        ok = res.has_sample() & (scale > 0)
        res.W = (self.w_sum / np.maximum(scale, np.float32(1e-30)) * ok).astype(np.float32, copy=False)
        res.key[~ok] = -1
        res.p_hat[~ok] = 0.0
        res.M = np.asarray(M, np.float32) * np.ones(len(res.W), np.float32)
        return res
