"""Shadow catchers (Object > Visibility > Mask > Shadow Catcher), as Cycles renders them: a catcher object receives
the shadows and light of the other objects so that they can be composited over a photograph of the real ground.

Where a camera ray meets a catcher first, the sample is matte in Combined (black, alpha 0, like a holdout) and
the catcher's light is path-traced twice with the same random numbers: L_with, with every object, and L_without,
in a scene of the catchers alone (no other object shadows it or sends it light; lamps, emissive surfaces and the
world stay: they are the light). Per pixel, the Shadow Catcher pass is the ratio of their sums
over the samples, per channel (1 where no sample met a catcher): below 1 in shadow, above 1 where the objects
add light. Combined then follows Cycles:
  - with the Shadow Catcher pass written: the matte alone (catchers transparent);
  - else, on a transparent film: the matte with the shadow in alpha, alpha + (1 - alpha) · s,
    s = clamp(1 - mean(ratio), 0, 1);
  - else (an opaque film): the matte plus what the catcher hides, times 1 - s, alpha 1. What it hides is the
    world in the camera ray's direction (an object behind a catcher is not seen through it).
Camera rays that reach a catcher through smooth glass shade it as an ordinary surface.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..geometry.accel import Accel, SplitAccel
from ..integrators import pathtracer
from ..sampling import finite

MODES = ("PASS", "TRANSPARENT", "OPAQUE")


def catcher_triangles(scene) -> np.ndarray | None:
    """(n,) bool: the geometry triangles of shadow catcher objects, or None where there are none."""
    geom = scene.geometry
    objs = getattr(geom, "objects", None)
    flags = getattr(objs, "shadow_catcher", None)
    if flags is None or not flags.any() or geom.instance is None:
        return None
    tris = flags[geom.instance]
    return tris if tris.any() else None


@dataclasses.dataclass(frozen=True)
class Catchers:
    """The frame's shadow catchers: ``tris`` (n,) bool per geometry triangle, ``ctx`` the trace context of the
    catchers alone (an Embree scene of the catchers and the emissive triangles; the rest of the context shared)."""

    tris: np.ndarray
    ctx: object

    @staticmethod
    def of(ctx) -> "Catchers | None":
        tris = catcher_triangles(ctx.scene)
        if tris is None:
            return None
        keep = tris.copy()
        keep[ctx.lights.geom_ids] = True  # emissive triangles are lights: in both scenes (consistent MIS)
        rows = np.flatnonzero(keep)
        alone = SplitAccel(Accel(ctx.scene.geometry.verts[rows]), rows, np.zeros((0, 3, 3), np.float32),
                           np.zeros(0, np.int32))
        return Catchers(tris, dataclasses.replace(ctx, geom_accel=alone, groups=None))

    def hits(self, surf, chain=None) -> np.ndarray:
        """Indices of the camera hits ``surf`` on a catcher, met directly (not through glass: ``chain``)."""
        on = self.tris[surf.prim]
        if chain is not None:
            on &= chain.depth == 0
        return np.flatnonzero(on)

    def light_pair(self, full_ctx, surf, rng) -> tuple:
        """(L_with, L_without) (3, k) of the catcher surfaces ``surf``: the light leaving them toward the camera in
        the whole scene and in the scene of the catchers alone, path-traced with the same random numbers
        (``rng()`` gives a fresh generator of one stream), so that where no object is in the way the two agree
        sample by sample and the ratio of their sums is exactly 1."""
        return tuple(_path_traced(ctx, surf, rng()) for ctx in (full_ctx, self.ctx))


def _path_traced(ctx, surf, rng) -> np.ndarray:
    """The light (3, k) leaving surfaces ``surf`` toward the camera (next-event estimation, BSDF-sampled emission,
    bounces), as the path tracer estimates it in ``ctx``."""
    if len(surf) == 0:
        return np.zeros((3, 0), np.float32)
    out = pathtracer.next_event(ctx, surf, rng)
    if pathtracer.needs_continuation(ctx, False):
        paths = pathtracer.continue_paths(ctx, surf, rng)
        out = out + paths.direct + paths.indirect
    return finite(out)


def film_mode(settings, catchers: bool) -> str | None:
    """How Combined shows the catchers (module docstring): "PASS", "TRANSPARENT" or "OPAQUE"; None where the scene
    has no catchers and no Shadow Catcher pass is written (then the film keeps no catcher sums; with the pass and
    no catchers, the pass is 1 everywhere)."""
    if settings.shadow_catcher_pass:
        return "PASS"
    if not catchers:
        return None
    return "TRANSPARENT" if settings.film_transparent else "OPAQUE"


def matte(c, rows: np.ndarray) -> None:
    """The chunk's catcher surfaces ``rows`` out of its direct, indirect and light group estimates (the matte
    has none of their light)."""
    for name in ("direct", "indirect"):
        v = getattr(c, name)
        if v is not None:
            v[:, rows] = 0.0
    for name in ("direct_g", "indirect_g"):
        v = getattr(c, name)
        if v is not None:
            v[:, :, rows] = 0.0


def ratio(with_sum: np.ndarray, without_sum: np.ndarray) -> np.ndarray:
    """Per pixel and channel Σ L_with / Σ L_without, 1 where no light arrived without the objects."""
    ok = without_sum > 0
    return np.where(ok, with_sum / np.where(ok, without_sum, 1.0), 1.0).astype(np.float32)


def shadow(ratio_rgb: np.ndarray, covered: np.ndarray) -> np.ndarray:
    """s (h, w): the shadow's opacity, clamp(1 - mean(ratio), 0, 1) where a sample met a catcher, else 0."""
    return (np.clip(1.0 - ratio_rgb.mean(axis=-1), 0.0, 1.0) * (covered > 0)).astype(np.float32)
