"""The world inside ReSTIR DI's reservoirs (core/lights/world_points.py) against the world light-sampled at the shaded point.

Scenes: tests/bpy_scenes.world_scene (three spheres on a floor) under the sky with a small sun (an environment
image), alone ("hdri") and with three small area lamps ("hdri+lamps"), and under a constant colour with the lamps
("constant+lamps"). Direct light only and 3 bounces (indirect path-traced). Configurations: light sampling
(NEE), ReSTIR DI with the world light-sampled beside the reservoirs (World Light "Light Sampled"), ReSTIR DI
with the world in the reservoirs (World Light "Resampled", World Candidates 1). Cases: 1-sample stills, 4-sample
stills, and the 4th frame of a 4-frame animation (static camera, 1 sample per frame, history carried). Error:
relMSE of Combined against Cycles at 1024 samples; seconds: render_frame's time; efficiency 1 / (relMSE x seconds),
relative to NEE.

    .venv/bin/python scripts/bench.py world_reservoirs   # -> docs/results/world/world_reservoirs.{json,png}
"""
from __future__ import annotations

import argparse
import hashlib
import inspect
import os
import sys
import time

from benchmarks.common import ROOT, write_json  # noqa: E402, F401
for p in (ROOT, os.path.join(ROOT, "scripts"), os.path.join(ROOT, "tests")):
    sys.path.insert(0, p)

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import bpy_scenes  # noqa: E402
import restir_engine  # noqa: E402
from harness.metrics import rel_mse  # noqa: E402
from harness.reference import reference_image  # noqa: E402
from harness.report import efficiency_bars, save_bar_figure  # noqa: E402
from harness.scenes import CACHE  # noqa: E402
from restir_engine.core.renderer import RenderSettings, render_frame  # noqa: E402
from restir_engine.export import export_scene  # noqa: E402

SIZE = (320, 180)
SCENES = ("hdri", "hdri+lamps", "constant+lamps")
CONFIGS = {"NEE": dict(direct_method="LIGHT_SAMPLING"),
           "DI, world light-sampled": dict(direct_method="RESTIR", world_method="LIGHT_SAMPLED"),
           "DI, world in reservoirs": dict(direct_method="RESTIR", world_method="RESAMPLED", world_candidates=1)}
CASES = (("still 1 spp", 1, 1), ("still 4 spp", 4, 1), ("animation", 1, 4))


def build(name: str) -> None:
    bpy_scenes.world_scene("CONSTANT" if name.startswith("constant") else "IMAGE", SIZE, rotation_z=0.8)
    if name.endswith("+lamps"):
        for k, (x, col) in enumerate(((-1.6, (1.0, 0.6, 0.3)), (0.2, (0.3, 0.6, 1.0)), (1.8, (1.0, 1.0, 1.0)))):
            data = bpy.data.lights.new(f"Lamp{k}", "AREA")
            data.size, data.energy, data.color = 0.3, 60.0, col
            obj = bpy.data.objects.new(f"Lamp{k}", data)
            obj.location = (x, -1.0, 1.8)
            bpy.context.scene.collection.objects.link(obj)


def scene_blend(name: str) -> str:
    text = inspect.getsource(bpy_scenes) + inspect.getsource(build) + bpy.app.version_string
    path = os.path.join(CACHE, "scenes", f"world-{name}-{hashlib.sha256(text.encode()).hexdigest()[:12]}.blend")
    if not os.path.exists(path):
        os.makedirs(os.path.dirname(path), exist_ok=True)
        build(name)
        bpy.ops.wm.save_as_mainfile(filepath=path, copy=True)
    return path


def measure(scene, cfg: dict, bounces: int, spp: int, frames: int, reps: int, ref) -> dict:
    errors, seconds = [], []
    for seed in range(reps):
        hist = None
        for f in range(frames):
            r = render_frame(scene, RenderSettings(integrator="RESTIR", indirect_method="PATH", samples=spp, seed=seed,
                                                   frame=f, max_bounces=bounces, data_passes=False, **cfg),
                             history=hist)
            hist = r.history
        errors.append(rel_mse(r.passes["Combined"][..., :3], ref))
        seconds.append(r.seconds)
    rv, sec = float(np.mean(errors)), float(np.median(seconds))
    return {"rel_mse": rv, "seconds": sec, "efficiency": 1.0 / max(rv * sec, 1e-30)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--reps", type=int, default=4)
    ap.add_argument("--reference-spp", type=int, default=1024)
    ap.add_argument("--bounces", type=int, nargs="*", default=[0, 3])
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "world"))
    args = ap.parse_args()
    restir_engine.register()
    os.makedirs(args.out, exist_ok=True)
    rows = []
    for name in SCENES:
        path = scene_blend(name)
        for bounces in args.bounces:
            ref = reference_image(path, bounces, args.reference_spp)
            bpy.ops.wm.open_mainfile(filepath=path)
            scene = export_scene(bpy.context.evaluated_depsgraph_get())
            render_frame(scene, RenderSettings(samples=1, integrator="RESTIR", data_passes=False))  # warm-up
            for case, spp, frames in CASES:
                row = {"scene": name, "bounces": bounces, "case": case, "configs": {}}
                for label, cfg in CONFIGS.items():
                    row["configs"][label] = measure(scene, cfg, bounces, spp, frames, args.reps, ref)
                base = row["configs"]["NEE"]["efficiency"]
                print(f"{name:<15} {bounces} bounces {case:<12} " + "  ".join(
                    f"{k}: {v['rel_mse']:.3g}@{v['seconds']:.3f}s x{v['efficiency'] / base:.2f}"
                    for k, v in row["configs"].items()), flush=True)
                rows.append(row)
                write_json(os.path.join(args.out, "world_reservoirs.json"), {"size": SIZE, "reps": args.reps,
                                                                             "reference_spp": args.reference_spp,
                                                                             "created": time.strftime("%Y-%m-%d"),
                                                                             "rows": rows})
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(args.bounces), figsize=(7 * len(args.bounces), 4.2), squeeze=False)
    axes = axes[0]
    for ax, b in zip(axes, args.bounces):
        sel = [r for r in rows if r["bounces"] == b]
        gains = {k: [r["configs"][k]["efficiency"] / r["configs"]["NEE"]["efficiency"] for r in sel] for k in CONFIGS}
        efficiency_bars(ax, [f"{r['scene']}, {r['case']}" for r in sel], gains, f"{b} bounces")
    save_bar_figure(fig, axes, "efficiency / NEE's", f"The world in ReSTIR DI reservoirs, {SIZE[0]}x{SIZE[1]}",
                    os.path.join(args.out, "world_reservoirs.png"))

if __name__ == "__main__":
    main()
