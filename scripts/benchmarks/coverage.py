"""Pixel coverage: relMSE of Combined versus time with 1, 4 and 16 camera rays per pixel for the emission seen
directly (the lighting shaded at one of them), against cached Cycles references (1024 spp).

    .venv/bin/python scripts/bench.py coverage          # -> docs/results/coverage/coverage.{json,png}

Each point: one still at 1, 2, 4 or 8 samples, relMSE averaged over repetitions with different seeds, the
renderer's own time (median). Direct light only (max_bounces 0), the engine's default direct method (AUTO).
"""
from __future__ import annotations

import argparse
import os
import time

from benchmarks.common import ROOT, write_json  # noqa: E402, F401

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import restir_engine  # noqa: E402
from harness.metrics import rel_mse  # noqa: E402
from harness.reference import reference_image, reference_lit  # noqa: E402
from harness.scenes import ensure_blend  # noqa: E402
from restir_engine.core.renderer import RenderSettings, render_frame  # noqa: E402
from restir_engine.export import export_scene  # noqa: E402

SCENES = [("many_lights", "10k"), ("many_lights", "1k"), ("cornell", "default")]
COVERAGE = (1, 4, 16)
SAMPLES = (1, 2, 4, 8)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", default="medium")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--reference-spp", type=int, default=1024)
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "coverage"))
    args = ap.parse_args()
    restir_engine.register()
    rows = []
    for name, variant in SCENES:
        path = ensure_blend(name, variant, args.size)
        reference_lit(path, 0, args.reference_spp)  # renders and caches Combined and Emit
        ref = reference_image(path, 0, args.reference_spp)
        bpy.ops.wm.open_mainfile(filepath=path)
        scene = export_scene(bpy.context.evaluated_depsgraph_get())
        base = dict(max_bounces=0, integrator="RESTIR", direct_method="AUTO", data_passes=False)
        render_frame(scene, RenderSettings(samples=1, **base))  # warm-up
        for cov in COVERAGE:
            for spp in SAMPLES:
                err, sec = [], []
                for seed in range(args.reps):
                    r = render_frame(scene, RenderSettings(samples=spp, seed=seed, coverage_samples=cov, **base))
                    err.append(rel_mse(r.passes["Combined"], ref))
                    sec.append(r.seconds)
                row = {"scene": f"{name}-{variant}", "coverage": cov, "samples": spp, "rel_mse": float(np.mean(err)),
                       "seconds": float(np.median(sec)), "method": r.stats["direct_method"]}
                rows.append(row)
                print(f"{row['scene']:<18} coverage {cov:2d} spp {spp}: relMSE {row['rel_mse']:.4f} "
                      f"{row['seconds']:.3f}s ({row['method']})", flush=True)
    os.makedirs(args.out, exist_ok=True)
    write_json(os.path.join(args.out, "coverage.json"), {"size": args.size, "reps": args.reps,
                                                         "created": time.strftime("%Y-%m-%d"), "rows": rows})
    chart(rows, os.path.join(args.out, "coverage.png"))


def chart(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    fig, axes = plt.subplots(1, len(scenes), figsize=(5 * len(scenes), 4))
    for ax, sc in zip(np.atleast_1d(axes), scenes):
        for cov in COVERAGE:
            pts = [r for r in rows if r["scene"] == sc and r["coverage"] == cov]
            ax.loglog([p["seconds"] for p in pts], [p["rel_mse"] for p in pts], "o-", label=f"{cov} ray(s)/pixel")
        ax.set_title(sc)
        ax.set_xlabel("seconds (renderer)")
        ax.set_ylabel("relMSE of Combined")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Pixel coverage: emission seen directly over 1 / 4 / 16 rays per pixel (lower-left is better)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
