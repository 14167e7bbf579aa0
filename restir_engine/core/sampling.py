"""Random streams and discrete sampling.

Every random number the renderer draws comes from a generator keyed by
``(seed, frame, pass, stream, chunk)`` so that the same settings give the same image
whatever the thread scheduling, and a different ``seed`` gives independent noise.
"""
from __future__ import annotations

import numpy as np

# Stream identifiers: one per use of randomness, so adding a new use never shifts another.
STREAM_CAMERA = 1
STREAM_PATH = 2
STREAM_SHADE = 3
STREAM_TEMPORAL = 4
STREAM_TILES = 5
STREAM_INITIAL = 6
STREAM_PIXEL_OFFSET = 7  # per-pixel rotation of the pass sequence (keyed without the pass)
STREAM_GI_TEMPORAL = 8
STREAM_CHAIN = 9  # camera paths through smooth glass (camera_paths.follow_specular)
STREAM_LENS = 11  # aperture samples of camera rays (depth of field)
STREAM_PROBE = 10  # the AUTO indirect method's measurement of a frame without one (renderer.FrameRenderer._probe)
STREAM_SPATIAL = 16  # + spatial pass index
STREAM_GI_SPATIAL = 48  # + spatial pass index
# passes with camera rays of their own (pipeline/own_rays.py): (per-pixel shift, aperture) streams
STREAM_CRYPTO_RAYS = (96, 97)
STREAM_AOV_RAYS = (98, 99)
STREAM_CATCHER = 100  # shadow catchers' light without the other objects (pipeline/shadow_catcher.py)


def _sobol_2d(s: int) -> tuple[int, int]:
    """Point ``s`` of the first two Sobol dimensions as 32-bit integers: the van der Corput radical inverse in
    base 2 and the dimension of primitive polynomial x + 1 (direction numbers v_i = v_(i-1) xor (v_(i-1) >> 1)):
    every 2^k consecutive points from 0 form a (0, k, 2)-net, stratified in every elementary interval."""
    x = y = 0
    v = 1 << 31
    i = 0
    while s >> i:
        if (s >> i) & 1:
            x ^= 1 << (31 - i)
            y ^= v
        v ^= v >> 1
        i += 1
    return x, y


def pass_jitter(shift: np.ndarray, s: int) -> np.ndarray:
    """Positions in the pixel (n, 2) float32 for sample pass ``s``: Sobol point s, digitally shifted by a per-pixel
    random ``shift`` (n, 2) uint32 (xor; Cranley-Patterson for base 2). Each pass is uniform over the pixel
    (unbiased); the first 2^k passes of a pixel are stratified in every 2^-a x 2^-b box with a + b = k, so edges
    and small emitters converge faster than with independent jitter."""
    x, y = _sobol_2d(int(s))
    out = np.empty(shift.shape, np.float32)
    out[:, 0] = (shift[:, 0] ^ np.uint32(x)) >> np.uint32(8)  # 24 bits: exact in float32, < 1
    out[:, 1] = (shift[:, 1] ^ np.uint32(y)) >> np.uint32(8)
    out *= np.float32(1.0 / (1 << 24))
    out += np.float32(0.5 / (1 << 24))  # the centre of the 24-bit cell: uniform in [0, 1), never 0 or 1
    return out


def rng(seed: int, frame: int, pass_index: int, stream: int, chunk: int = 0) -> np.random.Generator:
    """A generator keyed by the tuple; independent across any differing key (SeedSequence hashing). The bit
    generator is SFC64: 2.5x faster raw output than Philox here, and statistically sound (PractRand/BigCrush)."""
    key = [int(seed) & 0xFFFFFFFF, int(frame) & 0xFFFFFFFF, int(pass_index) & 0xFFFFFFFF,
           int(stream) & 0xFFFFFFFF, int(chunk) & 0xFFFFFFFF]
    return np.random.Generator(np.random.SFC64(np.random.SeedSequence(key)))


def uniform_ints(rng: np.random.Generator, high: int, shape) -> np.ndarray:
    """Integers uniform in [0, high) (int64 array of ``shape``) from 32 random bits each: the low bits when
    ``high`` is a power of two (exact), else ⌊(u >> 8) · high / 2²⁴⌋ (non-uniformity below high / 2²⁴, as for
    a float32 uniform). No rejection loop: several times faster than Generator.integers."""
    count = int(np.prod(shape))
    raw = rng.bit_generator.random_raw((count + 1) // 2).view(np.uint32)[:count]
    if high & (high - 1) == 0:
        out = (raw & np.uint32(high - 1)).astype(np.int64)
    else:
        out = ((raw >> np.uint32(8)).astype(np.float32) * np.float32(high / 2 ** 24)).astype(np.int64)
        np.minimum(out, high - 1, out=out)
    return out.reshape(shape)


class AliasTable:
    """Walker/Vose alias table for O(1) sampling proportional to non-negative weights.

    Built without a Python loop over items, by the prefix-sum form of the sweeping
    construction: light items (weight below the mean) are assigned, in order, to the
    heavy item whose cumulative excess covers their cumulative deficit; a heavy item
    keeps as its own probability what is left after its last donation and aliases to
    the next heavy item.

    ``pdf`` holds the normalized probability of every item (zero-weight items get 0).
    """

    def __init__(self, weights: np.ndarray):
        w = np.asarray(weights, dtype=np.float64).ravel()
        w = np.where(np.isfinite(w) & (w > 0), w, 0.0)
        n = w.size
        total = w.sum()
        if n == 0 or total <= 0:
            raise ValueError("AliasTable needs at least one positive finite weight")
        self.n = n
        self.pdf = (w / total).astype(np.float64)
        scaled = w * (n / total)  # mean 1 = one bucket
        prob = np.ones(n, dtype=np.float64)
        alias = np.arange(n, dtype=np.int64)
        light = np.flatnonzero(scaled < 1.0)
        heavy = np.flatnonzero(scaled >= 1.0)
        if light.size and heavy.size:
            demand = 1.0 - scaled[light]
            d_incl = np.cumsum(demand)            # cumulative demand after each light item
            d_excl = d_incl - demand               # ... before it
            excess = np.cumsum(scaled[heavy] - 1.0)  # T_j: cumulative excess of heavies 1..j
            # light item -> first heavy whose cumulative excess exceeds the demand before it
            j = np.searchsorted(excess, d_excl, side="right")
            j = np.minimum(j, heavy.size - 1)
            prob[light] = scaled[light]
            alias[light] = heavy[j]
            # heavy j closes at the first cumulative demand >= T_j; residual 1 + T_j - D
            k = np.searchsorted(d_incl, excess, side="left")
            closes = k < light.size
            closes[-1] = False  # the last heavy absorbs rounding error and keeps probability 1
            hj = np.flatnonzero(closes)
            prob[heavy[hj]] = np.clip(1.0 + excess[hj] - d_incl[k[hj]], 0.0, 1.0)
            alias[heavy[hj]] = heavy[np.minimum(hj + 1, heavy.size - 1)]
        elif light.size:  # cannot happen with a positive total, kept for safety
            prob[:] = scaled
        self.prob = prob
        self.alias = alias

    def sample(self, u1: np.ndarray, u2: np.ndarray) -> np.ndarray:
        """Item indices (int64) from two uniform [0,1) arrays."""
        k = np.minimum((u1 * self.n).astype(np.int64), self.n - 1)
        return np.where(u2 < self.prob[k], k, self.alias[k])

    def implied_pdf(self) -> np.ndarray:
        """Probabilities the table actually realizes (for verification)."""
        p = self.prob.copy()
        np.add.at(p, self.alias, 1.0 - self.prob)
        return p / self.n


def uniform_triangle(u1: np.ndarray, u2: np.ndarray):
    """Uniform barycentrics (b1, b2) on a triangle, square-root mapping (area measure)."""
    su = np.sqrt(u1)
    return (1.0 - u2) * su, u2 * su


def cosine_hemisphere(u1: np.ndarray, u2: np.ndarray) -> np.ndarray:
    """Cosine-weighted directions around +z as (3, n) rows; pdf = cos/pi (solid angle)."""
    r = np.sqrt(u1)
    phi = np.float32(2.0 * np.pi) * u2
    out = np.empty((3, len(u1)), np.float32)
    out[0] = r * np.cos(phi)
    out[1] = r * np.sin(phi)
    out[2] = np.sqrt(np.maximum(0.0, 1.0 - u1))
    return out


# -- vectors: (3, n) rows x, y, z (structure of arrays) -------------------------------------------------
# Per-vector scalars broadcast along the contiguous axis ((3, n) * (n,)); with (n, 3) rows the same product
# is 5x slower in NumPy 1.26 and a mask product 15x slower, which is why the core keeps vectors as rows.

def cols(a: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """Columns ``idx`` of a (k, n) block (np.take along axis 1)."""
    return np.take(a, idx, axis=1)


def finite(a: np.ndarray) -> np.ndarray:
    """``a`` with its non-finite values set to 0, in place (one check when all are finite)."""
    bad = ~np.isfinite(a)
    if bad.any():
        a[bad] = 0.0
    return a


def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Dot products of (3, n) vectors."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def norm(v: np.ndarray) -> np.ndarray:
    """Lengths of (3, n) vectors."""
    return np.sqrt(dot(v, v))


def vmax(a: np.ndarray) -> np.ndarray:
    """Largest of the 3 components of (3, n) vectors (e.g. RGB)."""
    return np.maximum(np.maximum(a[0], a[1]), a[2])


def vfinite(a: np.ndarray) -> np.ndarray:
    """True where all 3 components of (3, n) vectors are finite."""
    return np.isfinite(a[0] + a[1] + a[2])


def barycentric(c0: np.ndarray, c1: np.ndarray, c2: np.ndarray, b1: np.ndarray, b2: np.ndarray) -> np.ndarray:
    """Corner values interpolated at barycentrics (b1, b2), broadcasting: (k, n) rows with (n,) barycentrics,
    or (n, k) per-corner rows with (n, 1) barycentrics."""
    return c0 * (1.0 - b1 - b2) + c1 * b1 + c2 * b2


def orthonormal_basis(n: np.ndarray):
    """Tangent frames (t, b), (3, k) each, for unit normals n (3, k), branchless (Duff et al. 2017)."""
    sign = np.where(n[2] >= 0.0, np.float32(1.0), np.float32(-1.0))
    a = -1.0 / (sign + n[2])
    b = n[0] * n[1] * a
    t = np.empty_like(n)
    bb = np.empty_like(n)
    t[0] = 1.0 + sign * n[0] * n[0] * a
    t[1] = sign * b
    t[2] = -sign * n[0]
    bb[0] = b
    bb[1] = sign + n[1] * n[1] * a
    bb[2] = -n[1]
    return t, bb


def to_world(local: np.ndarray, n: np.ndarray, t: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(3, k) local-frame vectors (z = n) to world space."""
    return local[0] * t + local[1] * b + local[2] * n


def to_local(v: np.ndarray, n: np.ndarray, t: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(3, k) world vectors into the frame (t, b, n)."""
    out = np.empty((3, v.shape[1]), np.result_type(v, n))
    out[0] = dot(v, t)
    out[1] = dot(v, b)
    out[2] = dot(v, n)
    return out


def inverse3(m: np.ndarray) -> np.ndarray:
    """Inverses of (..., 3, 3) matrices by cofactors, float64 (a batched np.linalg.inv calls LAPACK once per matrix
    and lets BLAS start its threads, which contend with the renderer's own)."""
    m = np.asarray(m, np.float64)
    a, b, c = m[..., 0, 0], m[..., 0, 1], m[..., 0, 2]
    d, e, f = m[..., 1, 0], m[..., 1, 1], m[..., 1, 2]
    g, h, i = m[..., 2, 0], m[..., 2, 1], m[..., 2, 2]
    c00, c01, c02 = e * i - f * h, f * g - d * i, d * h - e * g
    c10, c11, c12 = c * h - b * i, a * i - c * g, b * g - a * h
    c20, c21, c22 = b * f - c * e, c * d - a * f, a * e - b * d
    det = a * c00 + b * c01 + c * c02
    adj = np.stack([np.stack([c00, c10, c20], -1), np.stack([c01, c11, c21], -1), np.stack([c02, c12, c22], -1)], -2)
    return adj / det[..., None, None]
