"""What the material model costs: frame time of the path tracer and of ReSTIR DI on the demo room (Principled
materials only) and the many_lights street, and the share of the CPU time spent evaluating materials.

Runs the same frames as scripts/bench.py stages (640x360, 1 sample per frame, steady frames of a sequence,
fastest kept; the material share of that frame and the median over the steady frames are reported). The
material share is measured with per-thread CPU clocks (time.thread_time) around the material
code — building per-hit parameters (SurfaceParams.take/of_table/gather and the row gathers on first use, Mix
picks), the GGX albedo and layer lookups, the view terms (ViewTerms.of), the diffuse part and the denoising albedo,
evaluating and sampling the BSDF (eval_view, sample_bsdf) and the exact-Fresnel part of the ReSTIR target — as a
fraction of the process CPU time of the frame. Run it from another checkout to measure a "before" (what exists
of those functions there is wrapped); ``--frames-only`` skips the clocks (their overhead is ~1 %).

Writes docs/results/materials/cost.json (cost_before.json / cost_start.json with --label before / start) and
cost.png with every series that exists. Usage:
  python scripts/bench.py material_cost [--frames 5] [--label after|start|before] [--frames-only] [--out DIR]
"""
from __future__ import annotations

import argparse
import functools
import json
import os
import threading
import time

from benchmarks.common import ROOT, write_json  # noqa: E402, F401

import bpy  # noqa: E402

from benchmarks.stages import blend_path, warm_up  # noqa: E402
from restir_engine.core.renderer import RenderSettings, render_frame  # noqa: E402
from restir_engine.export import export_scene  # noqa: E402

RUNS = [
    ("demo path", "demo", dict(integrator="PATH", max_bounces=4)),
    ("demo ReSTIR DI", "demo", dict(integrator="RESTIR", direct_method="RESTIR", indirect_method="PATH",
                                    max_bounces=4)),
    ("many_lights path", "many_lights", dict(integrator="PATH", max_bounces=0)),
    ("many_lights ReSTIR DI", "many_lights", dict(integrator="RESTIR", direct_method="RESTIR", max_bounces=0)),
]

_local = threading.local()
_lock = threading.Lock()
_spent = [0.0]


def _timed(fn):
    """Add the calling thread's CPU time inside ``fn`` to the total (outermost call only)."""
    @functools.wraps(fn)
    def wrapper(*a, **k):
        depth = getattr(_local, "depth", 0)
        if depth:
            return fn(*a, **k)
        _local.depth = 1
        t = time.thread_time()
        try:
            return fn(*a, **k)
        finally:
            dt = time.thread_time() - t
            _local.depth = 0
            with _lock:
                _spent[0] += dt
    return wrapper


def instrument() -> None:
    """Wrap the material code wherever it was imported (what exists of it: an older checkout has less)."""
    from restir_engine.core.materials import bsdf
    from restir_engine.core.integrators import pathtracer
    from restir_engine.core.materials import surface
    from restir_engine.core.restir import target
    from restir_engine.core.restir import di, gi
    sp = bsdf.SurfaceParams
    sp.take = _timed(sp.take)
    for name in ("gather", "grey", "__getattr__"):  # row gathers done on first use (newer checkouts)
        if hasattr(sp, name):
            setattr(sp, name, _timed(getattr(sp, name)))
    if isinstance(getattr(sp, "block", None), property):
        sp.block = property(_timed(sp.block.fget))
    # the GGX albedo and layer lookups per hit (Surface._table_at; older checkouts: rows_at in Surface.__init__)
    if hasattr(surface.Surface, "_table_at"):
        surface.Surface._table_at = _timed(surface.Surface._table_at)
    elif hasattr(surface, "rows_at"):
        surface.rows_at = _timed(surface.rows_at)
    for name in ("of_table", "from_material"):
        if hasattr(sp, name):
            setattr(sp, name, staticmethod(_timed(getattr(sp, name))))
    bsdf.ViewTerms.of = staticmethod(_timed(bsdf.ViewTerms.of))
    for mod in (bsdf, pathtracer, di, gi):
        for name in ("eval_view", "sample_bsdf"):
            if hasattr(mod, name):
                setattr(mod, name, _timed(getattr(mod, name)))
    from restir_engine.core.pipeline import film
    for mod, name in ((surface, "pick_components"), (target, "fresnel_exact"), (film, "denoising_albedo"),
                      (pathtracer, "diffuse_f"), (gi, "diffuse_f")):
        if hasattr(mod, name):
            setattr(mod, name, _timed(getattr(mod, name)))


def run(name, scene_name, kw, frames):
    bpy.ops.wm.open_mainfile(filepath=blend_path(scene_name))
    scene = export_scene(bpy.context.evaluated_depsgraph_get())
    hist, rows = None, []
    for f in range(frames):
        _spent[0] = 0.0
        c0, t = time.process_time(), time.perf_counter()
        r = render_frame(scene, RenderSettings(**kw, samples=1, seed=0, frame=f, data_passes=False), history=hist)
        wall, cpu = time.perf_counter() - t, time.process_time() - c0
        hist = r.history
        rows.append({"frame_s": wall, "cpu_s": cpu, "material_cpu_s": _spent[0]})
    steady = rows[1:] or rows
    best = min(steady, key=lambda r: r["frame_s"])
    shares = sorted(r["material_cpu_s"] / max(r["cpu_s"], 1e-9) for r in steady)
    out = {"name": name, "frame_s": best["frame_s"], "frames_s": [r["frame_s"] for r in rows],
           "material_share": best["material_cpu_s"] / max(best["cpu_s"], 1e-9),
           "material_shares": [r["material_cpu_s"] / max(r["cpu_s"], 1e-9) for r in rows],
           "material_share_median": shares[len(shares) // 2] if len(shares) % 2 else
           0.5 * (shares[len(shares) // 2 - 1] + shares[len(shares) // 2])}
    print(f"{name:<24} frame {out['frame_s']:6.3f}s  material share {100 * out['material_share']:4.1f}% "
          f"(steady frames: median {100 * out['material_share_median']:4.1f}%, "
          f"{100 * shares[0]:4.1f}-{100 * shares[-1]:4.1f}%)", flush=True)
    return out


SERIES = (("before", "cost_before.json", "before (Lambert + GGX approximation)"),
          ("start", "cost_start.json", "Principled as Cycles, per-hit gather (2026-11-26)"),
          ("after", "cost.json", "Principled as Cycles, lobes as present (now)"))


def chart(out_dir, path):
    """Frame time per run of every series measured (bars), labelled with the material share (median of frames)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    series = []
    for _key, fname, label in SERIES:
        f = os.path.join(out_dir, fname)
        if os.path.exists(f):
            with open(f) as fh:
                series.append((label, json.load(fh)))
    names = [r["name"] for r in series[-1][1]["runs"]]
    x = np.arange(len(names))
    width = 0.8 / len(series)
    fig, ax = plt.subplots(figsize=(9, 3.8))
    for j, (label, data) in enumerate(series):
        runs = {r["name"]: r for r in data["runs"]}
        xs = x - 0.4 + width * (j + 0.5)
        ax.bar(xs, [runs[n]["frame_s"] if n in runs else np.nan for n in names], width, label=label)
        for xi, n in zip(xs, names):
            if n in runs:
                r = runs[n]
                share = r.get("material_share_median", r["material_share"])
                ax.text(xi, r["frame_s"], f"{100 * share:.0f}%", ha="center", va="bottom", fontsize=7)
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xticks(x, names, fontsize=8)
    ax.set_ylabel("seconds per frame (640x360, 1 spp)")
    ax.set_title("Frame time; labels: CPU share of material evaluation (target: at most 15 %)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--frames", type=int, default=5)
    ap.add_argument("--label", default="after", choices=[k for k, _f, _l in SERIES],
                    help="which series this run is: after (this checkout), before / start (an older checkout)")
    ap.add_argument("--frames-only", action="store_true", help="frame times only, no material clocks")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "materials"))
    args = ap.parse_args()
    if not args.frames_only:
        instrument()
    warm_up()
    runs = [run(n, s, kw, args.frames) for n, s, kw in RUNS]
    os.makedirs(args.out, exist_ok=True)
    data = {"label": args.label, "runs": runs, "cores": os.cpu_count(), "date": time.strftime("%Y-%m-%d")}
    path = os.path.join(args.out, {k: f for k, f, _l in SERIES}[args.label])
    write_json(path, data)
    chart(args.out, os.path.join(args.out, "cost.png"))
    print("wrote", path)


if __name__ == "__main__":
    main()
