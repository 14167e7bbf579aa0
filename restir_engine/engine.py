"""The RenderEngine: thin glue between Blender and the core renderer."""
from __future__ import annotations

import time
from dataclasses import replace

import bpy
import numpy as np

from . import denoise
from . import passes as pass_table
from .core.pipeline import memory, methods
from .core.pipeline.bands import plan as band_plan
from .core.renderer import Cancelled, RenderSettings, render_frame
from .export import ExportError, export_scene, motion_blur, neighbour_frames
from .properties import scene_settings_to_core

MAX_REPORTED_WARNINGS = 12

# Figures of the last finished frame (seconds of export and of the core render, samples done), for
# benchmarks and the evaluation harness; a diagnostic, not state that rendering depends on.
LAST_FRAME_STATS: dict = {}

# ReSTIR temporal history across the frames of an animation. Engine instances are recreated per frame,
# so it lives here, keyed by (scene, view layer): (frame number, restir.history.TemporalHistory). It is used
# only by the next frame (a jump drops it) and only if resolution and light table still match.
_TEMPORAL_HISTORY: dict = {}

# What the automatic choices picked in the last render of each scene (by name), for the Sampling panel:
# {"direct_method", "direct_reason", "coverage_samples", "coverage_reason"}.
LAST_CHOICES: dict = {}


def settings_from_scene(scene) -> RenderSettings:
    """The core's settings from ``scene.restir`` (properties.SCENE_FIELDS), the frame and the film's transparency."""
    return RenderSettings(frame=int(scene.frame_current), film_transparent=bool(scene.render.film_transparent),
                          **scene_settings_to_core(scene.restir))


def with_data_passes(settings: RenderSettings, view_layer, denoise_guides: bool = False) -> RenderSettings:
    """``settings`` computing Depth/Normal/Vector only when the view layer writes one of them, and the Denoising
    Albedo / Normal when it writes them or the denoiser reads them (``denoise_guides``)."""
    wanted = bool(view_layer.use_pass_z or view_layer.use_pass_normal or view_layer.use_pass_vector)
    reservoirs = bool(view_layer.restir.use_pass_reservoir_m or view_layer.restir.use_pass_reservoir_ucw)
    gi_reservoirs = bool(view_layer.restir.use_pass_gi_reservoir_m or view_layer.restir.use_pass_gi_reservoir_ucw)
    return replace(settings, data_passes=wanted, reservoir_passes=reservoirs, gi_reservoir_passes=gi_reservoirs,
                   denoise_data=bool(view_layer.restir.use_pass_denoising_data) or denoise_guides,
                   shadow_catcher_pass=bool(view_layer.restir.use_pass_shadow_catcher))


def _set_rect(render_pass, pixels: np.ndarray) -> None:
    """Copy (w·h, channels) float32 pixels into a render pass through the buffer protocol (``foreach_set``):
    assigning ``rect`` converts element by element (measured 36-44 ms for a 320x180 Combined pass, 0.07 ms this
    way)."""
    try:
        render_pass.rect.foreach_set(pixels.ravel())
    except (AttributeError, TypeError):  # a bpy without foreach_set on the pass array
        render_pass.rect = pixels


def scene_problems(core_scene, light_count: int) -> list[str]:
    """Messages for scenes that render but not as the user probably expects."""
    problems = []
    if len(core_scene.geometry) == 0 and len(core_scene.lamps.tris) == 0:
        problems.append("The scene has nothing to render (no visible geometry)")
    if light_count == 0 and not np.any(core_scene.world_radiance > 0) and getattr(core_scene, "world_image", None) is None:
        problems.append("The scene has no lights, no emissive materials and a black world: the image is black")
    return problems


def _black_passes(scene, view_layer, window) -> dict:
    """Every enabled pass of a frame that sees nothing: zero, and the Depth of nothing hit (1e10, as Cycles)."""
    _x0, _y0, w, h = window
    images = {}
    for _name, chans, _ctype, _enabled, core_name in pass_table.enabled_passes(scene, view_layer):
        images[core_name] = np.full((h, w, len(chans)), 1e10 if core_name == "Depth" else 0.0, np.float32)
    return images


def apply_threads(scene) -> None:
    """Blender's Render Properties > Performance > Threads (``render.threads_mode``, ``render.threads``): Auto uses
    every logical core, Fixed that many; and our Processes (``scene.restir.processes``): the worker processes F12
    and animation frames render in (0 = Auto: one per core from 2 cores up, at most one per chunk of pixels), each
    with its share of the threads. The Rendered viewport chooses its processes the same way for the view's size
    (viewport.py), on a team of its own."""
    from .core.parallel.pool import set_thread_count
    from .core.parallel.processes import set_process_count
    render = scene.render
    set_thread_count(int(render.threads) if render.threads_mode == "FIXED" else None)
    set_process_count(int(getattr(getattr(scene, "restir", None), "processes", 0)))


def _viewport_pass(context) -> str:
    """The pass the 3D view shows (View3DShading.restir.render_pass)."""
    shading = getattr(getattr(context, "space_data", None), "shading", None)
    settings = getattr(shading, "restir", None)
    return settings.render_pass if settings is not None else "COMBINED"


class RestirRenderEngine(bpy.types.RenderEngine):
    bl_idname = "RESTIR"
    bl_label = "ReSTIR"
    bl_use_preview = False
    bl_use_eevee_viewport = True
    bl_use_shading_nodes_custom = False

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._viewport = None
        self._exporter = None
        self._viewport_settings_last = None
        self._texture = None

    def __del__(self):
        try:
            if getattr(self, "_viewport", None) is not None:
                self._viewport.halt()
        except ReferenceError:  # the RNA struct may already be gone
            pass

    # Blender calls this on throwaway instances too: no instance state.
    def update_render_passes(self, scene=None, renderlayer=None):
        pass_table.register_passes(self, scene, renderlayer)

    def render(self, depsgraph):
        """Render one frame; an unexpected error is reported in the UI (and printed) instead of being
        raised into Blender, which can crash after a failed render callback."""
        try:
            self._render(depsgraph)
        except Exception as exc:  # noqa: BLE001 - the last line of defence for the user's session
            import traceback
            traceback.print_exc()
            message = f"ReSTIR render failed: {type(exc).__name__}: {exc}"
            self.report({"ERROR"}, message)
            self.error_set(message)

    def _render(self, depsgraph):
        scene = depsgraph.scene
        view_layer = depsgraph.view_layer
        t0 = time.perf_counter()
        apply_threads(scene)
        denoising = denoise.wanted(scene)
        settings = with_data_passes(settings_from_scene(scene), view_layer,
                                    denoise_guides=denoising and scene.restir.denoising_input_passes != "RGB")
        # AUTO may resolve to ReSTIR (known once the scene is exported): keep and preroll its history too
        wants_temporal = methods.keeps_history(settings)
        key = (scene.name, view_layer.name)
        prev = _TEMPORAL_HISTORY.pop(key, None)
        history = prev[1] if prev is not None and prev[0] == scene.frame_current - 1 else None
        # a chunk of an animation render that starts without history prerolls; a still does not (its
        # sample passes are independent, and only animations carry history from frame to frame)
        if wants_temporal and history is None and self.is_animation and scene.restir.preroll_frames > 0:
            history, cancelled = self._preroll(depsgraph, settings, int(scene.restir.preroll_frames))
            if cancelled:
                return
        core_scene = self._export(depsgraph)
        if core_scene is None:
            return
        plan = self._memory_plan(core_scene, settings, denoising)
        if plan is None:
            return
        bands, margin, estimate = plan
        if core_scene.camera.blind:  # a camera scaled to zero sees nothing: a black frame, no history
            self._write(_black_passes(scene, view_layer, core_scene.camera.window), core_scene.camera.window,
                        scene, view_layer)
            return
        self._motion(depsgraph, core_scene, view_layer.use_pass_vector, wants_temporal)
        t_export = time.perf_counter() - t0

        def progress(fraction, message):
            self.update_progress(fraction)
            self.update_stats("ReSTIR", f"Frame {scene.frame_current} | {message}")

        try:
            result = render_frame(core_scene, settings, progress=progress, should_stop=self.test_break,
                                  history=history, bands=bands, band_margin=margin,
                                  keep_history=self.is_animation)
        except Cancelled:
            return
        except MemoryError:
            message = (f"ReSTIR ran out of memory (this frame was estimated at {memory.size_text(estimate.low)} to "
                       f"{memory.size_text(estimate.high)}): lower the resolution or use the Path Tracing integrator")
            self.report({"ERROR"}, message)
            self.error_set(message)
            return
        if result.stats.get("processes_note"):
            self.report({"WARNING"}, result.stats["processes_note"])
        if result.history is not None and not result.cancelled:
            _TEMPORAL_HISTORY[key] = (scene.frame_current, result.history)
        for msg in scene_problems(core_scene, result.stats["light_triangles"] + result.stats["suns"]):
            self.report({"WARNING"}, msg)
        stamps = {} if result.cancelled else self._own_ray_passes(core_scene, depsgraph, settings, result)
        if denoising and not result.cancelled:
            self._denoise(scene, result)
        self._write(result.passes, core_scene.camera.window, scene, view_layer, stamps)
        self._remember(scene, result, t_export)

    def _export(self, depsgraph):
        """The core Scene of the depsgraph, its warnings reported (at most MAX_REPORTED_WARNINGS of them); None
        (reported as an error) where the file cannot be rendered."""
        self.update_stats("ReSTIR", "Exporting scene")
        try:
            core_scene = export_scene(depsgraph, self.camera_override)
        except ExportError as exc:
            self.report({"ERROR"}, str(exc))
            self.error_set(str(exc))
            return None
        unique = list(dict.fromkeys(core_scene.warnings))  # a reason met in several places is named once
        for msg in unique[:MAX_REPORTED_WARNINGS]:
            self.report({"WARNING"}, msg)
        if len(unique) > MAX_REPORTED_WARNINGS:
            self.report({"WARNING"}, f"... and {len(unique) - MAX_REPORTED_WARNINGS} more warnings")
        return core_scene

    def _memory_plan(self, core_scene, settings: RenderSettings, denoising: bool):
        """(bands, band margin, memory estimate) of the frame, or None where it cannot fit in the machine's free
        memory (refused with the estimate before any work, rather than failing part-way)."""
        free = memory.available_memory()
        bands, margin = band_plan(core_scene, settings, free, keeps_history=self.is_animation)
        estimate = memory.banded_estimate(core_scene, settings, bands, margin, keeps_history=self.is_animation)
        if denoising:
            estimate = memory.with_denoising(estimate, settings, keeps_history=self.is_animation)
        refusal, caution = memory.memory_problem(estimate, free, settings)
        if refusal:
            self.report({"ERROR"}, refusal)
            self.error_set(refusal)
            return None
        if caution:
            self.report({"WARNING"}, caution)
        if bands > 1:
            self.report({"INFO"}, f"Rendering in {bands} bands of the image to stay within memory (about "
                                  f"{memory.size_text(estimate.high)} at most)")
        return bands, margin, estimate

    def _own_ray_passes(self, core_scene, depsgraph, settings: RenderSettings, result) -> dict:
        """Cryptomatte and Shader AOV passes (their own camera rays) into ``result.passes``; returns the
        Cryptomatte metadata stamps."""
        scene, view_layer = depsgraph.scene, depsgraph.view_layer
        kinds, aovs = pass_table.cryptomatte_kinds(view_layer), pass_table.shader_aovs(view_layer)
        if not (kinds or aovs):
            return {}
        from .core.integrators.trace_context import build_context
        from .core.pipeline.aovs import render_aovs
        ctx = build_context(core_scene, 0)  # the first hits these passes trace
        rays = min(max(int(settings.samples), 16), 64)  # rays per pixel
        self.update_stats("ReSTIR", f"Frame {scene.frame_current} | Cryptomatte and Shader AOVs")
        stamps = {}
        if kinds:
            stamps = self._cryptomatte(ctx, depsgraph, settings, view_layer, kinds, rays, result.passes)
        if aovs:
            images = render_aovs(ctx, aovs, rays, settings.seed, settings.frame)
            result.passes.update({f"AOV {name}": img for name, img in images.items()})
        return stamps

    def _denoise(self, scene, result) -> None:
        """Combined denoised in place (the raw image kept as the Noisy Image pass)."""
        self.update_stats("ReSTIR", f"Frame {scene.frame_current} | Denoising")
        t_den = time.perf_counter()
        try:
            result.passes["Noisy Image"] = denoise.denoise_combined(result.passes, denoise.settings_of(scene))
            result.stats["denoise_seconds"] = time.perf_counter() - t_den
        except denoise.DenoiserUnavailable as exc:
            self.report({"WARNING"}, str(exc))

    def _remember(self, scene, result, t_export: float) -> None:
        """The frame's choices and statistics for the panels (LAST_CHOICES, LAST_FRAME_STATS) and the status line."""
        LAST_CHOICES[scene.name] = {k: result.stats[k] for k in ("direct_method", "direct_reason",
                                                                  "world_method", "world_reason",
                                                                  "coverage_samples", "coverage_reason",
                                                                  "spatial_radius", "indirect_method",
                                                                  "indirect_reason",
                                                                  "gi_spatial_radius", "gi_skipped_passes")}
        LAST_CHOICES[scene.name]["samples"] = result.samples_done
        LAST_FRAME_STATS.clear()
        LAST_FRAME_STATS.update(export_seconds=t_export, core_seconds=result.seconds, samples=result.samples_done,
                                frame=scene.frame_current, cancelled=result.cancelled, **result.stats)
        self.update_stats("ReSTIR", f"Frame {scene.frame_current} | {result.samples_done} samples | "
                                    f"export {t_export:.2f}s, render {result.seconds:.2f}s")

    def _motion(self, depsgraph, core_scene, wants_vector: bool, wants_temporal: bool) -> None:
        """The neighbouring frames' transforms (motion vectors, temporal reuse) and the shutter's (motion blur)."""
        if wants_vector or wants_temporal:
            self.update_stats("ReSTIR", "Evaluating neighbouring frames for motion")
            neighbour_frames(self, depsgraph, core_scene, self.camera_override, need_next=wants_vector)
        if motion_blur.wanted(depsgraph.scene):
            self.update_stats("ReSTIR", "Evaluating the shutter for motion blur")
            for msg in motion_blur.export_shutter(self, depsgraph, core_scene, self.camera_override):
                self.report({"WARNING"}, msg)

    def _preroll(self, depsgraph, settings, count: int):
        """Render the first sample pass of frames F-count .. F-1 (not written): the history travels through
        each frame's first pass, so this builds exactly the history a sequential render has at frame F (same
        seeds) at one pass per frame. Returns (history or None, whether the user cancelled)."""
        scene = depsgraph.scene
        frame = scene.frame_current
        history = None
        try:  # whatever happens, the scene goes back to frame F (an unrestored frame crashes Blender)
            for f in range(frame - count, frame):
                if self.test_break():
                    return None, True
                self.update_stats("ReSTIR", f"Preroll frame {f} for frame {frame}")
                self.frame_set(f, subframe=0.0)
                try:
                    core = export_scene(depsgraph, self.camera_override)
                    neighbour_frames(self, depsgraph, core, self.camera_override, need_next=False)
                    result = render_frame(core, replace(settings, samples=1, frame=f, data_passes=False),
                                          history=history)
                    if result.history is None:  # AUTO chose a method without history (and no ReSTIR GI)
                        return None, False
                    history = result.history
                except (ExportError, Cancelled):
                    history = None
        finally:
            self.frame_set(frame, subframe=0.0)
        return history, False

    # -- viewport (Rendered shading) ----------------------------------------------------------
    def view_update(self, context, depsgraph):
        """Blender's thread: export what the edit changed (export.incremental); the worker renders it."""
        from .export.incremental import SceneExporter, reads_object_properties, reads_view_layer, update_level
        from .viewport import ViewportSession
        scene = depsgraph.scene
        apply_threads(scene)
        if self._viewport is None:
            self._viewport = ViewportSession(self.tag_redraw)
            self._exporter = SceneExporter()
        exporter = self._exporter
        level = update_level(depsgraph.updates, reads_object_properties(exporter.last),
                             reads_view_layer(exporter.last)) if exporter.last is not None else "FULL"
        cam, key = self._view(context)
        settings = self._viewport_settings(scene, context)
        session = self._viewport
        session.budget = float(scene.restir.viewport_budget_ms) / 1000.0
        session.max_samples = int(scene.restir.viewport_samples)
        session.time_limit = float(scene.restir.time_limit)
        session.denoise = self._viewport_denoiser(scene)
        if level == "NONE" and settings == self._viewport_settings_last:
            session.set_view(cam, key)
            return
        try:
            core_scene = exporter.export(depsgraph, cam, level)
        except ExportError as exc:
            self.report({"ERROR"}, str(exc))
            return
        self._viewport_settings_last = settings
        session.set_scene(core_scene, settings)
        session.set_view(cam, key)

    @staticmethod
    def _viewport_settings(scene, context) -> RenderSettings:
        """The render settings for the viewport's Samples, data passes only on demand (the Depth/Normal/Motion viewport
        passes compute them lazily); a reservoir pass on screen makes Auto resample, as in a final render."""
        from .viewport import GI_RESERVOIR_PASSES, RESERVOIR_PASSES
        settings = settings_from_scene(scene)
        # a pass renders one sample (or a batch, viewport.py); Samples is the viewport's: adaptive sampling's schedule
        # (Noise Threshold, as in a final render) reads it, and converged pixels stop refining
        settings.samples = max(1, int(scene.restir.viewport_samples))
        settings.data_passes = False
        settings.reservoir_passes = _viewport_pass(context) in RESERVOIR_PASSES
        settings.gi_reservoir_passes = _viewport_pass(context) in GI_RESERVOIR_PASSES
        settings.tile_pixels = 16384  # small chunks: a stop request is seen within one chunk of one stage
        settings.denoise_data = bool(scene.restir.use_preview_denoising)  # the albedo guiding the denoiser
        return settings

    def _viewport_denoiser(self, scene):
        """(Denoiser, its viewport settings) where Viewport Denoise is on and the library loads, else None."""
        if not scene.restir.use_preview_denoising:
            return None
        try:
            return denoise.denoiser(), denoise.VIEWPORT_SETTINGS
        except denoise.DenoiserUnavailable as exc:
            self.report({"WARNING"}, str(exc))
            return None

    def _view(self, context):
        """(core camera of the 3D view at its full viewport resolution, key of the view)."""
        from .export.camera import film_filter, thin_lens
        from .viewport import view_camera
        scene = context.scene
        pixel = max(1, int(self.get_preview_pixel_size(scene)))
        w, h = max(1, context.region.width // pixel), max(1, context.region.height // pixel)
        space = context.space_data
        rd = context.region_data
        lens = None
        if rd.view_perspective == "CAMERA" and scene.camera is not None:  # through the camera: its depth of field
            lens = thin_lens(scene, scene.camera, np.linalg.inv(np.array(rd.view_matrix, np.float64)), [])
        key = (tuple(map(tuple, rd.view_matrix)), tuple(map(tuple, rd.window_matrix)), w, h)
        return view_camera(rd, w, h, space.clip_start, space.clip_end, film_filter(scene), lens), key

    def view_draw(self, context, depsgraph):
        """UI thread: hand the view to the worker, draw its newest image. Never waits for a pass."""
        import gpu
        from gpu_extras.presets import draw_texture_2d

        from .viewport import DATA_PASSES, GI_RESERVOIR_PASSES, RESERVOIR_PASSES
        session = self._viewport
        if session is None:
            return
        cam, key = self._view(context)
        session.set_view(cam, key)
        name = _viewport_pass(context)
        last = self._viewport_settings_last
        wants = (name in RESERVOIR_PASSES, name in GI_RESERVOIR_PASSES)
        if last is not None and (last.reservoir_passes, last.gi_reservoir_passes) != wants and \
                self._exporter.last is not None:
            # Auto picks its methods with the reservoir passes in mind: re-plan with the same scene
            settings = replace(last, reservoir_passes=wants[0], gi_reservoir_passes=wants[1])
            self._viewport_settings_last = settings
            session.set_scene(self._exporter.export(depsgraph, cam, "SETTINGS"), settings)
        session.set_pass(name)
        image, _samples = session.latest()
        if session.last_error:
            self.update_stats("ReSTIR", f"Viewport failed: {session.last_error}")
        if image is None:
            return
        if self._texture is None or self._texture[0] is not image:  # upload only a new image, not every redraw
            ih, iw = image.shape[:2]
            buf = gpu.types.Buffer("FLOAT", iw * ih * 4, np.ascontiguousarray(image).ravel())
            self._texture = (image, gpu.types.GPUTexture((iw, ih), format="RGBA16F", data=buf))
        gpu.state.blend_set("ALPHA_PREMULT")
        data = session.image_pass in DATA_PASSES  # false colours and data: shown as they are, not tone-mapped
        if not data:
            self.bind_display_space_shader(depsgraph.scene)
        draw_texture_2d(self._texture[1], (0, 0), context.region.width, context.region.height)
        if not data:
            self.unbind_display_space_shader()
        gpu.state.blend_set("NONE")
        if not session.last_error:
            self.update_stats("ReSTIR", session.stats.text())

    @staticmethod
    def _cryptomatte(ctx, depsgraph, settings, view_layer, kinds, rays: int, passes: dict) -> dict:
        """Adds the Cryptomatte passes to ``passes``; returns their metadata fields (the manifests name the lights
        too, as Cycles')."""
        from .core.pipeline import cryptomatte
        images, manifests = cryptomatte.render_cryptomatte(ctx, kinds, int(view_layer.pass_cryptomatte_depth), rays,
                                                           settings.seed, settings.frame)
        passes.update(images)
        from .export.meshes import asset_name
        lights = [inst.object for inst in depsgraph.object_instances if inst.object.type == "LIGHT"]
        extra = {"object": [o.name for o in lights], "asset": [asset_name(o) for o in lights]}
        stamps = {}
        for kind in kinds:
            manifest = {**{n: f"{cryptomatte.name_hash(n):08x}" for n in extra.get(kind, ())}, **manifests[kind]}
            stamps.update(cryptomatte.metadata(view_layer.name, kind, manifest))
        return stamps

    def _write(self, images: dict, window, scene, view_layer, stamps: dict | None = None):
        _x0, _y0, w, h = window
        result = self.begin_result(0, 0, w, h, layer=view_layer.name)
        layer = result.layers[0] if len(result.layers) == 1 else result.layers[view_layer.name]
        for name, chans, _ctype, _enabled, core_name in pass_table.enabled_passes(scene, view_layer):
            rp = layer.passes.find_by_name(name, "")
            if rp is None or core_name not in images:
                continue
            _set_rect(rp, np.ascontiguousarray(images[core_name], dtype=np.float32).reshape(w * h, len(chans)))
        self.end_result(result)
        if stamps:  # metadata (Cryptomatte manifests) go on the engine's whole result, written into EXR headers
            whole = self.get_result()
            for key, value in stamps.items():
                whole.stamp_data_add_field(key, value)
