"""Statistics for comparing stochastic renders: z-scores from independent repetitions."""
from __future__ import annotations

import numpy as np


def block_means(images: np.ndarray, blocks: int) -> np.ndarray:
    """(k, h, w, c) repetitions -> (k, blocks*blocks + 1) luminance-free channel-mean per block,
    with the whole image as the last column."""
    k, h, w = images.shape[:3]
    flat = images.reshape(k, h, w, -1).mean(axis=3)
    ys = np.linspace(0, h, blocks + 1).astype(int)
    xs = np.linspace(0, w, blocks + 1).astype(int)
    cols = [flat[:, ys[i]:ys[i + 1], xs[j]:xs[j + 1]].mean(axis=(1, 2)) for i in range(blocks) for j in range(blocks)]
    cols.append(flat.mean(axis=(1, 2)))
    return np.stack(cols, axis=1)


def compare(ours: np.ndarray, ref: np.ndarray, blocks: int = 2):
    """z-scores (Welch) of the difference of block means between two sets of independent
    repetitions, and the standard error of the difference relative to the reference mean.
    Returns (z (b,), mean_ours (b,), mean_ref (b,), rel_se (b,))."""
    a = block_means(ours, blocks)
    b = block_means(ref, blocks)
    ma, mb = a.mean(axis=0), b.mean(axis=0)
    se = np.sqrt(a.var(axis=0, ddof=1) / len(a) + b.var(axis=0, ddof=1) / len(b))
    z = (ma - mb) / np.maximum(se, 1e-12)
    return z, ma, mb, se / np.maximum(np.abs(mb), 1e-12)
