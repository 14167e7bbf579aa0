"""Render presets (Sampling panel): one click sets the ReSTIR settings to a tested combination."""
from __future__ import annotations

import bpy
from bpy.props import EnumProperty

from .core.restir.gi import GISettings
from .core.restir.reuse import SpatialSettings, TemporalSettings

# ReSTIR GI at its measured defaults (docs/RESULTS.md, "ReSTIR GI")
_GI = {"indirect_method": "RESTIR_GI", "gi_spatial_neighbors": GISettings.neighbors,
       "gi_spatial_radius": GISettings.radius, "gi_spatial_passes": GISettings.passes,
       "gi_confidence_cap": GISettings.confidence_cap, "gi_max_age": GISettings.max_age,
       "gi_roughness_threshold": GISettings.roughness_threshold}

PRESETS = {
    "FAST": {"integrator": "RESTIR", "direct_method": "RESTIR", "samples": 4, "light_candidates": 8,
             "bsdf_candidates": 1, "temporal_reuse": True, "confidence_cap": TemporalSettings.confidence_cap, "spatial_neighbors": 3,
             "preroll_frames": 2, "spatial_radius": SpatialSettings.radius, "spatial_passes": 1, "bias_correction": "NONE",
             "light_tiles": "AUTO", "boiling_filter": True, **_GI},
    "BALANCED": {"integrator": "RESTIR", "direct_method": "RESTIR", "samples": 16, "light_candidates": 32,
                 "bsdf_candidates": 1, "temporal_reuse": True, "confidence_cap": TemporalSettings.confidence_cap, "spatial_neighbors": 5,
                 "spatial_radius": SpatialSettings.radius, "spatial_passes": 1, "bias_correction": "NONE", "light_tiles": "AUTO",
                 "boiling_filter": False, **_GI},
    "UNBIASED": {"integrator": "RESTIR", "direct_method": "RESTIR", "samples": 16, "light_candidates": 32,
                 "bsdf_candidates": 1, "temporal_reuse": True, "confidence_cap": TemporalSettings.confidence_cap, "spatial_neighbors": 5,
                 "spatial_radius": SpatialSettings.radius, "spatial_passes": 1, "bias_correction": "UNBIASED",
                 "light_tiles": "AUTO", "boiling_filter": False, **_GI},
    "REFERENCE": {"integrator": "PATH", "samples": 256},
}


def apply_preset(settings, name: str) -> None:
    for key, value in PRESETS[name].items():
        setattr(settings, key, value)


PRESET_ITEMS = [
    ("FAST", "Fast", "Biased ReSTIR DI + GI, 8 light candidates, 3 neighbours, boiling filter, 4 samples"),
    ("BALANCED", "Balanced", "Biased ReSTIR DI + GI (1/M), 32 candidates, 5 neighbours, 16 samples"),
    ("UNBIASED", "Unbiased", "Unbiased ReSTIR DI + GI (pairwise MIS): converges to the path tracer"),
    ("REFERENCE", "Reference", "The path tracer at 256 samples")]


class RESTIR_OT_apply_preset(bpy.types.Operator):
    """Set the ReSTIR render settings to a preset"""

    bl_idname = "restir.apply_preset"
    bl_label = "Apply ReSTIR Preset"
    bl_options = {"REGISTER", "UNDO"}

    preset: EnumProperty(items=PRESET_ITEMS)

    def execute(self, context):
        apply_preset(context.scene.restir, self.preset)
        return {"FINISHED"}


def register():
    bpy.utils.register_class(RESTIR_OT_apply_preset)


def unregister():
    bpy.utils.unregister_class(RESTIR_OT_apply_preset)
