"""The cost of a frame at small sizes: frame time against pixel count, per stage, and the fixed per-frame part.

One-sample animation frames (history carried, the BVH reused: frames 4..N of a sequence, the median kept) of the
harness's many_lights (10k emissive triangles, ReSTIR DI, direct light only) and interior_gi (ReSTIR DI + GI,
4 bounces) at 32x18 up to 640x360, with the core in this process (the pool's threads, no worker processes). The
fixed per-frame cost is bounded by the 32x18 frame (576 pixels: what does not scale with the pixels, plus a
little that does); its share of the 320x180 frame is what issue 28 asks to keep at or below 20 %. Writes
docs/results/frame_cost/frame_cost.json and frame_cost.png (frame time per stage against pixels, log-log).

    .venv313/bin/python scripts/bench.py frame_cost [--frames 10] [--only many_lights]
"""
from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

from benchmarks.common import RESULTS, write_json

SIZES = ((32, 18), (80, 45), (160, 90), (320, 180), (640, 360))
RUNS = {"many_lights": dict(integrator="RESTIR", direct_method="RESTIR", max_bounces=0),
        "interior_gi": dict(integrator="RESTIR", direct_method="RESTIR", indirect_method="RESTIR_GI", max_bounces=4)}


def measure(name: str, size, frames: int) -> dict:
    """Median steady frame time and stage walls of ``name`` at ``size``."""
    import bpy

    from benchmarks.stages import blend_path
    from restir_engine.core.profile import StageClock
    from restir_engine.core.renderer import RenderSettings, render_frame
    from restir_engine.export import export_scene
    bpy.ops.wm.open_mainfile(filepath=blend_path(name))
    r = bpy.context.scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = size[0], size[1], 100
    scene = export_scene(bpy.context.evaluated_depsgraph_get())
    hist, rows = None, []
    for f in range(frames):
        clock = StageClock()
        t = time.perf_counter()
        out = render_frame(scene, RenderSettings(**RUNS[name], samples=1, seed=0, frame=f, data_passes=False),
                           history=hist, clock=clock)
        rows.append((time.perf_counter() - t, {k: v["wall"] for k, v in clock.stages.items()}))
        hist = out.history
    steady = sorted(rows[4:] if len(rows) > 4 else rows, key=lambda r: r[0])
    frame_s, stages = steady[len(steady) // 2]
    return {"pixels": size[0] * size[1], "size": list(size), "frame_s": frame_s, "stages": stages,
            "frames_s": [r[0] for r in rows], "coverage_samples": out.stats.get("coverage_samples")}


def chart(results: dict, path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(results), figsize=(6 * len(results), 4.2), squeeze=False)
    for ax, (name, rows) in zip(axes[0], results.items()):
        px = [r["pixels"] for r in rows]
        ax.loglog(px, [r["frame_s"] for r in rows], "o-", color="k", label="frame")
        stages = sorted({s for r in rows for s in r["stages"]}, key=lambda s: -rows[-1]["stages"].get(s, 0))
        for s in stages[:6]:
            ax.loglog(px, [max(r["stages"].get(s, 0.0), 1e-5) for r in rows], ".--", label=s)
        ax.axhline(rows[0]["frame_s"], color="#c44e52", lw=0.8, ls=":", label="32x18 frame (fixed part bound)")
        ax.set_xlabel("pixels")
        ax.set_ylabel("seconds per 1-sample frame")
        ax.set_title(name)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    os.makedirs(os.path.dirname(path), exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--frames", type=int, default=10)
    ap.add_argument("--only", default=None)
    args = ap.parse_args()
    results = {}
    for name in RUNS:
        if args.only and args.only not in name:
            continue
        results[name] = []
        for size in SIZES:
            row = measure(name, size, args.frames)
            results[name].append(row)
            print(f"{name:12s} {size[0]}x{size[1]:<4d} {row['frame_s']:.4f} s  " +
                  "  ".join(f"{k} {v:.4f}" for k, v in row["stages"].items()), flush=True)
        at = {tuple(r["size"]): r["frame_s"] for r in results[name]}
        print(f"{name}: fixed part <= {at[(32, 18)]:.4f} s = {100 * at[(32, 18)] / at[(320, 180)]:.1f} % of the "
              f"320x180 frame ({at[(320, 180)]:.4f} s)")
    out = os.path.join(RESULTS, "frame_cost")
    write_json(os.path.join(out, "frame_cost.json"), {"machine": platform.processor() or platform.machine(),
                                                       "cpus": os.cpu_count(), "runs": results})
    chart(results, os.path.join(out, "frame_cost.png"))
    return 0
