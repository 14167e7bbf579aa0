"""What runs for these settings and this scene: the frame's integrator methods and their stage settings.

One place answers it for the renderer and for the Blender glue (engine, passes, panels): the bounces the paths take,
whether ReSTIR GI can run at all (:func:`gi_possible`), the direct method (AUTO: method_choice) with its candidates
and the world's treatment, and the spatial reuse settings of DI and GI. Radii are in pixels of the render.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..integrators.method_choice import choose_direct_method, choose_world_method
from ..lights.tiles import TileSettings
from ..modes import DirectMethod, IndirectMethod, Integrator, WorldMethod
from ..restir import di, gi, reuse

GI_RADIUS_FACTOR = 0.75  # the automatic GI spatial radius against DI's (docs/RESULTS.md, "ReSTIR GI")


def bounces(st) -> int:
    """Bounces the paths take: max_bounces, or 0 where the ReSTIR integrator's indirect light is off."""
    return 0 if st.integrator == Integrator.RESTIR and st.indirect_method == IndirectMethod.OFF else int(st.max_bounces)


def gi_possible(st) -> bool:
    """Whether ReSTIR GI may run for settings ``st`` (any object with RenderSettings' field names): the ReSTIR
    integrator with Indirect Method ReSTIR GI or Auto and at least one bounce."""
    return st.integrator == Integrator.RESTIR and st.indirect_method in (IndirectMethod.RESTIR_GI, IndirectMethod.AUTO) \
        and bounces(st) > 0


def gi_auto(st) -> bool:
    """Whether the Auto indirect method measures and chooses (not when a GI reservoir pass is wanted: then GI runs)."""
    return st.integrator == Integrator.RESTIR and st.indirect_method == IndirectMethod.AUTO and bounces(st) > 0 and \
        not st.gi_reservoir_passes


def tile_settings(st) -> TileSettings:
    return TileSettings(st.light_tiles, st.light_tile_count, st.light_tile_size)


@dataclass(frozen=True)
class DirectChoice:
    """The direct method (di.DIRECT_METHODS or "PATH" for the path tracer) and why; its candidate settings where
    the direct light is resampled (None otherwise); the world's treatment ("RESAMPLED" or "LIGHT_SAMPLED") and why."""

    method: str
    reason: str
    candidates: di.CandidateSettings | None
    world_method: str
    world_reason: str


def choose_direct(st, lights, n_bounces: int, gi_takes_indirect: bool) -> DirectChoice:
    """The direct method for settings ``st`` and light table ``lights`` (AUTO: method_choice.choose_direct_method,
    knowing whether ReSTIR GI takes the indirect light)."""
    if st.integrator != Integrator.RESTIR:
        return DirectChoice("PATH", "path tracer", None, WorldMethod.LIGHT_SAMPLED, "the direct light is not resampled")
    method, reason = st.direct_method, "set by the user"
    if method == DirectMethod.AUTO:
        method, reason = choose_direct_method(lights, st.reservoir_passes, n_bounces, gi_takes_indirect)
    if method not in (DirectMethod.RIS, DirectMethod.RESTIR):
        return DirectChoice(method, reason, None, WorldMethod.LIGHT_SAMPLED, "the direct light is not resampled")
    world_method, world_reason = choose_world_method(lights, st.world_method)
    if world_method == WorldMethod.RESAMPLED and st.world_candidates <= 0:
        world_method, world_reason = WorldMethod.LIGHT_SAMPLED, "World Candidates is 0"
    candidates = di.CandidateSettings(method, max(0, st.light_candidates), max(0, st.bsdf_candidates),
                                      tile_settings(st),
                                      world_candidates=max(0, st.world_candidates) if world_method == WorldMethod.RESAMPLED
                                      else 0)
    return DirectChoice(method, reason, candidates, world_method, world_reason)


def spatial_settings(st, camera) -> reuse.SpatialSettings:
    """DI spatial reuse: the settings' neighbours, passes and bias correction; radius 0 = reuse.auto_radius."""
    radius = float(st.spatial_radius) if st.spatial_radius > 0 else reuse.auto_radius(camera.width, camera.height)
    return reuse.SpatialSettings(max(0, st.spatial_neighbors), max(1.0, radius), max(0, st.spatial_passes),
                                 st.bias_correction)


def gi_settings(st, camera) -> tuple[gi.GISettings, reuse.SpatialSettings]:
    """ReSTIR GI's settings and its spatial reuse's; radius 0 = GI_RADIUS_FACTOR x DI's automatic radius (at least
    reuse.AUTO_RADIUS_MIN)."""
    radius = float(st.gi_spatial_radius) if st.gi_spatial_radius > 0 else \
        max(reuse.AUTO_RADIUS_MIN, GI_RADIUS_FACTOR * reuse.auto_radius(camera.width, camera.height))
    g = gi.GISettings(max(0, int(st.gi_spatial_neighbors)), max(1.0, radius), max(0, int(st.gi_spatial_passes)),
                      float(st.gi_confidence_cap), max(0, int(st.gi_max_age)), float(st.gi_roughness_threshold))
    return g, reuse.SpatialSettings(g.neighbors, g.radius, g.passes, st.bias_correction)


def resamples_direct(st) -> bool:
    """Whether the direct light may come from reservoirs (RIS or ReSTIR; Auto resamples where it pays or a reservoir
    pass is asked for)."""
    return st.integrator == Integrator.RESTIR and st.direct_method in (DirectMethod.AUTO, DirectMethod.RIS,
                                                                      DirectMethod.RESTIR)


def reuses_direct(st) -> bool:
    """Whether the DI reservoirs may be reused over frames and pixels (ReSTIR, or Auto choosing it)."""
    return st.integrator == Integrator.RESTIR and st.direct_method in (DirectMethod.RESTIR, DirectMethod.AUTO)


def keeps_history(st) -> bool:
    """Whether a frame may leave a temporal history for the next (DI or GI reservoirs with temporal reuse)."""
    return bool(st.temporal_reuse) and (reuses_direct(st) or gi_possible(st))
