"""The settings of one frame's render (plain values; the Blender add-on fills them from ``scene.restir``).

Enumerated settings are strings: integrator INTEGRATORS; direct_method di.DIRECT_METHODS; indirect_method
gi.INDIRECT_METHODS; world_method method_choice.WORLD_METHODS; light_tiles tiles.TILE_MODES; bias_correction
reuse.BIAS_CORRECTIONS. :func:`validate` rejects unknown values with the list of known ones.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..integrators.method_choice import WORLD_METHODS
from ..lights.tiles import TILE_MODES, TileSettings
from ..modes import Integrator, LightSampler, values
from ..restir import di, gi, reuse
from ..restir.boiling import THRESHOLD as BOILING_THRESHOLD
from .work import CHUNK_PIXELS

INTEGRATORS = values(Integrator)
LIGHT_SAMPLERS = values(LightSampler)


@dataclass
class RenderSettings:
    """samples: sample passes averaged per frame; seed: noise seed; max_bounces: 0 = direct only;
    frame: frame number (keys the random streams). Stage defaults come from the stages' own settings
    (di.CandidateSettings, reuse.SpatialSettings, TileSettings)."""

    samples: int = 16
    time_limit: float = 0.0  # seconds a frame may render before it stops after the pass that ran past it; 0 = none
    use_adaptive_sampling: bool = False  # pixels whose noise estimate fell under the threshold stop (adaptive.py)
    adaptive_threshold: float = 0.01  # the Noise Threshold; 0 = automatic (adaptive.threshold_for)
    adaptive_min_samples: int = 0  # samples before the first check; 0 = automatic (adaptive.min_samples_for)
    seed: int = 0
    max_bounces: int = 4
    frame: int = 0
    integrator: str = "PATH"
    direct_method: str = "RIS"  # with integrator RESTIR: "AUTO", "LIGHT_SAMPLING" (NEE + MIS), "RIS" or "RESTIR"
    reservoir_passes: bool = False  # a reservoir pass is wanted (AUTO then resamples: method_choice)
    light_candidates: int = di.CandidateSettings.light_candidates
    bsdf_candidates: int = di.CandidateSettings.bsdf_candidates
    world_method: str = "AUTO"  # the world with resampled direct light: "AUTO", "RESAMPLED", "LIGHT_SAMPLED"
    world_candidates: int = di.CandidateSettings.world_candidates
    spatial_neighbors: int = reuse.SpatialSettings.neighbors
    spatial_radius: float = reuse.SpatialSettings.radius  # pixels; 0 = automatic (reuse.auto_radius)
    spatial_passes: int = reuse.SpatialSettings.passes
    bias_correction: str = reuse.SpatialSettings.bias_correction  # "NONE" (1/M) or "UNBIASED" (pairwise MIS)
    temporal_reuse: bool = True  # ReSTIR: pass 0 of a frame reuses pass 0 of the previous frame (history)
    confidence_cap: float = reuse.TemporalSettings.confidence_cap
    boiling_filter: bool = False  # bias_correction NONE only: drop reservoirs far above their block's mean
    boiling_threshold: float = BOILING_THRESHOLD  # x the 16x16 block's mean p̂·W (core.boiling)
    light_tiles: str = TileSettings.mode  # light candidates from presampled tiles: "AUTO", "ON", "OFF"
    light_tile_count: int = TileSettings.count
    light_tile_size: int = TileSettings.size
    light_sampler: str = "SPATIAL"  # light tiles: "SPATIAL" (per-block importance, light_blocks.py) or "POWER"
    film_transparent: bool = False
    data_passes: bool = True  # Depth, Normal and Vector (one more ray per pixel and frame); off when not written
    denoise_data: bool = False  # Denoising Albedo / Normal: first-hit albedo and camera-space normal, per sample
    shadow_catcher_pass: bool = False  # a Shadow Catcher pass is written (Combined then leaves catchers transparent)
    tile_pixels: int = CHUNK_PIXELS  # pixels per chunk of work (smaller: finer progress and cancellation)
    sample_batch: int = 0  # samples a pass renders at once where it can (plan.batch_size); 0 = automatic
    coverage_samples: int = 0  # camera rays per pixel for the emission seen directly: 1, 4, 9, 16 ...; 0 = automatic
    indirect_method: str = "PATH"  # with integrator RESTIR: "AUTO" (method_choice), "OFF" (no bounces), "PATH" or
    #                                "RESTIR_GI" (restir/gi.py)
    gi_reservoir_passes: bool = False  # a GI reservoir pass is wanted (AUTO then resamples the indirect light)
    gi_spatial_neighbors: int = gi.GISettings.neighbors
    gi_spatial_radius: float = gi.GISettings.radius  # pixels; 0 = automatic (GI_RADIUS_FACTOR x reuse.auto_radius)
    gi_spatial_passes: int = gi.GISettings.passes
    gi_confidence_cap: float = gi.GISettings.confidence_cap
    gi_max_age: int = gi.GISettings.max_age  # frames a GI sample may be reused for
    gi_roughness_threshold: float = gi.GISettings.roughness_threshold
    gi_target: str = "INTEGRAND"  # GI target function (gi.GI_TARGETS); the alternative serves measurements only


def validate(st: RenderSettings) -> None:
    """Raise ValueError naming the setting and the known values when an enumerated setting is unknown."""
    def check(name, value, known):
        if value not in known:
            raise ValueError(f"unknown {name} {value!r}; available: {known}")
    check("integrator", st.integrator, INTEGRATORS)
    if st.integrator != "RESTIR":
        return
    check("direct method", st.direct_method, di.DIRECT_METHODS)
    check("indirect method", st.indirect_method, gi.INDIRECT_METHODS)
    check("light tile mode", st.light_tiles, TILE_MODES)
    check("bias correction", st.bias_correction, reuse.BIAS_CORRECTIONS)
    check("world method", st.world_method, WORLD_METHODS)
