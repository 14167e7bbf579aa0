"""Where the 1-sample error of the default cube sits, ours against Cycles, and whether it averages out over seeds.

The factory startup scene at 320x180, 4 bounces, 1 sample per pixel, K seeds per engine, scored per pixel against
the cached Cycles 1024-spp reference (relMSE terms as scripts/harness/metrics.rel_mse). Pixels are split into the
world (constant background), edges (silhouettes and the cube's edges: a luminance gradient of the reference above
5 % of the pixel) and surfaces. For each engine and class: the mean per-image relMSE, and the relMSE of the mean of
the K images over the per-image one: 1/K where every seed draws independent, unbiased samples; 1 where the error
is the same for every seed (a seed-independent sample position: aliasing that no average over seeds removes).

    .venv/bin/python scripts/bench.py first_sample [--seeds 8]   # -> docs/results/default_cube/first_sample.json
"""
from __future__ import annotations

import argparse
import json
import os

from benchmarks.common import ROOT, write_json  # noqa: E402, F401

import numpy as np  # noqa: E402

import restir_engine  # noqa: E402
from harness.metrics import EPS  # noqa: E402
from harness.reference import reference_image  # noqa: E402
from harness.render import render_blend_passes  # noqa: E402
from harness.scenes import ensure_blend  # noqa: E402

BOUNCES = 4


def pixel_classes(ref: np.ndarray) -> dict:
    lum = ref.mean(axis=2)
    gy, gx = np.gradient(lum)
    edge = np.hypot(gx, gy) > 0.05 * (lum + 0.05)
    world = np.all(np.abs(ref - ref[0, 0]) < 1e-3, axis=2)
    return {"world": world & ~edge, "edges": edge, "surfaces": ~world & ~edge}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "default_cube"))
    args = ap.parse_args()
    restir_engine.register()
    blend = ensure_blend("default_cube", "default", "medium")
    ref = reference_image(blend, BOUNCES, 1024)[..., :3].astype(np.float64)
    classes = pixel_classes(ref)
    out = {"seeds": args.seeds, "pixels": {k: int(v.sum()) for k, v in classes.items()}, "engines": {}}
    for engine in ("CYCLES", "RESTIR"):
        errs, images = [], []
        for seed in range(args.seeds):
            passes, _, _ = render_blend_passes(blend, engine, 1, BOUNCES, seed=seed + 1)
            x = passes["Combined"][..., :3].astype(np.float64)
            errs.append(((x - ref) ** 2 / (ref * ref + EPS)).mean(axis=2))
            images.append(x)
        per_image = np.mean(errs, axis=0)
        of_mean = ((np.mean(images, axis=0) - ref) ** 2 / (ref * ref + EPS)).mean(axis=2)
        rows = {"rel_mse": float(per_image.mean())}
        for name, mask in classes.items():
            rows[name] = {"rel_mse_share": float(per_image[mask].sum() / per_image.size),
                          "mean_over_seeds_ratio": float(of_mean[mask].mean() / max(per_image[mask].mean(), 1e-30))}
        out["engines"][engine] = rows
        print(engine, json.dumps(rows), flush=True)
    os.makedirs(args.out, exist_ok=True)
    write_json(os.path.join(args.out, "first_sample.json"), out)


if __name__ == "__main__":
    main()
