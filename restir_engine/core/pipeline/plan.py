"""The plan of one sample pass: which stages run and why, decided once before the pass starts.

Stages of a pass, in order (each timed by the frame's profile.StageClock under its name):
  probe       Auto indirect with nothing measured: a few camera paths measure what GI would carry (indirect_choice)
  primary     camera rays, emission seen directly with pixel coverage, glass chains          (primary.py, per chunk)
  initial     RIS: light tiles (whole image), target terms and initial resampling             (direct.py, per chunk)
  paths       the first vertex's BSDF ray and bounces 1..max_bounces; GI's initial reservoirs (paths.py, per chunk)
  gbuffer     the frame's G-buffer and reservoirs assembled from the chunks                     (primary.py)
  temporal    DI: merge with the previous frame's reservoirs            (reuse.py, whole image: reads other pixels)
  boiling     DI, biased mode with the boiling filter                    (reuse.py, whole image: 16x16 blocks)
  spatial     DI spatial reuse passes                                    (reuse.py, whole image: reads neighbours)
  gi_temporal GI: merge with the previous frame's GI reservoirs          (reuse.py, whole image)
  gi_spatial  GI spatial reuse passes                                    (reuse.py, whole image)
  shade       direct light from the reservoirs or NEE; GI's shading       (shade.py, per chunk)
  passes      accumulation into the film                                   (film.py, per chunk)
"""
from __future__ import annotations

from dataclasses import dataclass

from ..restir import di
from ..sampling import rng


@dataclass(frozen=True)
class PassPlan:
    """seed and frame key the random streams with ``sample`` (the pass's first sample in the frame) and ``batch``
    (samples it renders at once: 1 wherever a pass keeps per-pixel state).

    resampled:   the direct light comes from reservoirs (RIS or ReSTIR), with ``candidates`` (light candidates
                 capped for viewport navigation) and light tiles where ``light_tiles``
    reusing:     the DI reservoirs are reused (ReSTIR); ``temporal``: with the previous frame's (first pass, history)
    gi:          GI's initial reservoirs are made (ReSTIR GI runs, or Auto is measuring at GI's cost);
                 ``gi_temporal``: merged with the previous frame's GI reservoirs where GI is reused
    probe:       Auto indirect while path-tracing measures in one chunk in PROBE_EVERY (a periodic probe)
    glass_chains: camera rays continue through smooth glass to the surface behind, where resampling runs
    world_resampled: the world's points are in the DI reservoirs (else the world is light-sampled at shading)
    continuing:  the path continuation has something to add (bounces, or the BSDF ray's emission)
    strata:      camera rays per pixel for the emission seen directly (coverage.coverage)
    partial:     the pass samples only the pixels adaptive sampling left active (the others keep their film)
    """

    seed: int
    frame: int
    sample: int
    batch: int
    resampled: bool
    reusing: bool
    temporal: bool
    gi: bool
    gi_temporal: bool
    probe: bool
    glass_chains: bool
    world_resampled: bool
    continuing: bool
    strata: int
    candidates: di.CandidateSettings | None = None
    light_tiles: bool = False
    window_step: int = 0  # pixels per chunk of a pass over the whole window (per-pixel streams: primary.py)
    partial: bool = False  # adaptive sampling: the pass samples only the pixels still active

    def rng(self, stream: int, chunk: int = 0, sample: int | None = None):
        """The random stream ``stream`` of chunk ``chunk`` in this pass (``sample`` overrides the pass index)."""
        return rng(self.seed, self.frame, self.sample if sample is None else sample, stream, chunk)
