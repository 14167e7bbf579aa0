"""Which (direct, indirect) pair pays on which scene: efficiency 1 / (relMSE x seconds) of the path tracer and of the
ReSTIR integrator's direct methods (light sampling, ReSTIR DI) crossed with its indirect methods (path-traced,
ReSTIR GI), with bounces, for stills and animation frames with history (static camera).

relMSE (the harness metric) of Combined against a cached Cycles reference, averaged over repetitions with
different seeds; seconds are the renderer's time per frame (render_frame), the median of the repetitions. Every
configuration here is unbiased, so the highest efficiency is the lowest error at equal time. Also recorded per
scene, to choose the automatic indirect method from: the path-traced indirect light's share of the image's
variance (from the repetitions' spread, against the reference) and of its light, and the share of the indirect
light ReSTIR GI's reservoirs carry (the renderer's own statistic).

    .venv/bin/python scripts/bench.py integrators                 # -> docs/results/integrators/
    .venv/bin/python scripts/bench.py integrators --size tiny --reps 2 --scenes cornell-default

The AUTO indirect method (restir_engine/core/method_choice.py) was chosen from these numbers (docs/RESULTS.md).
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
from harness.reference import reference_image  # noqa: E402
from harness.scenes import CACHE, SIZES, ensure_blend  # noqa: E402
from restir_engine.core.renderer import RenderSettings, render_frame  # noqa: E402
from restir_engine.export import export_scene  # noqa: E402

SCENES = [("default_cube", "default"), ("cornell", "default"), ("interior_gi", "default"), ("glossy", "0.2"),
          ("many_lights", "100"), ("many_lights", "1k"), ("glass", "spheres"), ("glass", "window")]
CONFIGS = {"PT": dict(integrator="PATH"),
           "NEE+PATH": dict(integrator="RESTIR", direct_method="LIGHT_SAMPLING", indirect_method="PATH"),
           "NEE+GI": dict(integrator="RESTIR", direct_method="LIGHT_SAMPLING", indirect_method="RESTIR_GI"),
           "DI+PATH": dict(integrator="RESTIR", direct_method="RESTIR", indirect_method="PATH"),
           "DI+GI": dict(integrator="RESTIR", direct_method="RESTIR", indirect_method="RESTIR_GI"),
           "AUTO": dict(integrator="RESTIR", direct_method="AUTO", indirect_method="AUTO")}
LUM = np.array([0.2126, 0.7152, 0.0722], np.float32)


def scene_blend(name: str, variant: str, size: str) -> str:
    """The cached .blend of a harness scene, or of the glass test scene (tests/bpy_scenes.glass_scene)."""
    if name != "glass":
        return ensure_blend(name, variant, size)
    import hashlib
    import inspect

    import bpy_scenes
    text = inspect.getsource(bpy_scenes) + bpy.app.version_string
    path = os.path.join(CACHE, "scenes", f"glass-{variant}-{size}-{hashlib.sha256(text.encode()).hexdigest()[:12]}"
                                         ".blend")
    if not os.path.exists(path):
        os.makedirs(os.path.dirname(path), exist_ok=True)
        bpy_scenes.glass_scene(SIZES[size], window=variant == "window")
        bpy.ops.wm.save_as_mainfile(filepath=path, copy=True)
    return path


def measure(scene, cfg: dict, bounces: int, reps: int, frames: int, ref) -> dict:
    """Repetitions of ``frames`` frames at one sample each (history carried); the last frame scores."""
    images, direct, indirect, seconds, stats = [], [], [], [], []
    for seed in range(reps):
        hist = None
        for f in range(frames):
            r = render_frame(scene, RenderSettings(samples=1, seed=seed, frame=f, max_bounces=bounces,
                                                   data_passes=False, **cfg), history=hist)
            hist = r.history
        images.append(r.passes["Combined"][..., :3])
        direct.append(r.passes["Direct"][..., :3])
        indirect.append(r.passes["Indirect"][..., :3])
        seconds.append(r.seconds)
        stats.append(r.stats)
    rv = float(np.mean([rel_mse(x, ref) for x in images]))
    sec = float(np.median(seconds))
    out = {"rel_mse": rv, "seconds": sec, "efficiency": 1.0 / max(rv * sec, 1e-30),
           "indirect_method": stats[-1]["indirect_method"], "direct_method": stats[-1]["direct_method"],
           "indirect_reason": stats[-1].get("indirect_reason"),
           "gi_share": stats[-1]["reuse"].get("gi_share")}
    # the variance split: per-pixel spread of Direct and Indirect over the repetitions, relative to the reference
    # (the harness metric's normalisation), and the light split
    den = (ref @ LUM) ** 2 + 1e-2
    vd = float((np.var(np.stack(direct) @ LUM, axis=0, ddof=1) / den).mean()) if reps > 1 else None
    vi = float((np.var(np.stack(indirect) @ LUM, axis=0, ddof=1) / den).mean()) if reps > 1 else None
    out["var_direct"], out["var_indirect"] = vd, vi
    out["light_indirect"] = float(np.mean(np.stack(indirect) @ LUM)) / max(
        float(np.mean(np.stack(direct) @ LUM) + np.mean(np.stack(indirect) @ LUM)), 1e-30)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", default="medium")
    ap.add_argument("--reps", type=int, default=4)
    ap.add_argument("--scenes", nargs="*", default=None, help="names-variants, e.g. cornell-default")
    ap.add_argument("--configs", nargs="*", default=list(CONFIGS))
    ap.add_argument("--bounces", type=int, default=4)
    ap.add_argument("--reference-spp", type=int, default=1024)
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "integrators"))
    args = ap.parse_args()
    restir_engine.register()
    os.makedirs(args.out, exist_ok=True)
    json_path = os.path.join(args.out, "integrators.json")
    results = []
    for name, variant in SCENES:
        if args.scenes and f"{name}-{variant}" not in args.scenes:
            continue
        path = scene_blend(name, variant, args.size)
        ref = reference_image(path, args.bounces, args.reference_spp)
        bpy.ops.wm.open_mainfile(filepath=path)
        scene = export_scene(bpy.context.evaluated_depsgraph_get())
        render_frame(scene, RenderSettings(samples=1, integrator="RESTIR", data_passes=False))  # warm-up
        for label, frames in (("still", 1), ("animation", 4)):
            row = {"scene": f"{name}-{variant}", "bounces": args.bounces, "case": label, "configs": {}}
            for k in args.configs:
                row["configs"][k] = measure(scene, CONFIGS[k], args.bounces, args.reps, frames, ref)
            eff = {k: v["efficiency"] for k, v in row["configs"].items()}
            row["best"] = max(eff, key=eff.get)
            base = eff.get("PT") or 1.0
            print(f"{row['scene']:<22} {label:<9} best {row['best']:<9} " + "  ".join(
                f"{k} {v['rel_mse']:.3g}@{v['seconds']:.3f}s x{eff[k] / base:.2f}" for k, v in row["configs"].items()),
                flush=True)
            pt = row["configs"].get("NEE+PATH")
            if pt and pt["var_indirect"] is not None:
                share = (row["configs"].get("NEE+GI") or {}).get("gi_share")
                print(f"    indirect: {pt['var_indirect'] / max(pt['var_indirect'] + pt['var_direct'], 1e-30):.2f} "
                      f"of the variance, {pt['light_indirect']:.2f} of the light; GI share {share}; "
                      f"auto {row['configs'].get('AUTO', {}).get('indirect_method')}", flush=True)
            results.append(row)
            write_json(json_path, {"size": args.size, "reps": args.reps, "bounces": args.bounces,
                                   "created": time.strftime("%Y-%m-%d"), "rows": results})
    chart(results, os.path.join(args.out, "integrators.png"))


def chart(results, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    cases = ("still", "animation")
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.8), sharey=True)
    for ax, c in zip(axes, cases):
        rows = [r for r in results if r["case"] == c]
        keys = [k for k in CONFIGS if rows and k in rows[0]["configs"]]
        gains = {k: [r["configs"][k]["efficiency"] / r["configs"]["PT"]["efficiency"] for r in rows] for k in keys}
        efficiency_bars(ax, [r["scene"] for r in rows], gains, f"{c}, {rows[0]['bounces'] if rows else ''} bounces, 1 spp")
    save_bar_figure(fig, axes, "efficiency 1/(relMSE x s) relative to the path tracer",
                    "Integrator configurations (higher is better)", path)


if __name__ == "__main__":
    main()
