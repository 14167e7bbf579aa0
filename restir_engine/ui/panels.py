"""Render Properties panels (Cycles-style) shown only for the ReSTIR engine, plus opt-in to the
standard Blender panels that apply to it."""
from __future__ import annotations

import bpy

from ..core.pipeline import methods
from ..presets import PRESET_ITEMS

ENGINE = "RESTIR"

# Standard panels that work unchanged with this engine (output, format, colour management,
# dimensions, camera, object, material surface, lights, world).
STANDARD_PANELS = (
    # render: output, format, frame range, colour management, post processing, stamp
    "RENDER_PT_format", "RENDER_PT_frame_range", "RENDER_PT_time_stretching", "RENDER_PT_stereoscopy",
    "RENDER_PT_output", "RENDER_PT_output_views", "RENDER_PT_output_color_management", "RENDER_PT_output_pixel_density",
    "RENDER_PT_encoding", "RENDER_PT_encoding_video", "RENDER_PT_encoding_audio", "RENDER_PT_post_processing",
    "RENDER_PT_stamp", "RENDER_PT_stamp_note", "RENDER_PT_stamp_burn", "RENDER_PT_color_management",
    "RENDER_PT_color_management_advanced", "RENDER_PT_color_management_curves",
    "RENDER_PT_color_management_white_balance", "RENDER_PT_color_management_working_space",
    "VIEWLAYER_PT_layer", "VIEWLAYER_PT_context_layer",
    # camera
    "DATA_PT_context_camera", "DATA_PT_lens", "DATA_PT_camera", "DATA_PT_camera_display", "DATA_PT_camera_dof",
    "DATA_PT_camera_dof_aperture",
    "DATA_PT_camera_display_composition_guides", "DATA_PT_camera_safe_areas", "DATA_PT_camera_safe_areas_center_cut",
    "DATA_PT_camera_background_image", "DATA_PT_camera_stereoscopy", "DATA_PT_custom_props_camera",
    # lights
    "DATA_PT_context_light", "DATA_PT_preview", "DATA_PT_light", "DATA_PT_spot", "DATA_PT_cone",
    "DATA_PT_custom_props_light",
    # object and mesh data
    "OBJECT_PT_visibility", "OBJECT_PT_custom_props", "DATA_PT_context_mesh", "DATA_PT_uv_texture",
    "DATA_PT_vertex_groups", "DATA_PT_shape_keys", "DATA_PT_mesh_attributes", "DATA_PT_texture_space",
    "DATA_PT_customdata", "DATA_PT_custom_props_mesh", "DATA_PT_remesh",
    # materials (surface node panel and slots) and world
    "EEVEE_MATERIAL_PT_context_material", "EEVEE_MATERIAL_PT_surface", "MATERIAL_PT_preview",
    "MATERIAL_PT_custom_props", "WORLD_PT_context_world", "EEVEE_WORLD_PT_surface", "WORLD_PT_custom_props",
    # particles (instancing)
    "PARTICLE_PT_context_particles", "PARTICLE_PT_emission", "PARTICLE_PT_render", "PARTICLE_PT_render_object",
    "PARTICLE_PT_render_collection",
)


class RestirPanel:
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    COMPAT_ENGINES = {ENGINE}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES

    def split_layout(self):
        """The panel layout in Blender's property-split style, without animation decorators."""
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        return layout


class RESTIR_PT_sampling(RestirPanel, bpy.types.Panel):
    bl_label = "Sampling"

    def draw(self, context):
        layout = self.split_layout()
        s = context.scene.restir
        row = layout.row(align=True)
        for key, label, _description in PRESET_ITEMS:
            row.operator("restir.apply_preset", text=label).preset = key
        layout.prop(s, "integrator")
        col = layout.column(align=True)
        col.prop(s, "samples", text="Render Samples")
        row = col.row(heading="Noise Threshold", align=True)
        row.prop(s, "use_adaptive_sampling", text="")
        sub = row.row()
        sub.active = s.use_adaptive_sampling
        sub.prop(s, "adaptive_threshold", text="")
        sub = col.row()
        sub.active = s.use_adaptive_sampling
        sub.prop(s, "adaptive_min_samples")
        col.prop(s, "viewport_samples")
        col.prop(s, "time_limit")
        col.prop(s, "viewport_budget_ms")
        col.prop(s, "seed")
        layout.prop(s, "coverage_samples")
        last = _last_choices(context.scene)
        if last and s.coverage_samples == "AUTO":
            _last_box(layout, None, f"Pixel coverage: {last['coverage_samples']} "
                                    f"ray{'s' if last['coverage_samples'] != 1 else ''} ({last['coverage_reason']})")


def _last_box(layout, headline, text):
    """An info box with what Auto chose in the last render: ``headline`` (or none) and ``text``."""
    box = layout.box()
    box.scale_y = 0.8
    if headline:
        box.label(text=headline, icon="INFO")
    box.label(text=text)


def _spatial_reuse(layout, s, last, prefix: str) -> None:
    """The Spatial Reuse settings of DI (``prefix`` "") or GI ("gi_"), with the last render's automatic radius."""
    col = layout.column(align=True, heading="Spatial Reuse")
    col.prop(s, prefix + "spatial_neighbors")
    col.prop(s, prefix + "spatial_radius")
    radius = last.get(prefix + "spatial_radius") if last else None
    if getattr(s, prefix + "spatial_radius") == 0 and radius:
        col.label(text=f"Auto radius in the last render: {radius:.1f} px")
    col.prop(s, prefix + "spatial_passes")


def _title(method: str) -> str:
    return method.replace("_", " ").title()


class RestirIntegratorPanel(RestirPanel):
    """A sub-panel of settings the ReSTIR integrator reads (hidden for the path tracer)."""

    @classmethod
    def poll(cls, context):
        return super().poll(context) and context.scene.restir.integrator == "RESTIR"


class RESTIR_PT_sampling_direct(RestirIntegratorPanel, bpy.types.Panel):
    bl_label = "Direct Light"
    bl_parent_id = "RESTIR_PT_sampling"

    def draw(self, context):
        layout = self.split_layout()
        s = context.scene.restir
        last = _last_choices(context.scene)
        layout.prop(s, "direct_method")
        if last and s.direct_method == "AUTO":
            _last_box(layout, f"Last render: {_title(last['direct_method'])}", last["direct_reason"])
        resampled = methods.resamples_direct(s)
        col = layout.column(align=True)
        col.active = resampled
        col.prop(s, "light_candidates")
        col.prop(s, "bsdf_candidates")
        col = layout.column(align=True)
        col.active = resampled
        col.prop(s, "world_method")
        sub = col.column(align=True)
        sub.active = s.world_method != "LIGHT_SAMPLED"
        sub.prop(s, "world_candidates")
        if last and s.world_method == "AUTO" and last.get("world_reason"):
            _last_box(col, f"Last render: {_title(last['world_method'])}", last["world_reason"])
        col = layout.column(align=True)
        col.active = resampled
        col.prop(s, "light_tiles")
        sub = col.column(align=True)
        sub.active = s.light_tiles != "OFF"
        sub.prop(s, "light_sampler")
        row = sub.column(align=True)
        row.active = s.light_sampler == "POWER"  # spatial tiles: one per block, their own size
        row.prop(s, "light_tile_count")
        row.prop(s, "light_tile_size")


class RESTIR_PT_sampling_reuse(RestirPanel, bpy.types.Panel):
    bl_label = "Reuse"
    bl_parent_id = "RESTIR_PT_sampling"

    @classmethod
    def poll(cls, context):
        return super().poll(context) and methods.reuses_direct(context.scene.restir)

    def draw(self, context):
        layout = self.split_layout()
        s = context.scene.restir
        last = _last_choices(context.scene)
        col = layout.column(align=True, heading="Temporal Reuse")
        col.prop(s, "temporal_reuse", text="")
        sub = col.column()
        sub.active = s.temporal_reuse
        sub.prop(s, "confidence_cap")
        sub.prop(s, "preroll_frames")
        _spatial_reuse(layout, s, last, "")
        layout.prop(s, "bias_correction")
        col = layout.column(align=True, heading="Boiling Filter")
        col.active = s.bias_correction == "NONE"  # biased: the unbiased mode never applies it
        row = col.row(align=True)
        row.prop(s, "boiling_filter", text="")
        sub = row.row(align=True)
        sub.active = s.boiling_filter
        sub.prop(s, "boiling_threshold")


class RESTIR_PT_sampling_indirect(RestirIntegratorPanel, bpy.types.Panel):
    bl_label = "Indirect"
    bl_parent_id = "RESTIR_PT_sampling"

    def draw(self, context):
        layout = self.split_layout()
        s = context.scene.restir
        layout.prop(s, "indirect_method")
        if s.indirect_method not in ("RESTIR_GI", "AUTO"):  # the settings below are ReSTIR GI's
            return
        if s.max_bounces == 0:
            layout.label(text="Max Bounces is 0: there is no indirect light", icon="INFO")
        last = _last_choices(context.scene)
        if last and s.indirect_method == "AUTO" and last.get("indirect_reason"):
            label = {"RESTIR_GI": "ReSTIR GI", "PATH": "Path Tracing"}.get(last["indirect_method"], "Off")
            _last_box(layout, f"Last render: {label}", last["indirect_reason"])
        elif last and last.get("gi_skipped_passes"):
            layout.label(text=f"Last render: path-traced indirect light in {last['gi_skipped_passes']} of "
                              f"{last.get('samples', '?')} samples (almost no bounce light to cache)", icon="INFO")
        if methods.reuses_direct(s):
            layout.label(text="Temporal reuse and bias correction: as set under Reuse")
        else:  # the shared settings are not drawn under Reuse for these direct methods
            layout.prop(s, "temporal_reuse")
            layout.prop(s, "bias_correction")
        col = layout.column(align=True, heading="Temporal Reuse")
        col.active = s.temporal_reuse
        col.prop(s, "gi_confidence_cap")
        col.prop(s, "gi_max_age")
        _spatial_reuse(layout, s, last, "gi_")
        layout.prop(s, "gi_roughness_threshold")


def _last_choices(scene):
    """What the automatic settings picked in this scene's last render (engine.LAST_CHOICES), or None."""
    from ..engine import LAST_CHOICES
    return LAST_CHOICES.get(scene.name)


class RESTIR_PT_sampling_denoising(RestirPanel, bpy.types.Panel):
    bl_label = "Denoising"
    bl_parent_id = "RESTIR_PT_sampling"

    def draw_header(self, context):
        self.layout.prop(context.scene.restir, "use_denoising", text="")

    def draw(self, context):
        from ..denoise import legacy_compositor_denoise
        layout = self.split_layout()
        s = context.scene.restir
        col = layout.column()
        col.active = s.use_denoising
        col.prop(s, "denoising_input_passes")
        sub = col.column()
        sub.active = s.denoising_input_passes != "RGB"
        sub.prop(s, "denoising_prefilter")
        col.prop(s, "denoising_quality")
        layout.prop(s, "use_preview_denoising")
        if legacy_compositor_denoise(context.scene):
            box = layout.box()
            box.label(text="The compositor denoises (set up by an older version)", icon="INFO")
            box.operator("restir.remove_compositor_denoising")


class RESTIR_PT_light_paths(RestirPanel, bpy.types.Panel):
    bl_label = "Light Paths"

    def draw(self, context):
        layout = self.split_layout()
        layout.prop(context.scene.restir, "max_bounces")
        layout.prop(context.scene.render, "film_transparent")


class RESTIR_PT_film(RestirPanel, bpy.types.Panel):
    bl_label = "Film"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = self.split_layout()
        s = context.scene.restir
        layout.prop(s, "pixel_filter")
        row = layout.row()
        row.active = s.pixel_filter != "BOX"
        row.prop(s, "filter_width")


class RESTIR_PT_motion_blur(RestirPanel, bpy.types.Panel):
    bl_label = "Motion Blur"
    bl_options = {"DEFAULT_CLOSED"}

    def draw_header(self, context):
        self.layout.prop(context.scene.render, "use_motion_blur", text="")

    def draw(self, context):
        layout = self.split_layout()
        layout.active = context.scene.render.use_motion_blur
        layout.prop(context.scene.render, "motion_blur_position", text="Position")
        layout.prop(context.scene.render, "motion_blur_shutter")


class RESTIR_PT_motion_blur_curve(RestirPanel, bpy.types.Panel):
    bl_label = "Shutter Curve"
    bl_parent_id = "RESTIR_PT_motion_blur"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = self.layout
        layout.active = context.scene.render.use_motion_blur
        layout.template_curve_mapping(context.scene.render, "motion_blur_shutter_curve")


class RESTIR_PT_performance(RestirPanel, bpy.types.Panel):
    bl_label = "Performance"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = self.split_layout()
        render = context.scene.render
        layout.prop(render, "threads_mode")
        row = layout.row()
        row.enabled = render.threads_mode == "FIXED"
        row.prop(render, "threads")
        layout.prop(context.scene.restir, "processes")
        from ..core.parallel.processes import split
        from ..core.parallel.tasks import spans
        from ..core.pipeline.work import CHUNK_PIXELS
        pixels = (render.resolution_x * render.resolution_y * render.resolution_percentage ** 2) // 10000
        procs, threads = split(render.threads if render.threads_mode == "FIXED" else None,
                               context.scene.restir.processes,
                               len(spans(max(1, pixels), CHUNK_PIXELS)))
        layout.label(text=f"F12 and animation: {procs} process{'es' if procs > 1 else ''} x {threads} "
                          f"thread{'s' if threads > 1 else ''}", icon="INFO")


class RESTIR_PT_passes(RestirPanel, bpy.types.Panel):
    bl_label = "Passes"
    bl_context = "view_layer"

    def draw(self, context):
        layout = self.split_layout()
        vl = context.view_layer
        col = layout.column(heading="Data", align=True)
        col.prop(vl, "use_pass_z")
        col.prop(vl, "use_pass_normal")
        col.prop(vl, "use_pass_vector")
        col = layout.column(heading="Light", align=True)
        col.prop(vl.restir, "use_pass_direct")
        col.prop(vl.restir, "use_pass_indirect")
        col.prop(vl.restir, "use_pass_emission")
        col = layout.column(heading="ReSTIR", align=True)
        col.active = context.scene.restir.integrator == "RESTIR" and context.scene.restir.direct_method != "LIGHT_SAMPLING"
        if context.scene.restir.direct_method == "AUTO":
            col.label(text="Auto uses ReSTIR when a reservoir pass is on")
        col.prop(vl.restir, "use_pass_reservoir_m")
        col.prop(vl.restir, "use_pass_reservoir_ucw")
        col = layout.column(heading="ReSTIR GI", align=True)
        sc = context.scene.restir
        col.active = methods.gi_possible(sc)
        if sc.indirect_method == "AUTO":
            col.label(text="Auto uses ReSTIR GI when a GI reservoir pass is on")
        col.prop(vl.restir, "use_pass_gi_reservoir_m")
        col.prop(vl.restir, "use_pass_gi_reservoir_ucw")
        col = layout.column(heading="Denoising", align=True)
        col.prop(vl.restir, "use_pass_denoising_data")
        col = layout.column(heading="Sampling", align=True)
        col.active = context.scene.restir.use_adaptive_sampling
        col.prop(vl.restir, "use_pass_sample_count")
        col = layout.column(heading="Shadow Catcher", align=True)
        col.prop(vl.restir, "use_pass_shadow_catcher", text="Shadow Catcher")
        col = layout.column(heading="Cryptomatte", align=True)
        col.prop(vl, "use_pass_cryptomatte_object", text="Object")
        col.prop(vl, "use_pass_cryptomatte_material", text="Material")
        col.prop(vl, "use_pass_cryptomatte_asset", text="Asset")
        col.prop(vl, "pass_cryptomatte_depth", text="Levels")
        layout.label(text="Shader AOV")
        row = layout.row()
        if hasattr(bpy.types, "VIEWLAYER_UL_aov"):
            row.template_list("VIEWLAYER_UL_aov", "aovs", vl, "aovs", vl, "active_aov_index", rows=3)
        else:
            row.template_list("UI_UL_list", "aovs", vl, "aovs", vl, "active_aov_index", rows=3)
        ops = row.column(align=True)
        ops.operator("scene.view_layer_add_aov", icon="ADD", text="")
        ops.operator("scene.view_layer_remove_aov", icon="REMOVE", text="")
        if vl.active_aov is not None:
            layout.prop(vl.active_aov, "type")
        layout.label(text="Light Groups")
        row = layout.row()
        row.template_list("UI_UL_list", "lightgroups", vl, "lightgroups", vl, "active_lightgroup_index", rows=3)
        ops = row.column(align=True)
        ops.operator("scene.view_layer_add_lightgroup", icon="ADD", text="")
        ops.operator("scene.view_layer_remove_lightgroup", icon="REMOVE", text="")


class RestirLightGroupPanel(RestirPanel):
    """An object's or the world's Light Group (one "Combined_<group>" pass per group of the view layer)."""
    bl_label = "Light Group"
    bl_options = {"DEFAULT_CLOSED"}

    def draw_group(self, context, owner):
        layout = self.split_layout()
        row = layout.row(align=True)
        row.prop_search(owner, "lightgroup", context.view_layer, "lightgroups", text="Light Group",
                        results_are_suggestions=True)
        name = owner.lightgroup
        if name and name not in context.view_layer.lightgroups:  # the view layer lacks it: offer to add it
            row.operator("scene.view_layer_add_lightgroup", icon="ADD", text="").name = name


class RESTIR_PT_object_light_group(RestirLightGroupPanel, bpy.types.Panel):
    bl_context = "object"

    @classmethod
    def poll(cls, context):
        return super().poll(context) and context.object is not None and context.object.type in {
            "MESH", "CURVE", "SURFACE", "FONT", "META", "LIGHT", "POINTCLOUD", "CURVES"}

    def draw(self, context):
        self.draw_group(context, context.object)


class RESTIR_PT_object_mask(RestirPanel, bpy.types.Panel):
    """Object Properties > Visibility > Shadow Catcher (pipeline/shadow_catcher.py; Holdout is in Visibility's own
    Mask)."""
    bl_label = "Shadow Catcher"
    bl_context = "object"
    bl_parent_id = "OBJECT_PT_visibility"

    @classmethod
    def poll(cls, context):
        return super().poll(context) and context.object is not None and context.object.type in {
            "MESH", "CURVE", "SURFACE", "FONT", "META", "POINTCLOUD", "CURVES"}

    def draw(self, context):
        layout = self.split_layout()
        layout.prop(context.object, "is_shadow_catcher")


class RESTIR_PT_world_light_group(RestirLightGroupPanel, bpy.types.Panel):
    bl_context = "world"

    @classmethod
    def poll(cls, context):
        return super().poll(context) and context.world is not None

    def draw(self, context):
        self.draw_group(context, context.world)


class RESTIR_PT_viewport_render_pass(bpy.types.Panel):
    """The Rendered viewport's pass, in the 3D view's Shading popover (as Cycles' Render Pass)."""
    bl_space_type = "VIEW_3D"
    bl_region_type = "HEADER"
    bl_parent_id = "VIEW3D_PT_shading"
    bl_label = "Render Pass"
    COMPAT_ENGINES = {ENGINE}

    @classmethod
    def poll(cls, context):
        view = context.space_data
        return context.engine in cls.COMPAT_ENGINES and view is not None and view.shading.type == "RENDERED"

    def draw(self, context):
        self.layout.prop(context.space_data.shading.restir, "render_pass", text="")


PANELS = (RESTIR_PT_sampling, RESTIR_PT_sampling_direct, RESTIR_PT_sampling_reuse, RESTIR_PT_sampling_indirect,
          RESTIR_PT_sampling_denoising, RESTIR_PT_light_paths, RESTIR_PT_film, RESTIR_PT_motion_blur,
          RESTIR_PT_motion_blur_curve, RESTIR_PT_performance,
          RESTIR_PT_passes)  # Render Properties
VIEW_PANELS = (RESTIR_PT_viewport_render_pass,)  # the 3D view's header popovers
DATA_PANELS = (RESTIR_PT_object_light_group, RESTIR_PT_object_mask,
               RESTIR_PT_world_light_group)  # Object and World Properties


def _standard_panels():
    for name in STANDARD_PANELS:
        panel = getattr(bpy.types, name, None)
        if panel is not None and hasattr(panel, "COMPAT_ENGINES"):
            yield panel


def register():
    for cls in PANELS + VIEW_PANELS + DATA_PANELS:
        bpy.utils.register_class(cls)
    for panel in _standard_panels():
        panel.COMPAT_ENGINES.add(ENGINE)


def unregister():
    for panel in _standard_panels():
        panel.COMPAT_ENGINES.discard(ENGINE)
    for cls in reversed(PANELS + VIEW_PANELS + DATA_PANELS):
        bpy.utils.unregister_class(cls)
