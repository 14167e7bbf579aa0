"""Homogeneous absorption inside closed meshes (a material's Volume Absorption, MaterialTable.absorption).

A ray segment that ends on the back of a triangle (the ray leaving the mesh its geometric normal points out of) has
travelled inside that mesh; where its material absorbs, the light carried along the segment keeps
exp(−σa · t) per colour channel (t: the segment's length in scene units, σa per scene unit). Segments that end on
a front face, or escape, are outside any volume. Light is scene-linear RGB.
"""
from __future__ import annotations

import numpy as np

from ..sampling import cols, dot


def has_absorption(ctx) -> bool:
    """Whether any material of the scene absorbs inside its mesh."""
    a = getattr(ctx.scene.materials, "absorption", None)
    return a is not None and bool((a > 0).any())


def transmittance(ctx, prim: np.ndarray, t: np.ndarray, d: np.ndarray) -> np.ndarray | None:
    """(3, n) float32: what survives along rays of directions ``d`` (3, n) to their hits ``prim`` (n,) (-1: none)
    at distances ``t`` (n,); None where nothing absorbs (every factor 1)."""
    if not has_absorption(ctx):
        return None
    sigma = ctx.scene.materials.absorption
    out = np.ones((3, len(prim)), np.float32)
    hit = np.flatnonzero(prim >= 0)
    if hit.size == 0:
        return out
    p = prim[hit].astype(np.intp)
    s = sigma[ctx.scene.geometry.material[p]].T  # (3, k)
    inside = dot(cols(ctx.geom_ng_rows, p), cols(d, hit)) > 0  # leaving through the back: it travelled inside
    sel = np.flatnonzero(inside & (s.max(axis=0) > 0))
    if sel.size:
        out[:, hit[sel]] = np.exp(-cols(s, sel) * t[hit[sel]].astype(np.float32)[None, :])
    return out
