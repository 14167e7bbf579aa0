"""Blender's factory startup scene (the default cube, its point light, the grey world) as a new user renders it:
relMSE of Combined versus wall time, ours (defaults) against Cycles, at 320x180 with 4 bounces.

    .venv/bin/python scripts/bench.py default_cube      # -> docs/results/default_cube/default_cube.{json,png}

Reference: Cycles at 1024 spp (cached). Every point: one still through bpy.ops.render.render (export included),
median wall time of the repetitions and their mean relMSE. Our converged image (256 spp) is scored too: what
remains there is bias of the material model (the Principled BSDF, the materials issue), which no sampling fixes.
"""
from __future__ import annotations

import argparse
import os
import time

from benchmarks.common import ROOT, write_json  # noqa: E402, F401

import numpy as np  # noqa: E402

import restir_engine  # noqa: E402
from harness.metrics import interpolate_loglog, rel_bias, rel_mse  # noqa: E402
from harness.reference import reference_image  # noqa: E402
from harness.render import render_blend_passes  # noqa: E402
from harness.scenes import ensure_blend  # noqa: E402

BOUNCES = 4
LADDERS = {"cycles": ("CYCLES", {}, (1, 2, 4, 8, 16, 32, 64)),
           "ours (defaults)": ("RESTIR", {}, (1, 2, 4, 8, 16, 32)),
           "ours, ReSTIR DI forced": ("RESTIR", {"integrator": "RESTIR", "direct_method": "RESTIR"}, (1, 2, 4, 8))}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", default="medium")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--reference-spp", type=int, default=1024)
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "default_cube"))
    args = ap.parse_args()
    restir_engine.register()
    blend = ensure_blend("default_cube", "default", args.size)
    ref = reference_image(blend, BOUNCES, args.reference_spp)
    out = {"scene": f"default_cube-{args.size}", "bounces": BOUNCES, "created": time.strftime("%Y-%m-%d"),
           "ladders": {}}
    for key, (engine, settings, ladder) in LADDERS.items():
        render_blend_passes(blend, engine, 1, BOUNCES, settings=settings)  # warm-up
        pts = []
        for spp in ladder:
            errs, walls = [], []
            for seed in range(args.reps):
                passes, wall, _core = render_blend_passes(blend, engine, spp, BOUNCES, seed=seed + 1, settings=settings)
                errs.append(rel_mse(passes["Combined"], ref))
                walls.append(wall)
            pts.append({"samples": spp, "seconds": float(np.median(walls)), "rel_mse": float(np.mean(errs))})
            print(f"{key:<24} {spp:3d} spp  {pts[-1]['seconds']:.3f}s  relMSE {pts[-1]['rel_mse']:.2e}", flush=True)
        out["ladders"][key] = pts
    from restir_engine.engine import LAST_FRAME_STATS
    conv, wall, _ = render_blend_passes(blend, "RESTIR", 256, BOUNCES, seed=9)
    out["converged"] = {"samples": 256, "rel_mse": rel_mse(conv["Combined"], ref),
                        "rel_bias": rel_bias(conv["Combined"], ref), "direct_method": LAST_FRAME_STATS["direct_method"]}
    print(f"ours at 256 spp: relMSE {out['converged']['rel_mse']:.2e}, bias {100 * out['converged']['rel_bias']:+.2f} %"
          f" ({out['converged']['direct_method']})", flush=True)
    cyc = out["ladders"]["cycles"]
    for key, pts in out["ladders"].items():
        if key == "cycles":
            continue
        # only where Cycles was measured at that time: interpolate_loglog clamps, and a clamped Cycles error
        # (its last point) would flatter us beyond the end of its ladder
        t_max = max(c["seconds"] for c in cyc)
        ratios = [interpolate_loglog([c["seconds"] for c in cyc], [c["rel_mse"] for c in cyc], p["seconds"])
                  / p["rel_mse"] if p["seconds"] <= t_max else None for p in pts]
        out.setdefault("cycles_over_ours", {})[key] = ratios
        print(f"{key}: Cycles relMSE / ours at equal time " + " ".join("-" if r is None else f"{r:.2f}" for r in ratios), flush=True)
    os.makedirs(args.out, exist_ok=True)
    write_json(os.path.join(args.out, "default_cube.json"), out)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for key, pts in out["ladders"].items():
        ax.loglog([p["seconds"] for p in pts], [p["rel_mse"] for p in pts], "o-", label=key)
    ax.axhline(out["converged"]["rel_mse"], color="k", ls=":", label="ours at 256 spp (material bias floor)")
    ax.set_xlabel("wall seconds (bpy.ops.render.render)")
    ax.set_ylabel("relMSE of Combined vs Cycles 1024 spp")
    ax.set_title(f"Default cube, {args.size}, {BOUNCES} bounces")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "default_cube.png"), dpi=110)


if __name__ == "__main__":
    main()
