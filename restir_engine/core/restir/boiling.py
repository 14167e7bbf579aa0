"""Boiling filter for biased ReSTIR DI: drop reservoirs whose weight stands far above their block's.

Temporal and spatial reuse copy a sample from pixel to pixel; a rare sample with a huge contribution
weight can spread over a neighbourhood and persist for frames ("boiling" blobs). The filter compares each
reservoir's contribution estimate p̂(y)·W (the unshadowed radiance luminance the pixel would shade, in
scene-linear units) with the mean of its 16x16 pixel block and empties the reservoir when it exceeds
``threshold`` times that mean. Its confidence M is kept, so the pixel's estimate is simply zero this pass.

This removes energy that an unbiased estimator needs: it is biased (darker) by construction and is only
applied with bias correction NONE.
"""
from __future__ import annotations

import numpy as np

BLOCK = 16  # pixels: the neighbourhood whose mean weight an outlier is compared with
THRESHOLD = 20.0  # default: x the block mean


def boiling_filter(res, pixels: np.ndarray, width: int, height: int, threshold: float) -> np.ndarray:
    """Empty (in place) the reservoirs of ``res`` (restir.reservoir.Reservoirs; reservoir i belongs to pixel
    ``pixels[i]`` of a width x height window, row-major) whose p̂·W exceeds ``threshold`` x the mean over the
    reservoirs of their block. Returns the boolean mask of dropped reservoirs."""
    weight = np.where(res.has_sample(), res.p_hat.astype(np.float64) * res.W, 0.0)
    pix = pixels
    bx, by = (pix % width) // BLOCK, (pix // width) // BLOCK
    blocks_x = (width + BLOCK - 1) // BLOCK
    block = by * blocks_x + bx
    n_blocks = blocks_x * ((height + BLOCK - 1) // BLOCK)
    total = np.bincount(block, weights=weight, minlength=n_blocks)
    count = np.bincount(block, minlength=n_blocks)
    mean = total / np.maximum(count, 1.0)
    drop = (weight > threshold * mean[block]) & (weight > 0)
    res.clear(drop)
    return drop
