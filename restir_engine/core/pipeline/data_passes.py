"""Depth, Normal and Vector at pixel centres: one camera ray per pixel, so depths do not mix at silhouettes (as
Cycles). Depth (h, w, 1) is planar distance along the camera axis in metres, Normal (h, w, 3) the world-space shading
normal, Vector (h, w, 4) Blender's motion vectors in pixels; row 0 at the bottom."""
from __future__ import annotations

import numpy as np

from ..integrators import camera_paths
from ..parallel.pool import pool


def tiles(w: int, h: int, tile_pixels: int):
    """Square-ish tiles (x, y, tw, th) covering a w x h window."""
    side = max(8, int(np.sqrt(max(tile_pixels, 64))))
    return [(x, y, min(side, w - x), min(side, h - y)) for y in range(0, h, side) for x in range(0, w, side)]


def render_data_passes(ctx, tile_pixels: int):
    """(Depth, Normal, Vector) of the camera window of ``ctx.scene.camera``."""
    x0, y0, w, h = ctx.scene.camera.window
    depth = np.empty((h, w, 1), np.float32)
    normal = np.empty((h, w, 3), np.float32)
    vector = np.empty((h, w, 4), np.float32)

    def gbuffer_tile(tile):
        tx, ty, tw, th = tile
        cy, cx = np.mgrid[0:th, 0:tw]
        dep, nrm, vec = camera_paths.gbuffer(ctx, (x0 + tx + cx.ravel() + 0.5).astype(np.float32),
                                           (y0 + ty + cy.ravel() + 0.5).astype(np.float32))
        depth[ty:ty + th, tx:tx + tw] = dep.reshape(th, tw, 1)
        normal[ty:ty + th, tx:tx + tw] = nrm.reshape(th, tw, 3)
        vector[ty:ty + th, tx:tx + tw] = vec.reshape(th, tw, 4)

    list(pool().map(gbuffer_tile, tiles(w, h, tile_pixels)))
    return depth, normal, vector
