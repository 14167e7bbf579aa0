"""The AUTO direct-light method: light sampling (NEE + MIS) where the scene has few emitters, ReSTIR DI where
resampling pays. Measured by scripts/benchmark_direct_methods.py (docs/RESULTS.md, "Choosing the direct-light
method"): with a handful of lights one light sample per pixel is already close to the best a light sampler
can do, and ReSTIR's candidates, reuse and bookkeeping cost more than the noise they remove."""
from __future__ import annotations

FEW_LIGHTS = 8  # light entries (emissive triangles, lamps; a point/spot sphere is one) up to which NEE wins


def choose_direct_method(lights, reservoir_passes: bool = False) -> tuple[str, str]:
    """(method, reason) for a lights.LightTable: "LIGHT_SAMPLING" or "RESTIR", and why, in words for the UI.
    ``reservoir_passes``: a reservoir pass is to be written, which only resampling produces."""
    if reservoir_passes:
        return "RESTIR", "a reservoir pass is enabled"
    count = int(lights.n_tri)
    suns = int(lights.n_sun)
    if count == 0:
        return "LIGHT_SAMPLING", f"no lights to resample ({suns} sun{'s' if suns != 1 else ''} only)"
    if count <= FEW_LIGHTS:
        return "LIGHT_SAMPLING", f"{count} light{'s' if count != 1 else ''}: light sampling is cheaper for " \
                                 f"the same error (ReSTIR pays from {FEW_LIGHTS + 1})"
    return "RESTIR", f"{count} lights: ReSTIR DI resamples them"
