"""The film: running sums of a frame's sample passes and the passes made from them.

Accumulators are float32 (h, w, c) or (h, w) arrays (:data:`FILM_DTYPE`) over the camera window, row 0 at the
*bottom* (Blender's pass order), kept in a pool between frames: a fresh array's pages are faulted in on first
write, a reused one is only zeroed. Keys: emit, direct, indirect (RGB radiance, W·sr⁻¹·m⁻², scene-linear),
alpha; res_m, res_w (DI reservoirs' M and W); gi_m, gi_w (GI reservoirs'); lg0, lg1, ... (the light of each light
group: emission, direct and indirect together, lights/groups.py); albedo, dnormal (denoising data: first-hit
albedo, camera-space normal);
with adaptive sampling (pipeline/adaptive.py) count (each pixel's samples) and aux (twice the RGB of the samples in
its half set). Passes are their means over each pixel's samples (the frame's samples where no count is kept),
float32 and finite.
"""
from __future__ import annotations

import threading

import numpy as np

from ..materials.denoising_albedo import denoising_albedo
from .adaptive import in_half
from ..parallel.pool import in_worker, pool
from ..parallel.tasks import map_tasks
from ..sampling import finite

# the running sums' type: float32 holds a sum of 2^24 samples to a relative 1e-7 per addition (a rounding error
# far below the noise), and radiance is clamped at export (export/limits.MAX_RADIANCE) so that sums stay finite
FILM_DTYPE = np.float32


class BufferPool:
    """Film accumulators (FILM_DTYPE) kept between frames (at most ``keep`` free ones)."""

    def __init__(self, keep: int = 12):
        self.free: list[np.ndarray] = []
        self.keep = keep
        self.lock = threading.Lock()

    def zeros(self, shape) -> np.ndarray:
        with self.lock:
            for i, a in enumerate(self.free):
                if a.shape == tuple(shape):
                    a = self.free.pop(i)
                    a.fill(0.0)
                    return a
        return np.zeros(shape, FILM_DTYPE)

    def put(self, a: np.ndarray) -> None:
        with self.lock:
            self.free.append(a)
            del self.free[:-self.keep]


BUFFERS = BufferPool()


def film_keys(gi: bool, denoise_data: bool, adaptive: bool = False, groups: int = 0,
              catchers: bool = False) -> list[tuple[str, int]]:
    """(accumulator key, channels) of a film with ``groups`` light groups (and shadow catchers), in allocation
    order (1: an (h, w) array)."""
    keys = [("emit", 3), ("direct", 3), ("indirect", 3), ("alpha", 1), ("res_m", 1), ("res_w", 1)]
    if gi:
        keys += [("gi_m", 1), ("gi_w", 1)]
    keys += [(f"lg{k}", 3) for k in range(groups)]
    if catchers:
        keys += [("sc_with", 3), ("sc_without", 3), ("sc_behind", 3), ("sc_cov", 1)]
    if denoise_data:
        keys += [("albedo", 3), ("dnormal", 3)]
    if adaptive:
        keys += [("count", 1), ("aux", 3)]
    return keys


def _add_catchers(flat: dict, c, pixels: np.ndarray) -> None:
    """A chunk's shadow catcher sums (pipeline/shadow_catcher.py) into the flat accumulators at its catcher surfaces'
    ``pixels`` (unique)."""
    for key, value in (("sc_with", c.sc_with), ("sc_without", c.sc_without), ("sc_behind", c.sc_behind)):
        flat[key][pixels] += np.ascontiguousarray(value.T)
    flat["sc_cov"][pixels] += 1.0


def _pixels(pixels: np.ndarray):
    """A slice where ``pixels`` (sorted, unique) is a contiguous range, else the index array itself."""
    if len(pixels) and int(pixels[-1]) - int(pixels[0]) + 1 == len(pixels):
        return slice(int(pixels[0]), int(pixels[-1]) + 1)
    return pixels


class Film:
    """The accumulators of one camera window (w x h) and the sample count they hold. ``zeros(shape)`` gives the
    accumulators (default: the buffer pool's; a team's film passes views of one zero-filled shared segment, and
    then nothing returns to the pool)."""

    def __init__(self, w: int, h: int, gi: bool, denoise_data: bool, zeros=None, adaptive: bool = False,
                 group_names: tuple = (), catcher_mode: str | None = None):
        self.pooled = zeros is None
        z = zeros or BUFFERS.zeros
        self.group_names = tuple(group_names)
        self.catcher_mode = catcher_mode  # shadow_catcher.MODES, or None without shadow catchers
        self.acc = {key: z((h, w, c) if c > 1 else (h, w))
                    for key, c in film_keys(gi, denoise_data, adaptive, len(self.group_names),
                                            catcher_mode is not None)}
        self.samples = 0

    def has(self, key: str) -> bool:
        return key in self.acc

    def release(self) -> None:
        """Hand the accumulators back to the pool (this film cannot accumulate any more)."""
        if self.pooled:
            for a in self.acc.values():
                BUFFERS.put(a)
        self.acc = {}

    def accumulate(self, chunks, resampled: bool, world_to_cam: np.ndarray, stop, in_order=None) -> None:
        """Add the chunks' results to the running sums (chunks hold disjoint pixels: one pool task each);
        ``world_to_cam`` (3, 3) float32 turns normals into camera space for the denoising normal; ``in_order(add)``
        wraps each chunk's addition where other processes add other passes to the same film (parallel/team.py)."""
        flat = {k: a.reshape(len(a) * a.shape[1], -1) if a.ndim == 3 else a.reshape(-1) for k, a in self.acc.items()}

        def add(c):
            if c.batch > 1:
                return _add_batch(flat, c, len(self.group_names), world_to_cam)
            # the (3, k) results are transposed into contiguous (k, 3) copies first: adding a transposed view
            # to (k, 3) rows runs NumPy's inner loop over 3 elements
            span = _pixels(c.pixels)  # a slice where the chunk is a contiguous pixel range (no scatter)
            emitted = np.ascontiguousarray(c.hits.emitted.T)
            flat["emit"][span] += emitted
            flat["alpha"][span] += c.hits.alpha
            hit = c.hits.rows
            pix = span if len(hit) == len(c.pixels) else c.pixels[hit]  # every pixel hit: no scatter
            chain = None if c.chain is None else c.chain.throughput  # what the glass in front passes
            rgb = emitted.copy() if "aux" in flat else None  # the sample's RGB (adaptive sampling)
            for key, value in (("direct", c.direct), ("indirect", c.indirect)):
                if value is not None:
                    v = np.ascontiguousarray((value if chain is None else value * chain).T)
                    flat[key][pix] += v
                    if rgb is not None:
                        rgb[hit] += v
            if rgb is not None:
                _add_adaptive(flat, c.pixels, rgb)
            if self.group_names:
                add_groups(c, span, pix, chain)
            if c.catcher is not None and len(c.catcher):
                _add_catchers(flat, c, c.pixels[hit[c.catcher]])
            if resampled:
                flat["res_m"][pix] += c.res.M
                flat["res_w"][pix] += c.res.W
            if c.gi_res is not None:
                flat["gi_m"][pix] += c.gi_res.M
                flat["gi_w"][pix] += c.gi_res.W
            if "albedo" in flat and len(hit):
                surf = c.hits.surf
                albedo = denoising_albedo(surf)
                flat["albedo"][pix] += np.ascontiguousarray((albedo if chain is None else albedo * chain).T)
                flat["dnormal"][pix] += np.ascontiguousarray((world_to_cam @ surf.facing_normals()[1]).T)

        def add_groups(c, span, pix, chain):
            """Each light group's emission seen, direct and indirect light of the chunk's sample."""
            for k in range(len(self.group_names)):
                acc = flat[f"lg{k}"]
                if c.hits.emitted_g is not None:
                    acc[span] += np.ascontiguousarray(c.hits.emitted_g[k].T)
                for value in (c.direct_g, c.indirect_g):
                    if value is not None:
                        acc[pix] += np.ascontiguousarray((value[k] if chain is None else value[k] * chain).T)

        map_tasks(add if in_order is None else in_order(add), chunks, stop)

    def _inverse_counts(self):
        """1 / samples: a scalar, or (h, w) float32 per pixel where each pixel's count is kept."""
        if "count" in self.acc:
            return (1.0 / np.maximum(self.acc["count"], 1.0)).astype(np.float32)
        return np.float32(1.0 / max(1, self.samples))

    def combined(self) -> np.ndarray:
        """The running mean of Combined (h, w, 4) float32: emission + direct + indirect, and alpha; with shadow
        catchers, their shadows as the mode says (shadow_catcher.py)."""
        inv = self._inverse_counts()
        h, w = self.acc["alpha"].shape
        out = np.empty((h, w, 4), np.float32)
        np.add(self.acc["emit"], self.acc["direct"], out=out[..., :3], casting="unsafe")
        out[..., :3] += self.acc["indirect"]
        out[..., :3] *= inv if np.ndim(inv) == 0 else inv[..., None]
        np.multiply(self.acc["alpha"], inv, out=out[..., 3], casting="unsafe")
        if self.catcher_mode in ("TRANSPARENT", "OPAQUE"):
            from .shadow_catcher import shadow
            s = shadow(self.catcher_ratio(), self.acc["sc_cov"])
            if self.catcher_mode == "TRANSPARENT":
                out[..., 3] += (1.0 - out[..., 3]) * s
            else:
                out[..., :3] += self.mean("sc_behind") * (1.0 - s)[..., None]
                out[..., 3] += self.mean("sc_cov")[..., 0]
        return finite(out)

    def catcher_ratio(self) -> np.ndarray:
        """The Shadow Catcher pass (h, w, 3): Σ L_with / Σ L_without per pixel (shadow_catcher.ratio)."""
        from .shadow_catcher import ratio
        return finite(ratio(self.acc["sc_with"], self.acc["sc_without"]))

    def mean(self, key: str) -> np.ndarray:
        """The running mean of accumulator ``key`` as (h, w, c) float32 (c = 1 for scalar ones), finite."""
        a = self.acc[key]
        inv = self._inverse_counts()
        if np.ndim(inv) and a.ndim == 3:
            inv = inv[..., None]
        out = np.multiply(a, inv, out=np.empty(a.shape, np.float32), casting="unsafe")
        return finite(out if out.ndim == 3 else out[..., None])

    def sample_counts(self) -> np.ndarray | None:
        """(h, w, 1) float32: each pixel's samples, where adaptive sampling keeps them (else None)."""
        return None if "count" not in self.acc else self.acc["count"].astype(np.float32)[..., None]

    def passes(self, reservoirs: bool) -> dict:
        """{pass name: (h, w, c) float32} of the light passes, and the reservoir passes where ``reservoirs`` (DI)
        or the GI accumulators exist, and the denoising data where kept."""
        mean = self.mean
        jobs = {"Combined": self.combined, "Direct": lambda: mean("direct"), "Indirect": lambda: mean("indirect"),
                "Emission": lambda: mean("emit")}
        if reservoirs:
            jobs["Reservoir M"] = lambda: mean("res_m")
            jobs["Reservoir UCW"] = lambda: mean("res_w")
        if "gi_m" in self.acc:
            jobs["GI Reservoir M"] = lambda: mean("gi_m")
            jobs["GI Reservoir UCW"] = lambda: mean("gi_w")
        for k, name in enumerate(self.group_names):  # Cycles' names of the light groups' passes
            jobs[f"Combined_{name}"] = lambda k=k: mean(f"lg{k}")
        if "sc_with" in self.acc:
            jobs["Shadow Catcher"] = self.catcher_ratio
        if "count" in self.acc:
            jobs["Sample Count"] = self.sample_counts
        if "albedo" in self.acc:
            jobs["Denoising Albedo"] = lambda: mean("albedo")
            jobs["Denoising Normal"] = lambda: mean("dnormal")
        run = map if in_worker() else pool().map  # one pass per pool task (inline inside a worker)
        return dict(zip(jobs, run(lambda job: job(), jobs.values())))


def _add_adaptive(flat: dict, pixels, rgb) -> None:
    """Into the film's flat sums ``flat``: one more sample of ``pixels`` (unique) with RGB ``rgb`` (k, 3): the
    count, and twice the RGB into aux where it is the pixel's sample in the half set."""
    count = flat["count"][pixels]
    half = in_half(count)
    flat["count"][pixels] = count + 1.0
    sel = pixels[half]
    flat["aux"][sel] += 2.0 * rgb[half]


def _add_batch(flat: dict, c, groups: int, world_to_cam: np.ndarray) -> None:
    """Into the film's flat sums ``flat`` (with ``groups`` light groups): a chunk of ``batch`` samples per pixel (no
    reservoirs or glass chains: those passes do not batch; a chain of coloured transparent surfaces in front may
    come): each result summed over the samples of its pixel."""
    n = len(c.pixels) // c.batch
    chain = None if c.chain is None else c.chain.throughput
    base = c.pixels[:n]
    span = _pixels(base)
    emitted = c.hits.emitted.reshape(3, c.batch, n)
    flat["emit"][span] += emitted.sum(axis=1).T
    flat["alpha"][span] += c.hits.alpha.reshape(c.batch, n).sum(axis=0)
    rgb = np.ascontiguousarray(emitted.transpose(1, 2, 0), dtype=FILM_DTYPE) if "aux" in flat else None

    def add_rows(key, value, light=False, tinted=True):  # (3, hits) values of the hit rows, per pixel
        dense = _by_sample(c, n, c.hits.rows, (value if chain is None or not tinted else value * chain).T)
        flat[key][span] += dense.sum(axis=0)
        if light and rgb is not None:
            rgb[...] += dense

    for key, value in (("direct", c.direct), ("indirect", c.indirect)):
        if value is not None:
            add_rows(key, value, light=True)
    for k in range(groups):
        key = f"lg{k}"
        if c.hits.emitted_g is not None:
            flat[key][span] += c.hits.emitted_g[k].reshape(3, c.batch, n).sum(axis=1).T
        for value in (c.direct_g, c.indirect_g):
            if value is not None:
                add_rows(key, value[k])
    if c.catcher is not None and len(c.catcher):
        _add_batched_catchers(flat, c, span, n)
    if rgb is not None:
        for b in range(c.batch):  # the samples of the pass, in order
            _add_adaptive(flat, base, rgb[b])
    if "albedo" in flat and len(c.hits.rows):
        add_rows("albedo", denoising_albedo(c.hits.surf))
        add_rows("dnormal", world_to_cam @ c.hits.surf.facing_normals()[1], tinted=False)


def _by_sample(c, n: int, rows: np.ndarray, values: np.ndarray) -> np.ndarray:
    """(batch, n, ...) float32: ``values`` (k, ...) placed at positions ``rows`` of a batched chunk's pixel list (its
    ``n`` pixels once per sample), zero elsewhere; summed over axis 0 it is each pixel's sum over its samples."""
    dense = np.zeros((len(c.pixels),) + values.shape[1:], np.float32)
    dense[rows] = values
    return dense.reshape((c.batch, n) + values.shape[1:])


def _add_batched_catchers(flat: dict, c, span, n: int) -> None:
    """A batched chunk's shadow catcher sums (pipeline/shadow_catcher.py) into the film's flat sums at ``span`` (its
    ``n`` pixels): each summed over the samples of its pixel."""
    rows = c.hits.rows[c.catcher]  # positions in the chunk's (batch * n) pixel list
    for key, value in (("sc_with", c.sc_with), ("sc_without", c.sc_without), ("sc_behind", c.sc_behind)):
        flat[key][span] += _by_sample(c, n, rows, value.T).sum(axis=0)
    flat["sc_cov"][span] += _by_sample(c, n, rows, np.ones(len(rows), np.float32)).sum(axis=0)
