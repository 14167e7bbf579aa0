"""ReSTIR DI ablation over frames: spatial only, temporal only, both, biased, against RIS and the path tracer.

many_lights 10k at 640x360, direct light, a static camera rendered as an 8-frame sequence at one sample
per frame (history carried frame to frame, as in `blender -a`), each frame scored against the cached
Cycles reference (surfaces only: Combined - Emission, see docs/EVALUATION.md). Temporal reuse needs
frames to act on, so this is where it shows; the still charts cannot show it.

Prints per-frame relMSE and time; writes docs/results/restir_di/ablation.json and .png.
Usage: python scripts/bench.py ablation_restir_di [--frames 8] [--out DIR]
"""
from __future__ import annotations

import argparse
import os

from benchmarks.common import ROOT, write_json  # noqa: E402, F401

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import restir_engine  # noqa: E402
from harness import metrics  # noqa: E402
from harness.reference import reference_lit  # noqa: E402
from harness.scenes import ensure_blend  # noqa: E402
from restir_engine.core.renderer import RenderSettings, render_frame  # noqa: E402
from restir_engine.export import export_scene  # noqa: E402

BASE = dict(integrator="RESTIR", direct_method="RESTIR", bias_correction="UNBIASED", max_bounces=0, samples=1)
VARIANTS = [
    ("path", "path tracer (NEE + MIS)", dict(integrator="PATH", max_bounces=0, samples=1)),
    ("ris", "RIS only", {**BASE, "direct_method": "RIS"}),
    ("spatial", "spatial only", {**BASE, "temporal_reuse": False}),
    ("temporal", "temporal only", {**BASE, "spatial_neighbors": 0}),
    ("both", "temporal + spatial (defaults)", BASE),
    ("both_r10", "temporal + spatial, 10 px", {**BASE, "spatial_radius": 10.0}),
    ("both_tuned", "temporal + spatial, 10 px, 2 passes", {**BASE, "spatial_radius": 10.0, "spatial_passes": 2}),
    ("biased", "temporal + spatial, biased (1/M)", {**BASE, "bias_correction": "NONE"}),
]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--frames", type=int, default=8)
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "restir_di"))
    args = ap.parse_args()
    if not hasattr(bpy.types.Scene, "restir"):
        restir_engine.register()
    blend = ensure_blend("many_lights", "10k", "large")
    ref = reference_lit(blend, 0, 1024)
    bpy.ops.wm.open_mainfile(filepath=blend)
    scene = export_scene(bpy.context.evaluated_depsgraph_get())
    out = {"scene": "many_lights 10k, direct light, 640x360", "frames": args.frames, "variants": {}}
    for key, label, st in VARIANTS:
        hist, errs, secs = None, [], []
        for f in range(args.frames):
            r = render_frame(scene, RenderSettings(**st, seed=7, frame=f), history=hist)
            hist = r.history
            img = r.passes["Combined"][..., :3] - r.passes["Emission"]
            errs.append(metrics.rel_mse(img, ref))
            secs.append(r.seconds)
        out["variants"][key] = {"label": label, "settings": st, "relmse": errs, "seconds": secs}
        print(f"{label:40s} relMSE per frame {' '.join(f'{e:.3f}' for e in errs)}  "
              f"mean time {np.mean(secs[1:]):.2f}s", flush=True)
    path = out["variants"]["path"]
    base = np.mean(path["relmse"]) * np.mean(path["seconds"][1:])  # relMSE x seconds: the path tracer's efficiency
    for v in out["variants"].values():
        v["steady_relmse"] = float(np.mean(v["relmse"][-3:]))
        v["efficiency_vs_path"] = float(base / (v["steady_relmse"] * np.mean(v["seconds"][1:])))
        print(f"{v['label']:40s} steady relMSE {v['steady_relmse']:.3f}  "
              f"x{v['efficiency_vs_path']:.1f} vs path at equal time")
    os.makedirs(args.out, exist_ok=True)
    write_json(os.path.join(args.out, "ablation.json"), out)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4))
    for key, v in out["variants"].items():
        ax.semilogy(range(1, args.frames + 1), v["relmse"], "o-", label=f"{v['label']} ({np.mean(v['seconds'][1:]):.2f} s)")
    ax.set_xlabel("frame (1 sample per frame, history carried between frames)")
    ax.set_ylabel("relMSE, surfaces only (Combined - Emission)")
    ax.set_title(f"ReSTIR DI ablation: {out['scene']}", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "ablation.png"), dpi=110)
    print(f"wrote {args.out}/ablation.json and .png")


if __name__ == "__main__":
    main()
