"""Third-party .blend files against Cycles: the share of files whose image agrees within 5 % mean and 10 % per region.

    .venv313/bin/python scripts/bench.py third_party FOLDER      # -> docs/results/third_party/third_party.{json,png}

Every .blend under FOLDER (for example the glTF add-on's own test scenes: KhronosGroup/glTF-Blender-IO,
tests/scenes) is opened in a process of its own (a file that crashes or hangs costs only itself; --timeout), at its
current frame, at 96x72. Where a file has no camera, one is added looking at the visible geometry's bounding box
from the front-right-above; where it has no Light object, a sun (3 W/m², angle 10°) is added. Both engines render
the same prepared scene with the same sampling settings as the accuracy tests (box filter, no clamping, no
denoising, --bounces; Cycles' transparent bounces raised to TRANSPARENT_LAYERS): Cycles, then our path tracer
(--method, or our defaults with --method defaults).

Per file: the relative error of the image mean (RGB summed), and of each of 4x4 regions, where a region's error is
|ours - Cycles| / max(Cycles, 0.1 x the image mean) (a black region is judged against a tenth of the image). A file
agrees when its mean error is at most 5 % and every region's at most 10 %. The warnings our export printed are
kept with each file, to tell why a file disagrees. At 128 samples a region's relative standard error is below 1 %
in most scenes of this suite; --noise records each engine's own spread (a second seed against the first, the same
measures), which tells a difference of the models from noise (a caustic's firefly in a 96x72 region).
"""
from __future__ import annotations

import argparse
import glob
import json
import os
import subprocess
import sys
import time

from benchmarks.common import ROOT, write_json

import numpy as np

OUT = os.path.join(ROOT, "docs", "results", "third_party")
MEAN_TOL, REGION_TOL, REGIONS = 0.05, 0.10, 4
#: Cycles' transparent bounce limit here: our alpha cut-outs are followed through up to
#: accel.MAX_CUTOUT_LAYERS surfaces, where Cycles would stop a path at --bounces transparent surfaces (a cube whose
#: faces are partly transparent is several layers deep) and leave it black
TRANSPARENT_LAYERS = 32


def errors(ours: np.ndarray, ref: np.ndarray) -> tuple[float, float]:
    """(relative error of the image mean, worst region's relative error) of two (h, w, 3) images."""
    o, c = ours.sum(-1), ref.sum(-1)
    mean_c = float(c.mean())
    if mean_c <= 0:
        return (0.0 if float(np.abs(o).mean()) == 0 else float("inf")), 0.0
    h, w = c.shape
    ys = np.linspace(0, h, REGIONS + 1).astype(int)
    xs = np.linspace(0, w, REGIONS + 1).astype(int)
    worst = 0.0
    for i in range(REGIONS):
        for j in range(REGIONS):
            ro = float(o[ys[i]:ys[i + 1], xs[j]:xs[j + 1]].mean())
            rc = float(c[ys[i]:ys[i + 1], xs[j]:xs[j + 1]].mean())
            worst = max(worst, abs(ro - rc) / max(rc, 0.1 * mean_c))
    return abs(float(o.mean()) - mean_c) / mean_c, worst


def _prepare(scene, size: tuple[int, int]) -> list[str]:
    """Resolution, a camera and a light where missing; returns what was added."""
    import bpy
    from mathutils import Vector
    added = []
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.render.use_border = False
    dg = bpy.context.evaluated_depsgraph_get()
    if scene.camera is None:
        pts = []
        for inst in dg.object_instances:
            ob = inst.object
            if ob.type in {"MESH", "CURVE", "SURFACE", "META", "FONT", "POINTCLOUD"} and inst.show_self:
                pts += [inst.matrix_world @ Vector(c) for c in ob.bound_box]
        lo = Vector([min(p[k] for p in pts) for k in range(3)]) if pts else Vector((-1, -1, -1))
        hi = Vector([max(p[k] for p in pts) for k in range(3)]) if pts else Vector((1, 1, 1))
        centre, radius = (lo + hi) / 2, max((hi - lo).length / 2, 1e-3)
        cam = bpy.data.objects.new("AddedCamera", bpy.data.cameras.new("AddedCamera"))
        scene.collection.objects.link(cam)
        direction = Vector((1.0, -1.4, 0.9)).normalized()
        cam.location = centre + direction * radius * 2.6
        cam.rotation_euler = (-direction).to_track_quat("-Z", "Y").to_euler()
        cam.data.clip_start, cam.data.clip_end = radius * 0.01, radius * 100
        scene.camera = cam
        added.append("camera")
    if not any(ob.type == "LIGHT" for ob in scene.objects):
        sun = bpy.data.objects.new("AddedSun", bpy.data.lights.new("AddedSun", "SUN"))
        sun.data.energy, sun.data.angle = 3.0, np.radians(10.0)
        sun.rotation_euler = (np.radians(40), np.radians(10), np.radians(30))
        scene.collection.objects.link(sun)
        added.append("sun")
    return added


def render_one(path: str, size, samples: int, bounces: int, method: str, noise: bool) -> dict:
    """Open ``path`` and render it in both engines (this process); the file's record."""
    import bpy

    import restir_engine
    from harness.render import configure_cycles, configure_restir, render_scene
    restir_engine.register()
    bpy.ops.wm.open_mainfile(filepath=path, load_ui=False)
    scene = bpy.context.scene
    added = _prepare(scene, size)
    rec = {"file": os.path.basename(path), "added": added}
    configure_cycles(scene, samples, bounces, seed=1)
    scene.cycles.transparent_max_bounces = TRANSPARENT_LAYERS
    ref, rec["cycles_s"] = render_scene(scene)
    ref = ref["Combined"][..., :3]
    if noise:
        configure_cycles(scene, samples, bounces, seed=2)
        scene.cycles.transparent_max_bounces = TRANSPARENT_LAYERS
        ref2 = render_scene(scene)[0]["Combined"][..., :3]
        rec["cycles_noise_mean"], rec["cycles_noise_region"] = errors(ref2, ref)
    settings = {} if method == "defaults" else {"integrator": method}
    configure_restir(scene, samples, bounces, seed=1, **settings)
    ours, rec["ours_s"] = render_scene(scene)
    ours = ours["Combined"][..., :3]
    if noise:
        configure_restir(scene, samples, bounces, seed=2, **settings)
        ours2 = render_scene(scene)[0]["Combined"][..., :3]
        rec["ours_noise_mean"], rec["ours_noise_region"] = errors(np.nan_to_num(ours2), np.nan_to_num(ours))
    rec["finite"] = bool(np.isfinite(ours).all())
    rec["mean_error"], rec["region_error"] = errors(np.nan_to_num(ours), ref)
    rec["cycles_mean"] = float(ref.mean())
    return rec


def _warnings(output: str) -> list[str]:
    """Our report lines in a render's output (Blender prints reports as 'Warning: ...' / 'Error: ...')."""
    keep = []
    for line in output.splitlines():
        s = line.strip()
        if s.startswith(("Warning:", "Error:", "WARNING", "ERROR")) and s not in keep:
            keep.append(s)
    return keep


def run_file(path: str, args) -> dict:
    cmd = [sys.executable, os.path.join(ROOT, "scripts", "bench.py"), "third_party", "--one", path,
           "--samples", str(args.samples), "--bounces", str(args.bounces), "--method", args.method,
           "--size", args.size] + (["--noise"] if args.noise else [])
    t0 = time.perf_counter()
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=args.timeout)
    except subprocess.TimeoutExpired:
        return {"file": os.path.basename(path), "status": "timeout", "seconds": args.timeout}
    out = proc.stdout + proc.stderr
    rec = None
    for line in out.splitlines():
        if line.startswith("THIRD_PARTY_RECORD "):
            rec = json.loads(line[len("THIRD_PARTY_RECORD "):])
    if rec is None:
        tail = [s for s in out.splitlines() if s.strip()][-3:]
        return {"file": os.path.basename(path), "status": "failed", "rc": proc.returncode, "tail": tail,
                "warnings": _warnings(out)}
    rec["warnings"] = _warnings(out)
    rec["seconds"] = time.perf_counter() - t0
    rec["status"] = ("agrees" if rec["finite"] and rec["mean_error"] <= MEAN_TOL and rec["region_error"] <= REGION_TOL
                     else "differs")
    return rec


def chart(records: list, path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    ok = [r for r in records if "mean_error" in r]
    fig, ax = plt.subplots(figsize=(6, 4.2))
    colours = ["#55a868" if r["status"] == "agrees" else "#c44e52" for r in ok]
    ax.scatter([100 * max(r["mean_error"], 1e-3) for r in ok], [100 * max(r["region_error"], 1e-3) for r in ok],
               c=colours, s=14)
    ax.axvline(100 * MEAN_TOL, ls="--", color="grey")
    ax.axhline(100 * REGION_TOL, ls="--", color="grey")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("error of the image mean against Cycles (%)")
    ax.set_ylabel("worst of 16 regions (%)")
    n_ok = sum(r["status"] == "agrees" for r in records)
    ax.set_title(f"{n_ok} of {len(records)} files agree (green)")
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    os.makedirs(os.path.dirname(path), exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("folder", nargs="?", help="a folder of .blend files (searched recursively)")
    ap.add_argument("--one", help=argparse.SUPPRESS)
    ap.add_argument("--size", default="96x72")
    ap.add_argument("--samples", type=int, default=128)
    ap.add_argument("--bounces", type=int, default=4)
    ap.add_argument("--method", default="PATH", help="our integrator (PATH, RESTIR) or 'defaults'")
    ap.add_argument("--noise", action="store_true", help="also render both engines with a second seed")
    ap.add_argument("--jobs", type=int, default=2, help="files rendered at once")
    ap.add_argument("--timeout", type=float, default=600.0)
    ap.add_argument("--only", default="", help="a substring the file names must contain")
    ap.add_argument("--out", default=OUT)
    args = ap.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    if args.one:
        rec = render_one(args.one, size, args.samples, args.bounces, args.method, args.noise)
        print("THIRD_PARTY_RECORD " + json.dumps(rec), flush=True)
        return 0
    files = sorted(f for f in glob.glob(os.path.join(args.folder, "**", "*.blend"), recursive=True)
                   if args.only in os.path.basename(f))
    from concurrent.futures import ThreadPoolExecutor
    records = []
    with ThreadPoolExecutor(max(args.jobs, 1)) as pool:
        for rec in pool.map(lambda f: run_file(f, args), files):
            records.append(rec)
            extra = (f"mean {100 * rec['mean_error']:6.1f} %  region {100 * rec['region_error']:6.1f} %"
                     if "mean_error" in rec else " ".join(rec.get("tail", [])[-1:]))
            print(f"{rec['status']:8s} {rec['file']:<56s} {extra}", flush=True)
    summary = {s: sum(r["status"] == s for r in records) for s in ("agrees", "differs", "failed", "timeout")}
    out = {"created": time.strftime("%Y-%m-%d"), "folder": os.path.abspath(args.folder), "size": args.size,
           "samples": args.samples, "bounces": args.bounces, "method": args.method, "files": len(records),
           "summary": summary, "tolerances": {"mean": MEAN_TOL, "region": REGION_TOL, "regions": REGIONS ** 2},
           "records": records}
    write_json(os.path.join(args.out, "third_party.json"), out)
    chart(records, os.path.join(args.out, "third_party.png"))
    print(f"{summary['agrees']} of {len(records)} files agree; {summary}")
    return 0
