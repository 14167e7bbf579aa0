"""Fixed-seed before/after image comparison of every integrator on :func:`scenes_core.regression_room`.

``tests/data/regression_baseline.npz`` holds, per configuration, the block statistics of renders made
by the code *before* the core was restructured (commit 0e74da9, generated with
``python tests/regression.py``): for each of SEEDS seeds, the mean of the lit surfaces (Direct + Indirect) over a 4 x 4 grid of
blocks, plus the whole-image means of Emission, Direct and Indirect (64 x 48 pixels). A change that keeps the
estimators (only their random-number consumption and speed may change) must agree with it within noise:
Welch z-scores of independent repetitions (tests/core/test_regression_images.py).

Regenerate the baseline only when a change is *meant* to change the converged image (a material model fix,
say), with the code before that change, and say so in the commit: the test guards speed work, which must not.
"""
from __future__ import annotations

import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
BASELINE = os.path.join(HERE, "data", "regression_baseline.npz")
SEEDS = 32
BLOCKS = 4

CONFIGS = {
    "path": dict(integrator="PATH", max_bounces=2, samples=2),
    "restir": dict(integrator="RESTIR", direct_method="RESTIR", max_bounces=1, samples=1, light_candidates=8,
                   spatial_radius=8.0, frames=2),
    "restir_biased": dict(integrator="RESTIR", direct_method="RESTIR", bias_correction="NONE", boiling_filter=True,
                          light_tiles="ON", light_tile_count=8, light_tile_size=64, max_bounces=0, samples=1,
                          light_candidates=8, spatial_radius=8.0, spatial_passes=2, frames=2),
    "ris": dict(integrator="RESTIR", direct_method="RIS", max_bounces=0, samples=2, light_candidates=8),
    "light_sampling": dict(integrator="RESTIR", direct_method="LIGHT_SAMPLING", max_bounces=1, samples=2),
}


def block_stats(passes) -> np.ndarray:
    """(BLOCKS² + 3,) block means of the lit surfaces (Direct + Indirect, RGB mean), then whole-image means of
    Emission, Direct and Indirect. Surfaces and emission apart: the tiny bright emitter seen directly adds
    pixel-coverage noise that would hide a surface difference."""
    rgb = (passes["Direct"] + passes["Indirect"]).mean(axis=2)
    h, w = rgb.shape
    ys = np.linspace(0, h, BLOCKS + 1).astype(int)
    xs = np.linspace(0, w, BLOCKS + 1).astype(int)
    cols = [rgb[ys[i]:ys[i + 1], xs[j]:xs[j + 1]].mean() for i in range(BLOCKS) for j in range(BLOCKS)]
    cols += [passes["Emission"].mean(), passes["Direct"].mean(), passes["Indirect"].mean()]
    return np.array(cols, np.float64)


def render_stats(name: str, seed: int) -> np.ndarray:
    from restir_engine.core.renderer import RenderSettings, render_frame
    from scenes_core import regression_room

    cfg = dict(CONFIGS[name])
    frames = cfg.pop("frames", 1)
    scene = regression_room(64, 48)
    hist, r = None, None
    for f in range(frames):  # temporal reuse: the last frame reuses the one before
        r = render_frame(scene, RenderSettings(seed=seed, frame=f, data_passes=False, **cfg), history=hist)
        hist = r.history
    return block_stats(r.passes)


def render_all(name: str, seeds=range(SEEDS)) -> np.ndarray:
    return np.array([render_stats(name, 1000 + s) for s in seeds])


if __name__ == "__main__":
    sys.path.insert(0, os.path.dirname(HERE))
    sys.path.insert(0, HERE)
    out = {name: render_all(name) for name in CONFIGS}
    np.savez_compressed(BASELINE, **out)
    for name, a in out.items():
        print(name, a.mean(axis=0)[-3:], a.std(axis=0, ddof=1)[-3:] / np.sqrt(len(a)))
