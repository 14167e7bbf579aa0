"""A frame's peak memory, estimated before any work from its resolution, settings and scene, and the memory free
to hold it.

Bytes per pixel (of the camera window) of a frame's peak, including the history it keeps for the next frame, by
what runs; upper bounds of what scripts/benchmarks/memory.py measures (tracemalloc peaks of the core, two frames
with history). Where a setting is Auto, the frame's own choice decides: the estimate is then a range (the cheapest
and the dearest method Auto may pick). The scene adds its arrays, its textures and Embree's BVH.
"""
from __future__ import annotations

import os
from dataclasses import dataclass

from ..integrators.trace_context import may_be_anisotropic
from ..materials.textures import texture_bytes
from ..modes import DirectMethod, IndirectMethod, Integrator
from ..restir import target
from . import methods

BASE = 370  # camera paths, film (float32 sums), passes: the path tracer, or light sampling with path-traced indirect
DENOISE_DATA = 72  # the denoising data (albedo and normal accumulators and their passes)
DIRECT_REUSE = 720  # DI reservoirs, their target terms and G-buffer, this frame's and the history's
GI = 800          # GI reservoirs, their target terms and G-buffer, this frame's and the history's
FIXED = 64 << 20  # bytes that do not grow with the image (tables, pools, the pool's threads)
BVH_PER_TRIANGLE = 160  # Embree's BVH (outside NumPy)
WORKER_FIXED = 128 << 20  # a worker process's own: its interpreter, NumPy, Embree and the core's tables
WORKER_PER_PIXEL = 48     # a worker's private whole-image arrays (G-buffer slots, its copy of the history's M, W)
FRAME_WIDE = 260  # of BASE, what a banded frame keeps for its whole window: the film's sums and the passes
HISTORY = 240     # a ReSTIR band's temporal history (G-buffer, DI reservoirs), kept for the whole window
GI_HISTORY = 260  # ... and the GI reservoirs' and terms'
DENOISER = 112    # the denoiser's images after the frame: its cleaned inputs, guides, prefiltered guides, output
DENOISED_PASSES = 128  # the frame's passes while it is denoised (float32: Combined, guides, Noisy Image, a few more)
DENOISER_SCRATCH = 1024 << 20  # OIDN's scratch memory, capped by the caller (restir_engine/denoise.py)
BAND_BYTES = 2048 << 20  # one band's working set at most (pipeline/bands.py)
MIN_BAND_ROWS = 32


@dataclass(frozen=True)
class MemoryEstimate:
    """Peak bytes of a frame: ``low`` where Auto picks the cheapest methods, ``high`` the dearest (equal without
    Auto); ``pixels`` of the window and ``scene`` bytes (arrays, textures, BVH) included in both."""

    low: int
    high: int
    pixels: int
    scene: int
    render: int = 0   # where the frame is denoised afterwards: the render's own peak (its high), else 0


def frame_estimate(scene, settings, keeps_history: bool = True) -> MemoryEstimate:
    """The peak memory of rendering ``scene`` (core Scene) with ``settings`` (RenderSettings), keeping the frame's
    temporal history for the next where ``keeps_history``."""
    _x0, _y0, w, h = scene.camera.window
    pixels = int(w) * int(h)
    low, high = per_pixel_range(settings, keeps_history, target_extension_rows(scene))
    groups = getattr(scene, "light_groups", None)
    if groups is not None:  # per light group: a float32 RGB film sum and float32 RGB estimates of the pass's stages
        low, high = low + len(groups) * 24, high + len(groups) * 48
    catchers = getattr(getattr(scene.geometry, "objects", None), "shadow_catcher", None)
    if getattr(settings, "shadow_catcher_pass", False) or (catchers is not None and catchers.any()):
        low, high = low + 40, high + 76  # shadow catchers: 10 float32 film sums, 3 float32 RGB estimates
    scene_bytes = scene_size(scene)
    return MemoryEstimate(FIXED + scene_bytes + low * pixels, FIXED + scene_bytes + high * pixels, pixels,
                          scene_bytes)


def target_extension_rows(scene) -> int:
    """The float32 rows per surface that anisotropic or sheen lobes add to every block of target terms
    (restir/target.py's extension), 0 where the scene has neither."""
    mats = scene.materials
    sheen = getattr(mats, "sheen_roughness", None)
    return target.width(may_be_anisotropic(mats), sheen is not None and bool((sheen > 0).any())) - target.WIDTH


def per_pixel_range(st, keeps_history: bool = True, extension_rows: int = 0) -> tuple[int, int]:
    """(low, high) bytes per pixel for settings ``st``; a frame that keeps no history (a still) holds no second
    G-buffer and reservoirs while it renders. ``extension_rows``: float32 rows the target terms' blocks (DI's and
    GI's, this frame's and the history's) carry beyond target.WIDTH (:func:`target_extension_rows`)."""
    terms = extension_rows * 4 * (2 if keeps_history else 1)
    low = high = BASE + (DENOISE_DATA if st.denoise_data else 0)
    if st.integrator != Integrator.RESTIR:
        return low, high
    direct = st.direct_method
    di = DIRECT_REUSE - (0 if keeps_history else HISTORY) + terms
    if direct in (DirectMethod.RESTIR, DirectMethod.RIS) or st.reservoir_passes:
        low += di
        high += di
    elif direct == DirectMethod.AUTO:
        high += di
    if methods.gi_possible(st):
        gi = GI - (0 if keeps_history else GI_HISTORY) + terms
        if st.indirect_method == IndirectMethod.RESTIR_GI or st.gi_reservoir_passes:
            low += gi
            high += gi
        elif methods.gi_auto(st):  # the probe's own cost is part of GI's; choosing path tracing costs nothing more
            high += gi
    return low, high


def band_budget(free: int | None) -> int:
    """Bytes one band's working set may take: BAND_BYTES, or half the free memory where that is less."""
    return BAND_BYTES if free is None else max(64 << 20, min(BAND_BYTES, free // 2))


def banded_estimate(scene, settings, bands: int, margin: int, keeps_history: bool) -> MemoryEstimate:
    """The peak of ``scene`` rendered in ``bands`` bands of ``margin`` extra rows each side: the whole window's film
    and passes (FRAME_WIDE) and histories (where ``keeps_history``), and one band's working set."""
    if bands <= 1:
        return frame_estimate(scene, settings, keeps_history)
    _x0, _y0, w, h = scene.camera.window
    pixels = int(w) * int(h)
    band_pixels = int(w) * min(int(h), -(-int(h) // bands) + 2 * margin)
    low, high = per_pixel_range(settings, keeps_history, target_extension_rows(scene))
    hist = history_per_pixel(settings, keeps_history)
    scene_bytes = scene_size(scene)
    whole = FIXED + scene_bytes + (FRAME_WIDE + hist) * pixels
    return MemoryEstimate(whole + low * band_pixels, whole + high * band_pixels, pixels, scene_bytes)


def history_per_pixel(settings, keeps_history: bool) -> int:
    """Bytes per pixel of the temporal history a frame hands to the next (0 where it keeps none)."""
    if not keeps_history or settings.integrator != Integrator.RESTIR:
        return 0
    return HISTORY + (GI_HISTORY if methods.gi_possible(settings) else 0)


def with_denoising(estimate: MemoryEstimate, settings, keeps_history: bool) -> MemoryEstimate:
    """``estimate`` of a frame denoised afterwards: the peak is the larger of the render's and the denoiser's (the
    frame's passes, as the film's sums are gone by then, the history it keeps, the denoiser's images and OIDN's
    scratch)."""
    per_pixel = DENOISED_PASSES + DENOISER + history_per_pixel(settings, keeps_history)
    peak = FIXED + estimate.scene + per_pixel * estimate.pixels + DENOISER_SCRATCH
    return MemoryEstimate(max(estimate.low, peak), max(estimate.high, peak), estimate.pixels, estimate.scene,
                          render=estimate.high)


def scene_size(scene) -> int:
    """Bytes of the scene's arrays and textures and of its BVH."""
    g = scene.geometry
    arrays = sum(a.nbytes for a in (g.verts, g.normals, g.material, g.uvs, getattr(g, "instance", None),
                                    getattr(g, "tangents", None)) if a is not None)
    textures = sum(texture_bytes(t) for t in scene.materials.textures)
    world = scene.world_image.nbytes if scene.world_image is not None else 0
    return int(arrays + textures + world + BVH_PER_TRIANGLE * len(g.verts))


def available_memory() -> int | None:
    """Bytes the system can give this process now without swapping (Linux: MemAvailable; elsewhere the physical
    memory), or None where it cannot be read."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return int(os.sysconf("SC_PHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (AttributeError, ValueError, OSError):
        return None


def processes_that_fit(n: int, estimate: MemoryEstimate, triangles: int, free: int | None) -> int:
    """The most worker processes, at most ``n``, that fit in ``free`` bytes with the frame (``estimate``: its
    pixel buffers are shared by the workers, in shared memory): each worker adds its own WORKER_FIXED, its BVH and
    WORKER_PER_PIXEL per pixel. At least 1 (the frame alone is judged by :func:`memory_problem`)."""
    if free is None or n <= 1:
        return max(1, n)
    each = WORKER_FIXED + BVH_PER_TRIANGLE * int(triangles) + WORKER_PER_PIXEL * estimate.pixels
    return max(1, min(n, int((free - estimate.high) // each)))


def size_text(n: int) -> str:
    """Bytes as a user reads them: MB below a gigabyte, else GB with one decimal."""
    return f"{n / 2 ** 20:.0f} MB" if n < 2 ** 30 else f"{n / 2 ** 30:.1f} GB"


def memory_problem(estimate: MemoryEstimate, free: int | None, settings=None) -> tuple[str, str]:
    """(refusal, warning): why the frame cannot be rendered in ``free`` bytes ('' when it can), and a warning where
    only the dearest choice of Auto would not fit ('' when all fit or nothing is known). The refusal suggests the
    path tracer where it needs less than the frame's settings (``settings``: their denoising data counts)."""
    if free is None:
        return "", ""
    per_pixel = (estimate.low - FIXED - estimate.scene) // max(estimate.pixels, 1)
    if estimate.low > free:
        path_tracer = BASE + (DENOISE_DATA if settings is not None and settings.denoise_data else 0)
        cheaper = per_pixel > path_tracer
        advice = "lower the resolution (Output > Format) or render a border region"
        if estimate.render and estimate.render <= free:
            advice += (f", or turn Denoise off (Render Properties > Sampling; the frame alone needs about "
                       f"{size_text(estimate.render)})")
        elif cheaper:
            advice += f", or use the Path Tracing integrator (about {BASE} bytes per pixel)"
        return (f"This frame needs about {size_text(estimate.low)} of memory ({estimate.pixels} pixels at "
                f"{per_pixel} bytes each, scene {size_text(estimate.scene)}) but {size_text(free)} is free: "
                f"{advice}"), ""
    if estimate.high > free:
        return "", (f"This frame may need up to {size_text(estimate.high)} of memory if Auto picks ReSTIR, and "
                    f"{size_text(free)} is free; set the Direct and Indirect Methods to avoid running out")
    return "", ""
