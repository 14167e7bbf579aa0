"""The AUTO direct-light method: light sampling (NEE + MIS) where resampling cannot pay for itself, ReSTIR DI
elsewhere. Chosen from scripts/benchmark_direct_methods.py (docs/RESULTS.md, "Choosing the direct-light
method"): efficiency 1 / (relMSE x time) of each method on the harness scenes at 320x180.

- Point and spot lamps only, a few of them: their cone sampling is close to the best a light sampler can do
  (the default cube: light sampling 3-7x more efficient than RIS or ReSTIR).
- A few lights and indirect bounces: the path-traced indirect light holds most of the noise, so the cheaper
  direct estimator wins (1.7-2.5x on the Cornell box, the GI room and the glossy street at 4 bounces).
- Otherwise (many lights, or a few area/mesh emitters lighting the scene directly): ReSTIR DI (1.2-4x over
  light sampling on those scenes with direct light only).
"""
from __future__ import annotations

FEW_LIGHTS = 8  # light entries (emissive triangles, lamps; a point/spot sphere is one) counted as "a few"


def choose_direct_method(lights, reservoir_passes: bool = False, max_bounces: int = 0) -> tuple[str, str]:
    """(method, reason) for a lights.LightTable: "LIGHT_SAMPLING" or "RESTIR", and why, in words for the UI.
    ``reservoir_passes``: a reservoir pass is to be written, which only resampling produces."""
    if reservoir_passes:
        return "RESTIR", "a reservoir pass is enabled"
    count = int(lights.n_tri)
    plural = "s" if count != 1 else ""
    if count == 0:
        return "LIGHT_SAMPLING", "no lights to resample (suns and the world only)"
    if count > FEW_LIGHTS:
        return "RESTIR", f"{count} lights: resampling picks the ones that matter"
    spheres = int((lights.sphere_r[:count] > 0).sum())
    if spheres == count:
        return "LIGHT_SAMPLING", f"{count} point/spot lamp{plural}: sampled by their cone, nothing to gain"
    if max_bounces > 0:
        return "LIGHT_SAMPLING", f"{count} light{plural} and {max_bounces} bounces: the indirect light holds " \
                                 "most of the noise, the cheaper direct estimator wins"
    return "RESTIR", f"{count} area light{plural}, direct light only: resampling pays"
