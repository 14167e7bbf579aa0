"""Which direct-light method pays on which scene: efficiency 1 / (relMSE x seconds) of light sampling (NEE + MIS),
RIS and ReSTIR DI on the harness scenes, for stills and for animation frames with history.

relMSE (the harness metric) against a cached Cycles reference (1024 spp), averaged over independent repetitions
(different seeds), on the whole image (Combined) and on surfaces only (Combined - Emission against Cycles'
Combined - Emit). Seconds are the renderer's own time per frame (render_frame), the median of the repetitions.
Every method here is unbiased (ReSTIR in its default unbiased mode), so the one with the highest efficiency
1 / (relMSE x seconds) gives the lowest error at equal time. (A reference-free estimate from the spread of the
repetitions fails here: a pixel that sees a tiny bright emitter in one repetition of eight reads the same
relative variance whatever its coverage.)

    .venv/bin/python scripts/bench.py direct_methods            # -> docs/results/direct_methods/
    .venv/bin/python scripts/bench.py direct_methods --size tiny --reps 3   # a quick look

The AUTO direct method (restir_engine/core/method_choice.py) was chosen from these numbers (docs/RESULTS.md).
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
from harness.report import efficiency_bars, save_bar_figure  # noqa: E402
from harness.reference import reference_image, reference_lit  # noqa: E402
from harness.scenes import ensure_blend  # noqa: E402
from restir_engine.core.integrators import trace_context  # noqa: E402
from restir_engine.core.integrators.context_cache import context_for  # noqa: E402
from restir_engine.core.integrators.method_choice import choose_direct_method  # noqa: E402
from restir_engine.core.renderer import RenderSettings, render_frame  # noqa: E402
from restir_engine.export import export_scene  # noqa: E402

SCENES = [("default_cube", "default"), ("cornell", "default"), ("interior_gi", "default"), ("glossy", "0.2"),
          ("many_lights", "100"), ("many_lights", "1k"), ("many_lights", "10k")]
METHODS = ["LIGHT_SAMPLING", "RIS", "RESTIR"]


def measure(scene, method: str, bounces: int, reps: int, frames: int, ref, ref_lit, extra=None) -> dict:
    """Repetitions of ``frames`` frames (static camera; history carried with ReSTIR) at one sample each; the
    last frame's images give relMSE, the last frame's time the cost."""
    images, lit, seconds = [], [], []
    for seed in range(reps):
        hist = None
        for f in range(frames):
            kw = dict(samples=1, seed=seed, frame=f, max_bounces=bounces, data_passes=False, integrator="RESTIR",
                      direct_method=method, **(extra or {}))
            r = render_frame(scene, RenderSettings(**kw), history=hist)
            hist = r.history
        images.append(r.passes["Combined"][..., :3])
        lit.append(r.passes["Combined"][..., :3] - r.passes["Emission"][..., :3])
        seconds.append(r.seconds)
    rv = float(np.mean([rel_mse(x, ref) for x in images]))
    rv_lit = float(np.mean([rel_mse(x, ref_lit) for x in lit]))
    sec = float(np.median(seconds))
    return {"rel_mse": rv, "rel_mse_surfaces": rv_lit, "seconds": sec, "efficiency": 1.0 / max(rv * sec, 1e-30),
            "efficiency_surfaces": 1.0 / max(rv_lit * sec, 1e-30)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", default="small")
    ap.add_argument("--reps", type=int, default=6)
    ap.add_argument("--scenes", nargs="*", default=None, help="names-variants, e.g. many_lights-10k")
    ap.add_argument("--bounces", nargs="*", type=int, default=[0, 4])
    ap.add_argument("--reference-spp", type=int, default=1024)
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "direct_methods"))
    args = ap.parse_args()
    restir_engine.register()
    results = []
    for name, variant in SCENES:
        if args.scenes and f"{name}-{variant}" not in args.scenes:
            continue
        path = ensure_blend(name, variant, args.size)
        refs = {}
        for b in args.bounces:  # reference_lit renders Combined and Emit once and caches both
            lit = reference_lit(path, b, args.reference_spp)
            refs[b] = (reference_image(path, b, args.reference_spp), lit)
        bpy.ops.wm.open_mainfile(filepath=path)
        scene = export_scene(bpy.context.evaluated_depsgraph_get())
        render_frame(scene, RenderSettings(samples=1, integrator="RESTIR", data_passes=False))  # warm-up
        lights = context_for(scene, 0, False, trace_context.build_context)[0].lights
        for bounces in args.bounces:
            for label, frames in (("still", 1), ("animation", 4)):
                auto, reason = choose_direct_method(lights, False, bounces)
                row = {"scene": f"{name}-{variant}", "bounces": bounces, "case": label, "auto": auto,
                       "reason": reason, "methods": {}}
                for m in METHODS:
                    row["methods"][m] = measure(scene, m, bounces, args.reps, frames, *refs[bounces])
                best = max(row["methods"], key=lambda k: row["methods"][k]["efficiency"])
                row["best"] = best
                eff = {k: v["efficiency"] for k, v in row["methods"].items()}
                effs = {k: v["efficiency_surfaces"] for k, v in row["methods"].items()}
                print(f"{row['scene']:<22} b{bounces} {label:<9} best {best:<14} auto {auto:<14} " + "  ".join(
                    f"{k} {row['methods'][k]['rel_mse']:.2e}/{row['methods'][k]['rel_mse_surfaces']:.2e}"
                    f"@{row['methods'][k]['seconds']:.3f}s (x{eff[k] / eff['LIGHT_SAMPLING']:.2f}/"
                    f"{effs[k] / effs['LIGHT_SAMPLING']:.2f})" for k in METHODS), flush=True)
                results.append(row)
    os.makedirs(args.out, exist_ok=True)
    write_json(os.path.join(args.out, "direct_methods.json"), {"size": args.size, "reps": args.reps,
                                                               "created": time.strftime("%Y-%m-%d"), "rows": results})
    chart(results, os.path.join(args.out, "direct_methods.png"))


def chart(results, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    cases = [(b, c) for b in (0, 4) for c in ("still", "animation")]
    fig, axes = plt.subplots(1, len(cases), figsize=(5 * len(cases), 4.5), sharey=True)
    for ax, (b, c) in zip(axes, cases):
        rows = [r for r in results if r["bounces"] == b and r["case"] == c]
        gains = {m: [r["methods"][m]["efficiency"] / r["methods"]["LIGHT_SAMPLING"]["efficiency"] for r in rows]
                 for m in METHODS}
        efficiency_bars(ax, [r["scene"] for r in rows], gains, f"{c}, {b} bounces", rotation=60)
        for j, r in enumerate(rows):
            ax.text(j, 0.02, "auto: " + r["auto"].replace("LIGHT_SAMPLING", "NEE"), rotation=90, fontsize=7,
                    va="bottom", ha="center", transform=ax.get_xaxis_transform())
    save_bar_figure(fig, axes, "efficiency 1/(relMSE x s), relative to light sampling",
                    "Direct-light method efficiency (higher is better)", path)


if __name__ == "__main__":
    main()
