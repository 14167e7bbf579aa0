"""Render a cached .blend through Blender (bpy) with a chosen engine and read the result back."""
from __future__ import annotations

import os
import tempfile
import time

import bpy
import numpy as np

from restir_engine.compat import set_output_format


def configure_cycles(scene, samples: int, bounces: int, seed: int = 0):
    """Cycles as ground truth: CPU, no clamping, light threshold 0, box filter of one pixel (the same
    pixel filter as ours), no denoising, no adaptive sampling, no glossy blur, true sphere lights."""
    try:
        scene.render.engine = "CYCLES"
    except TypeError:  # Cycles' add-on unregistered (seen once on bpy 5.2.3 in a long test session): enable it
        import addon_utils
        addon_utils.enable("cycles", default_set=True)
        scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = samples
    c.seed = seed
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.light_sampling_threshold = 0.0
    c.blur_glossy = 0.0
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = bounces
    c.transmission_bounces = c.volume_bounces = c.transparent_max_bounces = bounces
    c.min_light_bounces = 0
    c.caustics_reflective = c.caustics_refractive = True
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    for lamp in bpy.data.lights:  # a true sphere light (our model); soft falloff is measured in docs
        if hasattr(lamp, "use_soft_falloff"):
            lamp.use_soft_falloff = False


def configure_restir(scene, samples: int, bounces: int, seed: int = 0, **settings):
    scene.render.engine = "RESTIR"
    scene.restir.samples = samples
    scene.restir.max_bounces = bounces
    scene.restir.seed = seed
    scene.restir.pixel_filter = "BOX"  # the filter configure_cycles gives Cycles (a setting may change it)
    scene.restir.use_adaptive_sampling = False  # every pixel takes the samples asked for, as configure_cycles
    scene.restir.use_denoising = False  # the raw estimate, as configure_cycles
    threads = int(os.environ.get("RESTIR_TEST_THREADS", "0"))
    if threads > 0:  # the cores this suite may use (scripts/test.sh runs two suites at once)
        scene.render.threads_mode = "FIXED"
        scene.render.threads = threads
    for k, v in settings.items():
        setattr(scene.restir, k, v)
    scene.view_settings.view_transform = "Standard"


def read_exr(path: str) -> dict:
    """{pass name: (h, w, c) float32, row 0 at the bottom} from a multilayer EXR."""
    import OpenEXR
    out: dict = {}
    for part in OpenEXR.File(path).parts:
        for name, ch in part.channels.items():
            px = np.asarray(ch.pixels, np.float32)
            if px.ndim == 2:
                px = px[..., None]
            key = name.split(".")[1] if "." in name else name
            out.setdefault(key, []).append((name, px[::-1].copy()))  # EXR rows are top-down
    return {k: np.concatenate([p for _n, p in sorted(v)], axis=2) if len(v) > 1 else v[0][1] for k, v in out.items()}


def use_multilayer_exr(scene) -> None:
    """Write renders of ``scene`` as 32-bit multilayer EXR (every pass; Blender 4.x and 5.x settings)."""
    settings = scene.render.image_settings
    set_output_format(settings, "OPEN_EXR_MULTILAYER")
    settings.color_depth = "32"


def render_scene(scene) -> tuple[dict, float]:
    """Render the current frame of ``scene``: (passes, wall seconds of the whole render incl. export)."""
    use_multilayer_exr(scene)
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "render.exr")
        scene.render.filepath = path
        t0 = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        wall = time.perf_counter() - t0
        return read_exr(path), wall


def render_blend_passes(path: str, engine: str, samples: int, bounces: int, seed: int = 0, frame: int | None = None,
                        settings: dict | None = None, emission: bool = False):
    """Open ``path`` and render one frame. Returns (passes {name: (h, w, c)}, wall s, core s or None); with
    ``emission`` the passes include "Emission" (RGB), emitters seen directly (Cycles: its Emit pass)."""
    bpy.ops.wm.open_mainfile(filepath=path)
    scene = bpy.context.scene
    if frame is not None:
        scene.frame_set(frame)
    if engine == "CYCLES":
        configure_cycles(scene, samples, bounces, seed)
    else:
        configure_restir(scene, samples, bounces, seed, **(settings or {}))
    if emission:
        vl = scene.view_layers[0]
        if engine == "CYCLES":
            vl.use_pass_emit = True
        else:
            vl.restir.use_pass_emission = True
    passes, wall = render_scene(scene)
    if emission and "Emit" in passes:
        passes["Emission"] = passes.pop("Emit")
    core = None
    if engine != "CYCLES":
        from restir_engine.engine import LAST_FRAME_STATS
        core = LAST_FRAME_STATS.get("core_seconds")
    return passes, wall, core


def render_blend(path: str, engine: str, samples: int, bounces: int, seed: int = 0, frame: int | None = None,
                 settings: dict | None = None):
    """Open ``path`` and render one frame. Returns (Combined RGB (h, w, 3), wall s, core s or None)."""
    passes, wall, core = render_blend_passes(path, engine, samples, bounces, seed, frame, settings)
    return passes["Combined"][..., :3], wall, core
