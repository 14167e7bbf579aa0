"""The film: running sums of a frame's sample passes and the passes made from them.

Accumulators are float64 (h, w, c) or (h, w) arrays over the camera window, row 0 at the *bottom* (Blender's pass
order), kept in a pool between frames: a fresh array's pages are faulted in on first write, a reused one is only
zeroed. Keys: emit, direct, indirect (RGB radiance, W·sr⁻¹·m⁻², scene-linear), alpha; res_m, res_w (DI reservoirs'
M and W); gi_m, gi_w (GI reservoirs'); albedo, dnormal (denoising data: first-hit albedo, camera-space normal).
Passes are their means over the samples done, float32 and finite.
"""
from __future__ import annotations

import threading

import numpy as np

from ..materials.bsdf import denoising_albedo
from ..parallel.pool import in_worker, pool
from ..parallel.tasks import map_tasks
from ..sampling import finite


class BufferPool:
    """Float64 accumulators kept between frames (at most ``keep`` free ones)."""

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
        return np.zeros(shape, np.float64)

    def put(self, a: np.ndarray) -> None:
        with self.lock:
            self.free.append(a)
            del self.free[:-self.keep]


BUFFERS = BufferPool()


def film_keys(gi: bool, denoise_data: bool) -> list[tuple[str, int]]:
    """(accumulator key, channels) of a film, in allocation order (1: an (h, w) array)."""
    keys = [("emit", 3), ("direct", 3), ("indirect", 3), ("alpha", 1), ("res_m", 1), ("res_w", 1)]
    if gi:
        keys += [("gi_m", 1), ("gi_w", 1)]
    if denoise_data:
        keys += [("albedo", 3), ("dnormal", 3)]
    return keys


class Film:
    """The accumulators of one camera window (w x h) and the sample count they hold. ``zeros(shape)`` gives the
    accumulators (default: the buffer pool's; a team's film passes views of one zero-filled shared segment, and
    then nothing returns to the pool)."""

    def __init__(self, w: int, h: int, gi: bool, denoise_data: bool, zeros=None):
        self.pooled = zeros is None
        z = zeros or BUFFERS.zeros
        self.acc = {key: z((h, w, c) if c > 1 else (h, w)) for key, c in film_keys(gi, denoise_data)}
        self.samples = 0

    def has(self, key: str) -> bool:
        return key in self.acc

    def release(self) -> None:
        """Hand the accumulators back to the pool (this film cannot accumulate any more)."""
        if self.pooled:
            for a in self.acc.values():
                BUFFERS.put(a)
        self.acc = {}

    def accumulate(self, chunks, resampled: bool, world_to_cam: np.ndarray, stop) -> None:
        """Add the chunks' results to the running sums (chunks hold disjoint pixels: one pool task each);
        ``world_to_cam`` (3, 3) float32 turns normals into camera space for the denoising normal."""
        flat = {k: a.reshape(len(a) * a.shape[1], -1) if a.ndim == 3 else a.reshape(-1) for k, a in self.acc.items()}

        def add(c):
            if c.batch > 1:
                return add_batch(c)
            # the (3, k) results are transposed into contiguous (k, 3) copies first: adding a transposed view
            # to (k, 3) rows runs NumPy's inner loop over 3 elements
            span = slice(int(c.pixels[0]), int(c.pixels[-1]) + 1)  # a chunk is a contiguous pixel range
            flat["emit"][span] += np.ascontiguousarray(c.hits.emitted.T)
            flat["alpha"][span] += c.hits.alpha
            hit = c.hits.rows
            pix = span if len(hit) == len(c.pixels) else c.pixels[hit]  # every pixel hit: a slice, no scatter
            chain = None if c.chain is None else c.chain.throughput  # what the glass in front passes
            for key, value in (("direct", c.direct), ("indirect", c.indirect)):
                if value is not None:
                    flat[key][pix] += np.ascontiguousarray((value if chain is None else value * chain).T)
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
                flat["dnormal"][pix] += np.ascontiguousarray((world_to_cam @ surf.ns).T)

        def add_batch(c):
            """A chunk of ``batch`` samples per pixel (no reservoirs or glass chains: those passes do not batch):
            each result summed over the samples of its pixel."""
            n = len(c.pixels) // c.batch
            span = slice(int(c.pixels[0]), int(c.pixels[0]) + n)
            flat["emit"][span] += c.hits.emitted.reshape(3, c.batch, n).sum(axis=1).T
            flat["alpha"][span] += c.hits.alpha.reshape(c.batch, n).sum(axis=0)

            def add_rows(key, value):  # (3, hits) values of the hit rows, summed into their pixels
                dense = np.zeros((len(c.pixels), 3), np.float32)
                dense[c.hits.rows] = value.T
                flat[key][span] += dense.reshape(c.batch, n, 3).sum(axis=0)

            for key, value in (("direct", c.direct), ("indirect", c.indirect)):
                if value is not None:
                    add_rows(key, value)
            if "albedo" in flat and len(c.hits.rows):
                add_rows("albedo", denoising_albedo(c.hits.surf))
                add_rows("dnormal", world_to_cam @ c.hits.surf.ns)

        map_tasks(add, chunks, stop)

    def combined(self) -> np.ndarray:
        """The running mean of Combined (h, w, 4) float32: emission + direct + indirect, and alpha."""
        inv = 1.0 / max(1, self.samples)
        h, w = self.acc["alpha"].shape
        out = np.empty((h, w, 4), np.float32)
        np.add(self.acc["emit"], self.acc["direct"], out=out[..., :3], casting="unsafe")
        out[..., :3] += self.acc["indirect"]
        out[..., :3] *= np.float32(inv)
        np.multiply(self.acc["alpha"], inv, out=out[..., 3], casting="unsafe")
        return finite(out)

    def mean(self, key: str) -> np.ndarray:
        """The running mean of accumulator ``key`` as (h, w, c) float32 (c = 1 for scalar ones), finite."""
        a = self.acc[key]
        out = np.multiply(a, np.float32(1.0 / max(1, self.samples)), out=np.empty(a.shape, np.float32),
                          casting="unsafe")
        return finite(out if out.ndim == 3 else out[..., None])

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
        if "albedo" in self.acc:
            jobs["Denoising Albedo"] = lambda: mean("albedo")
            jobs["Denoising Normal"] = lambda: mean("dnormal")
        run = map if in_worker() else pool().map  # one pass per pool task (inline inside a worker)
        return dict(zip(jobs, run(lambda job: job(), jobs.values())))
