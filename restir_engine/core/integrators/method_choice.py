"""The AUTO methods of the ReSTIR integrator, with the reason shown in the UI. Chosen from measurements:
scripts/bench.py direct_methods (docs/RESULTS.md, "Choosing the direct-light method") and
scripts/bench.py integrators ("Choosing the integrator per scene"): efficiency 1 / (relMSE x time) on the
harness scenes at 320x180.

Direct light (chosen when the frame starts):
- Point and spot lamps only, a few of them: their cone sampling is close to the best a light sampler can do
  (the default cube: light sampling 3-7x more efficient than RIS or ReSTIR).
- A few lights and path-traced bounces: the indirect light holds most of the noise, so the cheaper direct
  estimator wins (1.7-2.5x on the Cornell box, the GI room and the glossy street at 4 bounces).
- A few area lights and bounces that ReSTIR GI resamples: GI takes the indirect noise away and the direct light's
  is what is left, so ReSTIR DI pays again (Cornell box 1.4x over light sampling with GI).
- Otherwise (many lights, or a few area/mesh emitters lighting the scene directly): ReSTIR DI (1.2-4x over
  light sampling on those scenes with direct light only).
- No lights but an environment image: ReSTIR DI with the world in its reservoirs where the direct light is what is
  left (direct only, or with ReSTIR GI), light sampling beside path-traced bounces
  (scripts/bench.py world_reservoirs).

Indirect light (measured in the first sample pass of every frame, from the path-traced first bounces):
- ReSTIR GI caches the diffuse light leaving the first bounce's point x2; light it cannot hold (off glossy and
  specular x2, caustics through glass, sharp lobes at x1) keeps its path-traced noise. It pays where the
  reservoirs carry most of the indirect light's noise (rooms lit by bounce light: 3-30x over path tracing at equal
  time) and costs 2.5-4x per sample for nothing where they do not (the default cube's bounces meet only the
  world; glass spheres and glossy streets: 0.3-0.5x).
"""
from __future__ import annotations

from ..modes import WorldMethod, values

FEW_LIGHTS = 8  # light entries (emissive triangles, lamps; a point/spot sphere is one) counted as "a few"
GI_MIN_SHARE = 0.05   # ReSTIR GI (even when set by the user) is skipped in a pass whose reservoirs would carry
#                       less of the path-traced indirect light (luminance): nothing to cache
GI_MAX_UNCACHED = 0.25  # AUTO: path tracing where more of the indirect light's second moment is in light the
#   reservoirs cannot hold. A GI sample costs about 3x a path-traced one (scripts/bench.py integrators), so GI must
#   remove over 2/3 of the indirect noise to win, and it never removes the uncached part's. Measured: the scenes
#   where GI wins read 0.00 (rooms, many lights), those where it loses 0.39-0.94 (glass, glossy street)


def choose_direct_method(lights, reservoir_passes: bool = False, max_bounces: int = 0,
                         gi_expected: bool = False) -> tuple[str, str]:
    """(method, reason) for a lights.LightTable: "LIGHT_SAMPLING" or "RESTIR", and why, in words for the UI.
    ``reservoir_passes``: a reservoir pass is to be written, which only resampling produces; ``gi_expected``:
    ReSTIR GI will resample the indirect light (the bounces' noise is not what is left)."""
    if reservoir_passes:
        return "RESTIR", "a reservoir pass is enabled"
    count = int(lights.n_tri)
    plural = "s" if count != 1 else ""
    if count == 0:
        env = getattr(lights, "env", None)
        if env is None or env.world.image is None:
            return "LIGHT_SAMPLING", "no lights to resample (suns and a constant world only)"
        if max_bounces > 0 and not gi_expected:
            return "LIGHT_SAMPLING", f"an environment image and {max_bounces} path-traced bounces: the indirect " \
                                     "light holds most of the noise, the cheaper direct estimator wins"
        return "RESTIR", "an environment image: its samples are resampled and reused across pixels and frames"
    if count > FEW_LIGHTS:
        return "RESTIR", f"{count} lights: resampling picks the ones that matter"
    spheres = int((lights.sphere_r[:count] > 0).sum())
    if spheres == count:
        return "LIGHT_SAMPLING", f"{count} point/spot lamp{plural}: sampled by their cone, nothing to gain"
    if max_bounces > 0 and not gi_expected:
        return "LIGHT_SAMPLING", f"{count} light{plural} and {max_bounces} bounces: the indirect light holds " \
                                 "most of the noise, the cheaper direct estimator wins"
    if max_bounces > 0:
        return "RESTIR", f"{count} area light{plural}, indirect light by ReSTIR GI: the direct light's noise " \
                         "is what is left, resampling pays"
    return "RESTIR", f"{count} area light{plural}, direct light only: resampling pays"


WORLD_METHODS = values(WorldMethod)


def choose_world_method(lights, setting: str = "AUTO") -> tuple[str, str]:
    """(method, reason) for how resampled direct light treats the world: "RESAMPLED" (its samples in the ReSTIR DI
    reservoirs, world_points.py) or "LIGHT_SAMPLED" (one light sample per shaded point beside them). A reservoir
    keeps one sample for all its lights, so a world that shares the direct light with lamps or emitters adds the
    choice between them to the noise (scripts/bench.py world_reservoirs: a constant world with three lamps 3x
    the relMSE, an environment image with three lamps even to 2x worse); an environment image that is the only
    light gains from reuse (1.1-1.6x over light sampling at equal time, 2.5-3.8x over the world light-sampled
    beside the reservoirs)."""
    env = getattr(lights, "env", None)
    if env is None:
        return "LIGHT_SAMPLED", "the world gives no light"
    if setting != "AUTO":
        return setting, "set by the user"
    if env.world.image is None:
        return "LIGHT_SAMPLED", "a constant world: its cosine sample is already close to the best"
    if int(lights.n_tri) > 0:
        return "LIGHT_SAMPLED", "an environment image beside other lights: separate samples are less noisy"
    return "RESAMPLED", "an environment image, the only light: its samples are resampled and reused"


def choose_indirect_method(share: float, uncached: float) -> tuple[str, str]:
    """(method, reason) for AUTO: "RESTIR_GI" or "PATH" from a sample pass's path-traced first bounces.
    ``share``: the part of the indirect light (luminance sum) the GI reservoirs would carry; ``uncached``: the part
    of its second moment (sum over pixels of luminance squared) in the light they cannot carry (a proxy of its
    variance share: the indirect estimates' variance dwarfs their mean square)."""
    if share < GI_MIN_SHARE:
        return "PATH", "almost no bounce light to cache"
    if uncached > GI_MAX_UNCACHED:
        return "PATH", f"{uncached:.0%} of the indirect light's noise is specular or caustic light ReSTIR GI " \
                       "cannot cache"
    return "RESTIR_GI", f"{share:.0%} of the indirect light is cached by ReSTIR GI"
