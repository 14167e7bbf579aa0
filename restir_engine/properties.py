"""Settings stored in the .blend: ``scene.restir`` (render) and ``view_layer.restir`` (passes)."""
from __future__ import annotations

from dataclasses import dataclass

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty

from .core.restir.boiling import THRESHOLD as BOILING_THRESHOLD
from .core.lights.tiles import TileSettings
from .core.restir.di import CandidateSettings
from .core.restir.gi import GISettings
from .core.restir.reuse import SpatialSettings, TemporalSettings
from .viewport import DEFAULT_BUDGET, MAX_VIEWPORT_SAMPLES, VIEWPORT_PASSES


def _update_passes(self, context):
    """Pass toggles change the render result layout: ask Blender to re-query the pass list."""
    view_layer = getattr(context, "view_layer", None)
    if view_layer is not None:
        view_layer.update_render_passes()


@dataclass(frozen=True)
class Field:
    """One ``scene.restir`` setting: its property name (kept as saved .blend files, presets and scripts use it), the
    bpy.props function and its arguments, and ``to_core``, which turns the stored value into the RenderSettings
    field of the same name (None: a Blender-side setting the core does not read)."""

    name: str
    prop: object
    to_core: object
    kwargs: dict


def _coverage(value: str) -> int:
    return 0 if value == "AUTO" else int(value)


# The table every scene setting is written in once: RestirSceneSettings is generated from it, settings_from_scene
# (engine.py) reads through it, and tests/blender/test_settings_table.py checks it against RenderSettings, the
# presets and the panels.
SCENE_FIELDS = (
    Field("integrator", EnumProperty, str, dict(
        name="Integrator",
        description="Light transport algorithm",
        items=[("PATH", "Path Tracing", "Unbiased reference path tracer: next-event estimation and BSDF sampling "
                "combined by multiple importance sampling", 0),
               ("RESTIR", "ReSTIR", "Direct light of the first hit by resampled importance sampling (ReSTIR DI "
                "stages, see Direct Method); indirect light path traced", 1)],
        default="RESTIR", update=_update_passes)),
    Field("direct_method", EnumProperty, str, dict(
        name="Direct Method",
        description="How the ReSTIR integrator estimates direct light at the first hit",
        items=[("AUTO", "Auto", "Light sampling where the scene has a few lights, ReSTIR where resampling pays "
                "(chosen per frame from the light count, measured; the choice and its reason show below)", 3),
               ("LIGHT_SAMPLING", "Light Sampling", "Baseline: one light sample and one BSDF sample combined by MIS", 0),
               ("RIS", "RIS", "Resampled importance sampling: pick one of many light and BSDF candidates by the "
                "unshadowed contribution, then trace one shadow ray (unbiased)", 1),
               ("RESTIR", "ReSTIR", "RIS, then reuse of the previous frame's reservoirs (temporal) "
                "and of neighbouring pixels' (spatial)", 2)],
        default="AUTO", update=_update_passes)),
    Field("coverage_samples", EnumProperty, _coverage, dict(
        name="Pixel Coverage",
        description="Camera rays per pixel for the emission seen directly (lamps, emissive surfaces, the world): "
                    "the pixel is split into strata, the lighting is shaded at one ray and the emission averaged "
                    "over one ray per stratum, so small bright emitters and their edges converge faster",
        items=[("AUTO", "Auto", "4 rays per pixel where the camera can see emitters (16 where it sees 4096 or more "
                "emissive triangles), else 1", 0),
               ("1", "1 Ray", "One camera ray per pixel and sample", 1),
               ("4", "4 Rays", "2 x 2 strata", 4),
               ("9", "9 Rays", "3 x 3 strata", 9),
               ("16", "16 Rays", "4 x 4 strata", 16)],
        default="AUTO")),
    Field("light_candidates", IntProperty, int, dict(
        name="Light Candidates", description="Light samples per pixel resampled by RIS",
        default=CandidateSettings.light_candidates, min=0, soft_max=256)),
    Field("bsdf_candidates", IntProperty, int, dict(
        name="BSDF Candidates", description="BSDF-sampled rays per pixel resampled by RIS",
        default=CandidateSettings.bsdf_candidates, min=0, soft_max=8)),
    Field("world_method", EnumProperty, str, dict(
        name="World Light",
        description="How resampled direct light treats the world (environment image or colour)",
        items=[("AUTO", "Auto", "In the reservoirs for an environment image that is the only light, else light-"
                                "sampled (the Sampling panel shows the last render's choice)"),
               ("RESAMPLED", "Resampled", "World samples are resampled with the lights and reused across pixels and "
                                          "frames like any light"),
               ("LIGHT_SAMPLED", "Light Sampled", "One world light sample per shaded point beside the reservoirs "
                                                  "(MIS with the BSDF)")],
        default="AUTO")),
    Field("world_candidates", IntProperty, int, dict(
        name="World Candidates",
        description="Directions per pixel drawn from the world's own distribution and resampled with the lights "
                    "(World Light resampled)",
        default=CandidateSettings.world_candidates, min=0, soft_max=8)),
    Field("light_tiles", EnumProperty, str, dict(
        name="Light Tiles",
        description="Draw light candidates from small presampled tiles of light points (one tile per 16x16 "
                    "pixel block) instead of the full light table: the same result on average, much cheaper "
                    "candidates, some correlation between nearby pixels",
        items=[("AUTO", "Auto", "Use tiles when the candidates of a sample pass outnumber the tile points "
                "eight times (any image larger than about 180x180 at 32 candidates)", 0),
               ("ON", "On", "Always draw candidates from tiles", 1),
               ("OFF", "Off", "Draw every candidate from the full light table", 2)],
        default=TileSettings.mode)),
    Field("light_sampler", EnumProperty, str, dict(
        name="Tile Sampling",
        description="How the light tiles are drawn",
        items=[("SPATIAL", "Spatial", "One tile per 16x16 pixel block, drawn with more probability for the lights "
                "near that block's surfaces (light clusters weighted by power over distance, 10 % by power alone): "
                "surfaces next to an emitter get candidates from it", 0),
               ("POWER", "Power", "Tiles drawn by light power alone, one picked at random per block", 1)],
        default="SPATIAL")),
    Field("light_tile_count", IntProperty, int, dict(
        name="Tiles", description="Light tiles drawn per sample pass", default=TileSettings.count,
        min=1, soft_max=1024)),
    Field("light_tile_size", IntProperty, int, dict(
        name="Tile Size", description="Light points per tile", default=TileSettings.size, min=1,
        soft_max=8192)),
    Field("temporal_reuse", BoolProperty, bool, dict(
        name="Temporal Reuse", description="Reuse the reservoir the pixel's surface had "
        "in the previous frame of an animation (through each frame's first sample pass; "
        "the other passes stay independent, so a frame's average is not correlated)",
        default=True)),
    Field("preroll_frames", IntProperty, None, dict(
        name="Preroll Frames", description="When an animation job starts without the "
        "previous frame's history (the first frame of a farm chunk), first render the first "
        "sample pass of this many frames before it, unsaved: the chunk then matches a "
        "sequential render exactly", default=3, min=0, soft_max=16)),
    Field("confidence_cap", FloatProperty, float, dict(
        name="Confidence Cap", description="Largest confidence M a reused reservoir keeps",
        default=TemporalSettings.confidence_cap, min=1.0, soft_max=100.0)),
    Field("spatial_neighbors", IntProperty, int, dict(
        name="Neighbors", description="Neighbouring reservoirs merged per spatial pass",
        default=SpatialSettings.neighbors, min=0, soft_max=16)),
    Field("spatial_radius", FloatProperty, float, dict(
        name="Radius", description="Spatial reuse radius in pixels; 0 = automatic: "
        "8 px at 640x360, scaled with the image diagonal (4 px at least)",
        default=SpatialSettings.radius, min=0.0, soft_max=100.0, subtype="PIXEL")),
    Field("spatial_passes", IntProperty, int, dict(
        name="Passes", description="Spatial reuse passes (more passes add correlation)",
        default=SpatialSettings.passes, min=0, soft_max=4)),
    Field("bias_correction", EnumProperty, str, dict(
        name="Bias Correction",
        description="How merged reservoirs are normalized",
        items=[("NONE", "None (1/M)", "Fastest; darkens where neighbours could not have produced the sample", 0),
               ("UNBIASED", "Unbiased (pairwise MIS)", "Pairwise MIS weights with confidences: converges to the "
                "path tracer and Cycles, robust where neighbours' targets differ; two target evaluations per neighbour", 1)],
        default=SpatialSettings.bias_correction)),
    Field("boiling_filter", BoolProperty, bool, dict(
        name="Boiling Filter", description="With bias correction None: empty reservoirs whose contribution is "
        "far above their 16x16 pixel block's mean, so a rare bright sample does not spread into blotches over "
        "neighbours and frames. Biased (darker); never used by the unbiased mode", default=False)),
    Field("boiling_threshold", FloatProperty, float, dict(
        name="Threshold", description="A reservoir is emptied when its contribution exceeds this many times its "
        "block's mean (lower filters more)", default=BOILING_THRESHOLD, min=1.5, soft_max=100.0)),
    Field("use_denoising", BoolProperty, None, dict(
        name="Denoise", description="Denoise F12 and animation frames with Open Image Denoise (the library Blender "
        "ships), guided by the first hit's albedo and normal, as Cycles does; the compositor is left as it is. "
        "With the Denoising Data passes on, the image before denoising is kept as Noisy Image", default=True)),
    Field("denoising_input_passes", EnumProperty, None, dict(
        name="Passes", description="Passes that guide the denoiser",
        items=[("RGB", "None", "The image alone", 1),
               ("RGB_ALBEDO", "Albedo", "The image and the first hit's albedo", 2),
               ("RGB_ALBEDO_NORMAL", "Albedo and Normal", "The image, the first hit's albedo and its normal", 3)],
        default="RGB_ALBEDO_NORMAL")),
    Field("denoising_prefilter", EnumProperty, None, dict(
        name="Prefilter", description="How the guiding passes are treated",
        items=[("NONE", "None", "Taken as noise-free (renders with many samples, no depth of field or motion)", 1),
               ("FAST", "Fast", "Handed over as noisy: the denoiser allows for it at no extra cost", 2),
               ("ACCURATE", "Accurate", "Denoised first, each on its own, then used as clean guides (slower, "
                "sharper where the guides are noisy)", 3)],
        default="ACCURATE")),
    Field("denoising_quality", EnumProperty, None, dict(
        name="Quality", description="The denoiser's quality (its network's size)",
        items=[("HIGH", "High", "Best detail, slowest", 1), ("BALANCED", "Balanced", "Between the two", 2),
               ("FAST", "Fast", "Quickest, for previews", 3)],
        default="HIGH")),
    Field("use_preview_denoising", BoolProperty, None, dict(
        name="Viewport Denoise", description="Denoise the Rendered viewport's Combined image each time its samples "
        "refine (off by default, as in Cycles)", default=False)),
    Field("processes", IntProperty, None, dict(
        name="Processes", description="Worker processes that render F12, animation frames and the Rendered "
        "viewport together, each with its share of the threads (Python runs one thread at a time per process, so "
        "processes use many cores where threads cannot). 0 = Auto: one per thread from 2 threads up (at most one "
        "per chunk of pixels: small frames and views render in Blender's own process; the viewport's header shows "
        "its count). "
        "The image is the same for any number", default=0, min=0, soft_max=64, max=1024)),
    Field("samples", IntProperty, int, dict(
        name="Samples", description="Iterations averaged per frame", default=16, min=1,
        soft_max=4096)),
    Field("time_limit", FloatProperty, float, dict(
        name="Time Limit", description="Seconds a render (each frame of an animation) or a still viewport may take: "
        "it stops after the sample that reaches the limit, with fewer samples than asked for (0 = no limit)",
        default=0.0, min=0.0, soft_max=3600.0, subtype="TIME_ABSOLUTE")),
    Field("use_adaptive_sampling", BoolProperty, bool, dict(
        name="Noise Threshold", description="Adaptive sampling, as Cycles': pixels whose noise estimate falls "
        "under the threshold stop taking samples, and the frame's work goes to the noisy ones (F12, animation and "
        "the viewport, up to its Samples)", default=True)),
    Field("adaptive_threshold", FloatProperty, float, dict(
        name="Noise Threshold", description="The noise level at which a pixel stops: its relative difference "
        "between all its samples and half of them (lower: less noise, more samples; 0 = automatic, 1/Samples)",
        default=0.01, min=0.0, max=1.0, soft_min=0.001, precision=4, step=0.1)),
    Field("adaptive_min_samples", IntProperty, int, dict(
        name="Min Samples", description="Samples every pixel takes before adaptive sampling may stop it "
        "(0 = automatic from the threshold: 64 at 0.01)", default=0, min=0, soft_max=4096)),
    Field("viewport_samples", IntProperty, None, dict(
        name="Viewport Samples", description="Samples the Rendered viewport accumulates "
        "for a still view before it stops", default=MAX_VIEWPORT_SAMPLES, min=1,
        soft_max=4096)),
    Field("viewport_budget_ms", IntProperty, None, dict(
        name="Navigation Budget (ms)", description="Time the first image after a view "
        "change may take: while the view moves, the viewport renders at 1/2, 1/4 "
        "or 1/8 resolution to stay under it, then refines at full resolution "
        "(0 = always full resolution)", default=int(DEFAULT_BUDGET * 1000), min=0,
        soft_max=2000)),
    Field("pixel_filter", EnumProperty, None, dict(
        name="Pixel Filter", description="How camera samples spread over neighbouring pixels (as Cycles' Film > "
        "Pixel Filter: samples are placed by the filter, each counting in its own pixel)",
        items=[("BOX", "Box", "Each sample counts for its own pixel only (sharpest, most aliasing)", 0),
               ("GAUSSIAN", "Gaussian", "A Gaussian of the given width (standard deviation: a quarter of it)", 1),
               ("BLACKMAN_HARRIS", "Blackman-Harris", "The Blackman-Harris window (Cycles' default): less "
                "blur than a Gaussian for the same noise", 2)],
        default="BLACKMAN_HARRIS")),
    Field("filter_width", FloatProperty, None, dict(
        name="Width", description="Pixel filter width in pixels (the Box filter is always one pixel)",
        default=1.5, min=0.01, soft_max=10.0, subtype="PIXEL")),
    Field("seed", IntProperty, int, dict(
        name="Seed", description="Noise pattern; different seeds give independent noise", default=0,
        min=0)),
    Field("max_bounces", IntProperty, int, dict(
        name="Max Bounces", description="Indirect bounces (0 = direct light only)",
        default=4, min=0, soft_max=32, max=1024)),
    Field("indirect_method", EnumProperty, str, dict(
        name="Indirect Method",
        description="How the ReSTIR integrator estimates indirect light (bounces) at the first hit",
        items=[("AUTO", "Auto", "ReSTIR GI where its reservoirs carry most of the indirect light's noise, path "
                "tracing where they cannot (measured in each frame's first pass; the choice and its reason show "
                "below)", 3),
               ("OFF", "Off", "No indirect light (direct light only, whatever Max Bounces says)", 0),
               ("PATH", "Path Tracing", "One path per pixel and sample, as the path tracer", 1),
               ("RESTIR_GI", "ReSTIR GI", "Resample the first bounce: each pixel's path finds a point x2 and the "
                "light leaving it; reservoirs of x2 points are reused over frames (temporal) and neighbouring "
                "pixels (spatial) with the reconnection shift. Glossy surfaces keep path-traced samples for "
                "their sharp lobes", 2)],
        default="AUTO", update=_update_passes)),
    Field("gi_spatial_neighbors", IntProperty, int, dict(
        name="Neighbors", description="Neighbouring GI reservoirs merged per spatial "
        "pass (unbiased mode: one visibility ray each)",
        default=GISettings.neighbors, min=0, soft_max=16)),
    Field("gi_spatial_radius", FloatProperty, float, dict(
        name="Radius", description="GI spatial reuse radius in pixels; 0 = automatic: "
        "0.75 x the direct light's (6 px at 640x360, scaled with the image diagonal, 4 px at least)",
        default=GISettings.radius, min=0.0, soft_max=100.0, subtype="PIXEL")),
    Field("gi_spatial_passes", IntProperty, int, dict(
        name="Passes", description="GI spatial reuse passes",
        default=GISettings.passes, min=0, soft_max=4)),
    Field("gi_confidence_cap", FloatProperty, float, dict(
        name="Confidence Cap", description="Largest confidence M a reused GI "
        "reservoir keeps", default=GISettings.confidence_cap, min=1.0, soft_max=100.0)),
    Field("gi_max_age", IntProperty, int, dict(
        name="Max Sample Age", description="Frames a GI sample may be carried by temporal "
        "reuse before it is dropped (its cached radiance ages while objects move; any change "
        "of the lights drops the whole GI history at once)", default=GISettings.max_age, min=0,
        soft_max=100)),
    Field("gi_roughness_threshold", FloatProperty, float, dict(
        name="Roughness Threshold", description="Below this roughness a surface's specular lobe is too sharp to "
        "reconnect: seen by the camera, only its diffuse lobe is resampled (the specular keeps its path-traced "
        "sample). Light leaving a bounce's surface is always split: only its diffuse part is cached for reuse",
        default=GISettings.roughness_threshold, min=0.0, max=1.0)),
)


class RestirSceneSettings(bpy.types.PropertyGroup):
    __annotations__ = {f.name: f.prop(**f.kwargs) for f in SCENE_FIELDS}


def scene_settings_to_core(s) -> dict:
    """{RenderSettings field: value} of the scene settings ``s`` (``scene.restir``) the core reads."""
    return {f.name: f.to_core(getattr(s, f.name)) for f in SCENE_FIELDS if f.to_core is not None}


class RestirViewLayerSettings(bpy.types.PropertyGroup):
    use_pass_direct: BoolProperty(name="Direct", description="Direct lighting (one bounce) as its own pass",
                                  default=False, update=_update_passes)
    use_pass_indirect: BoolProperty(name="Indirect", description="Indirect lighting (two or more bounces)",
                                    default=False, update=_update_passes)
    use_pass_emission: BoolProperty(name="Emission", description="Emission seen directly by the camera",
                                    default=False, update=_update_passes)
    use_pass_reservoir_m: BoolProperty(name="Reservoir M", description="Confidence M of the shaded reservoir "
                                       "(ReSTIR integrator with RIS)", default=False, update=_update_passes)
    use_pass_reservoir_ucw: BoolProperty(name="Reservoir UCW", description="Unbiased contribution weight W of the "
                                         "shaded reservoir (ReSTIR integrator with RIS)", default=False,
                                         update=_update_passes)
    use_pass_gi_reservoir_m: BoolProperty(name="GI Reservoir M", description="Confidence M of the shaded ReSTIR GI "
                                          "reservoir (Indirect Method ReSTIR GI)", default=False, update=_update_passes)
    use_pass_gi_reservoir_ucw: BoolProperty(name="GI Reservoir UCW", description="Unbiased contribution weight W "
                                            "(m²) of the shaded ReSTIR GI reservoir (Indirect Method ReSTIR GI)",
                                            default=False, update=_update_passes)
    use_pass_denoising_data: BoolProperty(name="Denoising Data", description="Denoising Albedo and Denoising Normal "
                                          "(first hit's albedo and camera-space normal, averaged over the samples), "
                                          "for a compositor's Denoise node, and Noisy Image (Combined before "
                                          "denoising) with Denoise on", default=False, update=_update_passes)
    use_pass_sample_count: BoolProperty(name="Sample Count", description="Samples each pixel took (with adaptive "
                                        "sampling, Render Properties > Sampling > Noise Threshold)", default=False,
                                        update=_update_passes)
    use_pass_shadow_catcher: BoolProperty(name="Shadow Catcher", description="The light shadow catcher objects "
                                          "receive with the other objects over what they would receive without them "
                                          "(multiply a background plate by it); Combined then leaves the catchers "
                                          "transparent", default=False, update=_update_passes)


class RestirViewShadingSettings(bpy.types.PropertyGroup):
    """Per 3D view: what its Rendered shading shows (``View3DShading.restir``)."""

    render_pass: EnumProperty(name="Render Pass", description="Pass shown by the Rendered viewport",
                              items=[(key, label, desc) for key, label, desc in VIEWPORT_PASSES], default="COMBINED")


CLASSES = (RestirSceneSettings, RestirViewLayerSettings, RestirViewShadingSettings)


def register():
    for cls in CLASSES:
        bpy.utils.register_class(cls)
    bpy.types.Scene.restir = PointerProperty(type=RestirSceneSettings)
    bpy.types.ViewLayer.restir = PointerProperty(type=RestirViewLayerSettings)
    bpy.types.View3DShading.restir = PointerProperty(type=RestirViewShadingSettings)


def unregister():
    del bpy.types.View3DShading.restir
    del bpy.types.ViewLayer.restir
    del bpy.types.Scene.restir
    for cls in reversed(CLASSES):
        bpy.utils.unregister_class(cls)
