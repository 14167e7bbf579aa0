"""A frame too large for one pass over its window, rendered in horizontal bands so that memory stays bounded.

Each band is rendered as a frame of its own over a border window of the camera (the same camera, so the projection,
pixel filter, spatial radius and temporal reprojection are the full frame's), with ``margin`` rows more on each
side where the ReSTIR stages read neighbours (the spatial radius): a pixel near a band's edge then reuses from as
many neighbours as inside it, and the margin rows are cropped. Bands draw from random streams of their own (the
seed mixed with the band's index), so their noise is independent; a band's temporal history is kept for the same
band of the next frame. The working memory is then one band's; the film's passes and the histories still cover
the whole frame (memory.banded_estimate).
"""
from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

from . import memory, methods


@dataclass(frozen=True)
class BandHistory:
    """The temporal histories of a banded frame, one per band of ``layout`` ((a, b) window rows each)."""

    layout: tuple
    histories: tuple


def band_seed(seed: int, band: int) -> int:
    """The seed of band ``band``: the frame's own for the first, mixed with the index for the others."""
    return int(seed) if band == 0 else (int(seed) * 1000003 + 7919 * band) & 0x7FFFFFFF


def margin_rows(settings, camera) -> int:
    """Rows a band is extended by on each side: the largest spatial radius the ReSTIR stages reuse over (0 for the
    path tracer)."""
    if settings.integrator != "RESTIR":
        return 0
    radius = methods.spatial_settings(settings, camera).radius
    if methods.gi_possible(settings):
        radius = max(radius, methods.gi_settings(settings, camera)[0].radius)
    return int(math.ceil(radius)) + 1


def layout(h: int, bands: int) -> tuple:
    """(a, b) window rows of ``bands`` bands of about equal height over ``h`` rows."""
    edges = np.linspace(0, h, bands + 1).round().astype(int)
    return tuple((int(a), int(b)) for a, b in zip(edges[:-1], edges[1:]) if b > a)


def render_in_bands(render_one, scene, settings, bands: int, progress=None, should_stop=None, history=None,
                    clock=None, margin: int | None = None):
    """:func:`frame_render.render_frame`'s result for ``scene`` rendered in ``bands`` bands of ``margin`` extra rows each
    side (None: :func:`margin_rows`), each by ``render_one(scene, settings, progress, should_stop, history, clock,
    pixels)`` (one band's render_frame; ``pixels``: the largest band's, margins included, which worker processes size
    their buffers for once, so that no band's history is dropped for a larger one)."""
    from .frame import Cancelled, FrameResult
    cam = scene.camera
    x0, y0, w, h = cam.window
    rows = layout(h, bands)
    m = margin_rows(settings, cam) if margin is None else int(margin)
    hist = history.histories if isinstance(history, BandHistory) and history.layout == rows else (None,) * len(rows)
    t0 = time.perf_counter()
    passes: dict = {}
    histories, stats, samples, cancelled = [], {}, None, False
    limit = settings.time_limit / len(rows) if settings.time_limit > 0 else 0.0
    largest = w * max(min(h, b + m) - max(0, a - m) for a, b in rows)
    try:
        for i, (a, b) in enumerate(rows):
            lo, hi = max(0, a - m), min(h, b + m)
            scene.camera = dataclasses.replace(cam, window=(x0, y0 + lo, w, hi - lo))
            band_settings = dataclasses.replace(settings, seed=band_seed(settings.seed, i), time_limit=limit)
            report = None
            if progress:
                def report(f, msg, i=i):
                    progress((i + f) / len(rows), f"Band {i + 1}/{len(rows)} | {msg}")
            try:
                result = render_one(scene, band_settings, report, should_stop, hist[i], clock, largest)
            except Cancelled:
                if i == 0:
                    raise
                cancelled = True
                break
            for name, image in result.passes.items():
                if name not in passes:
                    passes[name] = np.zeros((h, w) + image.shape[2:], image.dtype)
                passes[name][a:b] = image[a - lo:a - lo + (b - a)]
            histories.append(result.history)
            samples = result.samples_done if samples is None else min(samples, result.samples_done)
            if i == 0:
                stats = dict(result.stats)
            if result.cancelled:
                cancelled = True
                break
    finally:
        scene.camera = cam
    stats["bands"] = len(rows)
    stats["band_margin"] = m
    keep = None if cancelled or not histories or any(hh is None for hh in histories) else \
        BandHistory(rows, tuple(histories))
    return FrameResult(passes, samples or 0, time.perf_counter() - t0, cancelled, stats, keep)


def plan(scene, settings, free: int | None, keeps_history: bool = True) -> tuple[int, int]:
    """(bands, margin rows) of a frame of ``scene``: one band while one band's working set (memory.band_budget)
    holds the whole window; else bands whose rows with both margins fit it, each at least MIN_BAND_ROWS tall, the
    margin (the spatial radius) cut to a quarter of what fits where the radius is large against the band (a pixel
    at a band's edge then reuses from fewer neighbours, as at the image's edge: still unbiased). A frame that
    ``keeps_history`` holds its first pass's G-buffer and reservoirs in each band's working set."""
    _x0, _y0, w, h = scene.camera.window
    budget = memory.band_budget(free)
    _low, high = memory.per_pixel_range(settings, keeps_history, memory.target_extension_rows(scene))
    m = margin_rows(settings, scene.camera)
    if high * w * h <= budget:
        return 1, m
    fit = max(memory.MIN_BAND_ROWS, int(budget // max(high * w, 1)))  # rows of one band, margins included
    m = min(m, fit // 4)
    rows = max(memory.MIN_BAND_ROWS // 2, fit - 2 * m)
    return max(1, min(-(-h // rows), max(1, h // (memory.MIN_BAND_ROWS // 2)))), m


def bands_needed(scene, settings, free: int | None) -> int:
    """Bands a frame of ``scene`` is split into (:func:`plan`)."""
    return plan(scene, settings, free)[0]
