"""Which camera rays a pass traces: pixel coverage (strata per pixel for the emission seen directly) and the masks
of window pixels where a camera ray may meet geometry or a lamp (elsewhere it sees only the world).

Masks are (window pixels,) bool, row-major over the camera window, or None for "every pixel".
"""
from __future__ import annotations

import numpy as np

from ..geometry import camera as camera_mod

AUTO_COVERAGE = 4  # strata where the camera can see emitters
MANY_COVERAGE = 16  # ... and where it sees at least MANY_EMITTERS emissive triangles
MANY_EMITTERS = 4096


def coverage_samples(setting: int, lights, lamps, camera=None) -> tuple[int, str]:
    """Strata per pixel for the emission seen directly and why (:func:`coverage`)."""
    return coverage(setting, lights, lamps, camera)[:2]


def coverage(setting: int, lights, lamps, camera=None) -> tuple[int, str, np.ndarray | None]:
    """Strata per pixel for the emission seen directly (a square number) and why: ``setting`` rounded down to a
    square, or when 0 (automatic): 1 where the camera can see no emitter (none visible to camera rays, or, given
    the ``camera``, none inside its view); MANY_COVERAGE where it sees many emissive triangles (at least
    MANY_EMITTERS: small emitters partly covering many pixels), else AUTO_COVERAGE (docs/RESULTS.md, "Pixel
    coverage", has the measurements behind these). The third value: the pixels that get the extra rays
    (coverage_pixels; None: all of them)."""
    if setting > 0:
        g = max(1, int(np.sqrt(setting + 1e-9)))
        return g * g, "set by the user", None
    lamps_seen = bool(len(lamps.tris) and lamps.camera_visible.any())
    if lights.n_geom >= MANY_EMITTERS:
        return MANY_COVERAGE, f"{lights.n_geom} emissive triangles: small emitters partly cover many pixels", None
    if lights.n_geom > 0 or lamps_seen:
        mask = None if camera is None else coverage_pixels(camera, lights, lamps)
        if mask is not None and not mask.any():
            return 1, "no emitter in view", None
        return AUTO_COVERAGE, "emitters can be seen directly", mask
    return 1, "no emitter can be seen directly", None


GEOMETRY_MASK_MAX = 0.9  # the share of the window above which masking camera rays by object boxes is not worth it


def geometry_mask(ctx, camera) -> np.ndarray | None:
    """(window pixels,) bool: where a camera ray may meet geometry (the projected boxes of the instances,
    camera.box_pixels); elsewhere it sees only lamps and the world, and is not traced. None when it would mark
    most of the window anyway."""
    derived = ctx.geom_derived
    if derived is None or derived.boxes is None or not camera_mod.projected_masks_hold(camera):
        return None
    mask = camera_mod.box_pixels(camera, *derived.boxes).ravel()
    return None if mask.mean() > GEOMETRY_MASK_MAX else mask


def lamp_mask(ctx, camera) -> np.ndarray | None:
    """(window pixels,) bool: where a camera ray may see a lamp visible to camera rays (the projected boxes of their
    triangles and sphere proxies, camera.emitter_pixels); elsewhere lamps are not intersected. None when it would
    mark most of the window anyway."""
    lamps = ctx.scene.lamps
    if len(lamps.tris) == 0 or not camera_mod.projected_masks_hold(camera):
        return None
    vis = lamps.camera_visible
    mask = camera_mod.emitter_pixels(camera, lamps.tris.verts[vis], np.zeros((0, 3)), np.zeros(0)).ravel()
    return None if mask.mean() > GEOMETRY_MASK_MAX else mask


def _seen_lights(lights, lamps) -> np.ndarray:
    """(n_tri,) bool: the light entries camera rays can see (emissive triangles; lamps visible to the camera)."""
    seen = np.ones(lights.n_tri, bool)
    if len(lights.lamp_ids):
        seen[lights.n_geom:] = lamps.camera_visible[lights.lamp_ids]
    return seen


def coverage_pixels(camera, lights, lamps):
    """(h * w,) bool: the pixels near an emitter the camera can see, where the extra coverage rays pay (elsewhere
    the shaded ray's emission alone is the estimate: both unbiased); None (every pixel) from MANY_EMITTERS on."""
    if lights.n_geom >= MANY_EMITTERS or not camera_mod.projected_masks_hold(camera):
        return None
    v = lights.tri_verts
    seen = _seen_lights(lights, lamps)
    sph = lights.sphere_r > 0
    tri = seen & ~sph
    return camera_mod.emitter_pixels(camera, v[tri], v[seen & sph, 0], lights.sphere_r[seen & sph] * 1.001).ravel()
