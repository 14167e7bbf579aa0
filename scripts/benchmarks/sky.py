"""The Sky Texture's four models against Cycles: each model's whole sky (an equirectangular camera over the sphere,
nothing else) rendered by both engines; per model the mean ratio (the sun's cells left out: a disc of 0.5° in
1.4° pixels is found by few of 16 jittered samples, so those cells are mostly noise) and the median / 95th-percentile
relative difference of 8 x 8-pixel cells, and a picture (Cycles, ours, their relative difference).

    .venv313/bin/python scripts/bench.py sky [--out docs/results/sky]
"""
from __future__ import annotations

import argparse
import os

import numpy as np

from benchmarks.common import RESULTS, write_json

SKIES = [("MULTIPLE_SCATTERING", {"sun_elevation": 0.35, "sun_rotation": 1.0}),
         ("SINGLE_SCATTERING", {"sun_elevation": 0.35, "sun_rotation": 1.0}),
         ("PREETHAM", {"sun_direction": (0.3, -0.5, 0.6), "turbidity": 3.0}),
         ("HOSEK_WILKIE", {"sun_direction": (0.3, -0.5, 0.6), "turbidity": 3.0})]
SIZE, SAMPLES, CELL = (256, 128), 16, 8


def _cells(img):
    h, w, _ = img.shape
    return img.reshape(h // CELL, CELL, w // CELL, CELL, 3).mean(axis=(1, 3, 4))


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--out", default=os.path.join(RESULTS, "sky"))
    args = ap.parse_args()
    import restir_engine
    from bpy_scenes import configure_cycles, configure_restir, render_passes, sky_scene
    restir_engine.register()
    rows, images = [], []
    for model, settings in SKIES:
        pair = []
        for engine in ("CYCLES", "RESTIR"):
            scene = sky_scene(model, SIZE, "SEEN", **settings)
            if engine == "CYCLES":
                configure_cycles(scene, SAMPLES, 0, 0)
            else:
                configure_restir(scene, SAMPLES, 0, 0, integrator="PATH")
            pair.append(render_passes(scene)["Combined"][::-1, :, :3].astype(np.float64))
        ref, ours = pair
        c, o = _cells(ref), _cells(ours)
        lit = c > 1e-3
        rel = np.abs(o - c)[lit] / c[lit]
        sky = c < 100 * np.median(c)  # not the sun's cells
        rows.append({"model": model, "settings": settings, "mean_ratio": float(o[sky].mean() / c[sky].mean()),
                     "cell_rel_median": float(np.median(rel)), "cell_rel_p95": float(np.percentile(rel, 95))})
        print(f"{model:20s} mean ours/Cycles {rows[-1]['mean_ratio']:.4f}  cells: median {rows[-1]['cell_rel_median']:.5f}"
              f"  95th {rows[-1]['cell_rel_p95']:.4f}", flush=True)
        images.append((model, ref, ours))
    write_json(os.path.join(args.out, "sky.json"), {"size": SIZE, "samples": SAMPLES, "cell": CELL, "skies": rows})
    _chart(os.path.join(args.out, "sky.png"), images)


def _chart(path, images):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(len(images), 3, figsize=(12, 1.9 * len(images)), squeeze=False)
    for r, (model, ref, ours) in enumerate(images):
        scale = 1.0 / max(np.percentile(ref, 99), 1e-6)
        for c, (img, title) in enumerate(((ref, "Cycles"), (ours, "ours"))):
            axes[r, c].imshow(np.clip(img * scale, 0, 1) ** (1 / 2.2))
            axes[r, c].set_title(f"{model.replace('_', ' ').title()}: {title}", fontsize=9)
        diff = (ours - ref).mean(axis=2) / np.maximum(ref.mean(axis=2), 1e-3)
        im = axes[r, 2].imshow(diff, cmap="coolwarm", vmin=-0.05, vmax=0.05)
        axes[r, 2].set_title("(ours - Cycles) / Cycles, ±5 %", fontsize=9)
        fig.colorbar(im, ax=axes[r, 2], fraction=0.025)
    for ax in axes.ravel():
        ax.set_xticks([])
        ax.set_yticks([])
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    fig.savefig(path, dpi=90)
