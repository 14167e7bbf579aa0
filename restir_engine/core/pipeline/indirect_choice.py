"""Auto indirect: ReSTIR GI or path tracing, chosen from what the GI reservoirs would carry.

A pass follows what the passes before it measured (this frame's, or the previous frame's of the same scene content,
kept on the shared trace context and used only by frame f + 1, so rendering a frame again gives the same image),
never its own samples, so the choice does not bias the pass. Measurements are luminance sums over surfaces
(:func:`share_sums`), decayed by MEASURE_DECAY per pass. A frame with nothing measured first probes a few pixels
(:meth:`IndirectChoice.probe`); while path-tracing, a quarter of the chunks of the first pass of every PROBE_FRAMES-th
frame measure again.
"""
from __future__ import annotations

import numpy as np

from ..integrators import camera_paths, pathtracer
from ..integrators.method_choice import choose_indirect_method
from ..materials.params import luminance_rows
from ..modes import IndirectMethod, Integrator
from ..restir.target import width
from ..sampling import STREAM_PROBE, rng

MEASURE_DECAY = 0.8  # weight of the earlier passes' measurements per pass (a memory of about five passes)
PROBE_EVERY = 4  # while path tracing: one chunk in this many measures (in a frame's first pass)
PROBE_FRAMES = 8  # ... in every this many frames (or views) of the same scene content
PROBE_PIXELS = 32  # a frame without a measurement first probes one pixel in this many,
PROBE_BOUNCES = 2  # with paths of at most this many bounces (the split is decided at the first two vertices)
PROBE_MAX = 2048  # ... and at most this many paths


def share_sums(indirect: np.ndarray, rest: np.ndarray) -> np.ndarray:
    """(4,) over surfaces: luminance sums of the path-traced indirect light (3, n) and of the part the GI reservoirs
    carry (indirect - rest); sums of squares of the indirect light and of ``rest``, the part they do not carry."""
    lum_all = luminance_rows(indirect).astype(np.float64)  # squares of bright light overflow float32
    lum_rest = luminance_rows(rest).astype(np.float64)
    total = float(lum_all.sum())
    return np.array([total, total - float(lum_rest.sum()), float(np.dot(lum_all, lum_all)),
                     float(np.dot(lum_rest, lum_rest))])


def ratios(sums: np.ndarray) -> tuple[float, float]:
    """(the share of the indirect light the reservoirs carry, the uncached part's share of its second moment)."""
    share = float(sums[1] / sums[0]) if sums[0] > 0 else 0.0
    uncached = float(sums[3] / sums[2]) if sums[2] > 0 else 1.0
    return share, uncached


class IndirectChoice:
    """The indirect method of a frame's passes ("OFF", "PATH" or "RESTIR_GI") and why; with ``auto`` the
    measurement state (decayed sums or None, frames since the last probe) behind it."""

    def __init__(self, st, n_bounces: int, auto: bool, ctx):
        self.ctx, self.frame, self.auto = ctx, st.frame, auto
        self.measure = (None, PROBE_FRAMES)
        self.method = IndirectMethod.PATH if n_bounces > 0 else IndirectMethod.OFF
        self.reason = "path tracer" if st.integrator == Integrator.PATH else "no bounces" if n_bounces == 0 else \
            "set by the user"
        if st.integrator == Integrator.RESTIR and n_bounces > 0 and st.indirect_method != IndirectMethod.PATH:
            self.method = IndirectMethod.RESTIR_GI
            if auto:
                self.reason = "not measured yet: the first pass measures"
                rec = ctx.measured.get("auto_indirect")
                if rec is not None and rec["frame"] == st.frame - 1:
                    self.method, self.reason = rec["choice"]
                    self.measure = (rec["sums"], rec["since"])
            elif st.indirect_method == IndirectMethod.AUTO:
                self.reason = "a GI reservoir pass is enabled"

    @property
    def measured(self) -> bool:
        return self.measure[0] is not None

    def probe_due(self) -> bool:
        """Path-tracing: this frame's first pass measures in some chunks (every PROBE_FRAMES-th frame)."""
        return self.measure[1] >= PROBE_FRAMES

    def start_first_pass(self) -> bool:
        """A frame's first pass while path-tracing: whether it measures (a periodic probe); counts the frame."""
        sums, since = self.measure
        probe = self.probe_due()
        self.measure = (sums, 1 if probe else since + 1)
        self.remember()
        return probe

    def probe(self, ctx, seed: int, may_hit, gi_initial) -> np.ndarray:
        """Nothing measured yet (a still, a first frame): camera paths of up to PROBE_BOUNCES bounces through one
        pixel in PROBE_PIXELS, at most PROBE_MAX of them, on their own random stream (the frame's passes are
        independent of it: the image stays unbiased and deterministic), measure what the GI reservoirs would carry.
        ``gi_initial(surf, first, block)`` makes GI's initial samples (paths.gi_initial). Returns the measured
        sums for :meth:`update`."""
        x0, y0, w, h = ctx.scene.camera.window
        r = rng(seed, self.frame, 0, STREAM_PROBE)
        pix = r.integers(0, w * h, max(1, min((w * h) // PROBE_PIXELS, PROBE_MAX)))
        jit = r.random((2, len(pix)), dtype=np.float32)
        hits = camera_paths.primary(ctx, (x0 + pix % w).astype(np.float32) + jit[0],
                                  (y0 + pix // w).astype(np.float32) + jit[1], None if may_hit is None else may_hit[pix])
        surf = hits.surf
        sums = np.zeros(4)
        if len(surf):
            out = pathtracer.continue_paths(ctx, surf, r, first_bounce=True,
                                            budget=np.full(len(surf), min(PROBE_BOUNCES, ctx.max_bounces)))
            block = np.empty((width(ctx.anisotropic, ctx.sheen), len(surf)), np.float32)
            _glossy, _res, rest, _rest_g = gi_initial(surf, out.first, block)
            sums = share_sums(out.indirect, rest)
        self.measure = (None, 1)  # measured now: no periodic probe in this frame's first pass
        return sums

    def update(self, sums: np.ndarray) -> dict:
        """Add a pass's measured sums and choose again for the next passes. Returns the decayed measurement's
        {"gi_share_measured", "gi_uncached_measured"} (diagnostics)."""
        acc, since = self.measure
        acc = sums if acc is None else acc * MEASURE_DECAY + sums
        self.measure = (acc, since)
        share, uncached = ratios(acc)
        self.method, self.reason = choose_indirect_method(share, uncached)
        self.remember()
        return {"gi_share_measured": share, "gi_uncached_measured": uncached}

    def remember(self) -> None:
        """Keep the measurement on the context for the next frame (or view) of the same content."""
        self.ctx.measured["auto_indirect"] = {"frame": self.frame, "choice": (self.method, self.reason),
                                              "sums": self.measure[0], "since": self.measure[1]}
