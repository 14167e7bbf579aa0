"""What shader node programs cost: frame time of the path tracer (4 bounces) and of ReSTIR DI on the demo room (no
node graphs: the fixed material path) and on a room of 10 procedural materials (Noise, Checker, Gradient, Color
Ramp, Map Range, Layer Weight and Math graphs on Base Color, Roughness, Metallic and Mix factors), and the share
of the process CPU time spent inside node programs (Program.run, per-thread CPU clocks).

640x360, 1 sample per frame, steady frames of a sequence (the first is a warm-up), fastest kept. Writes
docs/results/nodes/cost.json (cost_before.json with --label before, from a checkout without node programs: the
demo only) and cost.png. Usage:
  python scripts/bench.py node_cost [--frames 5] [--label after|before]
"""
from __future__ import annotations

import argparse
import functools
import json
import os
import threading
import time

from benchmarks.common import ROOT, write_json

import bpy

from benchmarks.stages import blend_path, warm_up
from restir_engine.core.renderer import RenderSettings, render_frame
from restir_engine.export import export_scene

RUNS = [("path", dict(integrator="PATH", max_bounces=4)),
        ("ReSTIR DI", dict(integrator="RESTIR", direct_method="RESTIR", indirect_method="PATH", max_bounces=4))]

_local = threading.local()
_lock = threading.Lock()
_spent = [0.0]


def instrument() -> bool:
    try:
        from restir_engine.core.materials.nodes import program
    except ImportError:  # a checkout without node programs
        return False
    run = program.Program.run

    @functools.wraps(run)
    def timed(self, *a, **k):
        t = time.thread_time()
        try:
            return run(self, *a, **k)
        finally:
            with _lock:
                _spent[0] += time.thread_time() - t
    program.Program.run = timed
    return True


def procedural_room():
    """The demo room with 10 procedural materials: its objects' materials replaced, round robin."""
    import node_graphs as ng
    bpy.ops.wm.open_mainfile(filepath=blend_path("demo"))
    mats = []
    graphs = [ng.noise(), ng.checker(5.0), ng.ramp("B_SPLINE"), ng.noise("4D", "RIDGED_MULTIFRACTAL", output="Fac"),
              ng.gradient("RADIAL"), ng.mix_color("OVERLAY"), ng.noise("2D", distortion=0.5), ng.checker(9.0),
              ng.ramp("EASE"), ng.noise(kind="HYBRID_MULTIFRACTAL", output="Fac", positive=True)]
    for k, graph in enumerate(graphs):
        m = bpy.data.materials.new(f"Procedural{k}")
        m.use_nodes = True
        t = m.node_tree
        b = t.nodes["Principled BSDF"]
        graph(t, b.inputs["Base Color"])
        ng.noise(output="Fac", scale=2.0 + k)(t, b.inputs["Roughness"])
        if k % 3 == 0:
            ng.checker(3.0)(t, b.inputs["Metallic"])
        mats.append(m)
    objs = [o for o in bpy.context.scene.objects if o.type == "MESH"]
    for i, o in enumerate(objs):
        for slot in o.material_slots:
            slot.material = mats[i % len(mats)]


def run(name, kw, frames, build):
    build()
    scene = export_scene(bpy.context.evaluated_depsgraph_get())
    hist, rows = None, []
    for f in range(frames):
        _spent[0] = 0.0
        c0, t = time.process_time(), time.perf_counter()
        r = render_frame(scene, RenderSettings(**kw, samples=1, seed=0, frame=f, data_passes=False), history=hist)
        rows.append({"frame_s": time.perf_counter() - t, "cpu_s": time.process_time() - c0, "node_cpu_s": _spent[0]})
        hist = r.history
    steady = rows[1:] or rows
    best = min(steady, key=lambda r: r["frame_s"])
    out = {"name": name, "frame_s": best["frame_s"], "frames_s": [r["frame_s"] for r in rows],
           "node_share": best["node_cpu_s"] / max(best["cpu_s"], 1e-9)}
    print(f"{name:<34} frame {out['frame_s']:6.3f}s  node programs {100 * out['node_share']:4.1f}% of CPU", flush=True)
    return out


def chart(out_dir, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    series = [(label, json.load(open(os.path.join(out_dir, f)))) for label, f in
              (("before node programs", "cost_before.json"), ("now", "cost.json"))
              if os.path.exists(os.path.join(out_dir, f))]
    names = [r["name"] for r in series[-1][1]["runs"]]
    x = np.arange(len(names))
    width = 0.8 / len(series)
    fig, ax = plt.subplots(figsize=(9, 3.6))
    for j, (label, data) in enumerate(series):
        runs = {r["name"]: r for r in data["runs"]}
        xs = x - 0.4 + width * (j + 0.5)
        ax.bar(xs, [runs[n]["frame_s"] if n in runs else np.nan for n in names], width, label=label)
        for xi, n in zip(xs, names):
            if n in runs and runs[n].get("node_share"):
                ax.text(xi, runs[n]["frame_s"], f"{100 * runs[n]['node_share']:.0f}%", ha="center", va="bottom",
                        fontsize=7)
    ax.set_xticks(x, names, fontsize=8)
    ax.set_ylabel("seconds per frame (640x360, 1 spp)")
    ax.set_title("Frame time; labels: CPU share inside node programs (target: at most 25 %)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--frames", type=int, default=5)
    ap.add_argument("--label", default="after", choices=("after", "before"))
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "nodes"))
    args = ap.parse_args()
    has_nodes = instrument()
    warm_up()
    runs = []
    for name, kw in RUNS:
        runs.append(run(f"demo {name}", kw, args.frames,
                        lambda: bpy.ops.wm.open_mainfile(filepath=blend_path("demo"))))
        if has_nodes:
            runs.append(run(f"10 procedural materials {name}", kw, args.frames, procedural_room))
    os.makedirs(args.out, exist_ok=True)
    data = {"label": args.label, "runs": runs, "cores": os.cpu_count(), "date": time.strftime("%Y-%m-%d")}
    path = os.path.join(args.out, "cost.json" if args.label == "after" else "cost_before.json")
    write_json(path, data)
    chart(args.out, os.path.join(args.out, "cost.png"))
    print("wrote", path)


if __name__ == "__main__":
    main()
