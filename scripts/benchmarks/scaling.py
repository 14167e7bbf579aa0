"""Core scaling: frame time of the bpy-free core on 1..N cores, as worker processes and as threads, per stage.

Two steps, so that the timing runs on any many-core machine with Python, numpy and embreex (no bpy there):

  .venv313/bin/python scripts/bench.py scaling export [--out .cache/scaling]
        exports the scenes (the demo, the harness's many_lights 10k and interior_gi; frames 1..F with their motion)
        and the add-on's default settings to pickles
  python3 scripts/benchmarks/scaling.py run --scenes .cache/scaling --cores 1,2,4,8,16 [--out DIR]
        renders each run in a fresh process limited to the first N cores (sched_setaffinity, as taskset): with
        N worker processes of one thread (``processes``) and with one process of N threads (``threads``)
  .venv313/bin/python scripts/bench.py scaling chart --json DIR/scaling.json
        the charts (speed-up over one core per run; per-stage speed-up at the most cores)

Runs: animation frames (1 sample, history carried; the steady frame time is the median of frames 2..F, the first
frame builds the BVH and starts the workers) and a still (the demo at 16 samples, rendered twice: the first F12
starts the workers and builds the BVH, the second is what a user's next F12 costs). Per run and core count it
records the frame time, the leader's per-stage wall times, the worker start-up and the image's checksum (the same
for every core count and mode: the same seed gives the same image). The serial fraction of a stage is Amdahl's
s = (N / S - 1) / (N - 1) for its speed-up S on N cores.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import pickle
import platform
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
CORE_DIR = os.path.join(ROOT, "restir_engine", "core")
SIZES = {"720p": (1280, 720), "360p": (640, 360), "180p": (320, 180)}
# (name, scene file, settings overrides on the add-on's defaults, samples, frames)
RUNS = [
    ("demo PATH 4b", "demo", dict(integrator="PATH", max_bounces=4), 1, 4),
    ("demo defaults", "demo", {}, 1, 4),
    ("many_lights PATH direct", "many_lights", dict(integrator="PATH", max_bounces=0), 1, 4),
    ("many_lights ReSTIR DI", "many_lights", dict(integrator="RESTIR", direct_method="RESTIR", max_bounces=0), 1, 4),
    ("interior_gi PATH", "interior_gi", dict(integrator="PATH", max_bounces=4), 1, 4),
    ("interior_gi DI+GI", "interior_gi", dict(integrator="RESTIR", direct_method="RESTIR",
                                              indirect_method="RESTIR_GI", max_bounces=4), 1, 4),
    ("demo F12 16 spp", "demo", {}, 16, 1),
    ("many_lights F12 ReSTIR DI 8 spp", "many_lights", dict(integrator="RESTIR", direct_method="RESTIR",
                                                             max_bounces=0), 8, 1),
    # enough later passes for 16 workers to render them one per worker (pipeline/spread.py)
    ("many_lights F12 ReSTIR DI 24 spp", "many_lights", dict(integrator="RESTIR", direct_method="RESTIR",
                                                              max_bounces=0), 24, 1),
    # the viewport's renderer (FrameRenderer in one process with N threads, SharedViewRenderer on N processes):
    # VIEW_MOVES full-resolution views panned one after the other (one pass each, the last view's history
    # reprojected, the navigation candidate cap), then VIEW_REFINE samples refining the last view
    ("viewport demo defaults", "demo", {}, 0, "viewport"),
    ("viewport interior DI+GI", "interior_gi", dict(integrator="RESTIR", direct_method="RESTIR",
                                                     indirect_method="RESTIR_GI", max_bounces=4), 0, "viewport"),
]
VIEW_MOVES, VIEW_REFINE = 5, 8


# -- export (bpy) ---------------------------------------------------------------------------------------------------
def export(out: str, frames: int, size: str) -> None:
    import bpy  # noqa: F401  (the export step runs in the bpy venvs)
    from benchmarks.stages import blend_path

    import restir_engine
    from restir_engine.engine import settings_from_scene
    from restir_engine.export import export_scene
    restir_engine.register()
    os.makedirs(out, exist_ok=True)
    w, h = SIZES[size]
    for name in ("demo", "many_lights", "interior_gi"):
        bpy.ops.wm.open_mainfile(filepath=blend_path(name))
        scene = bpy.context.scene
        scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = w, h, 100
        settings = settings_from_scene(scene)
        scenes = []
        for f in range(1, frames + 1):
            scene.frame_set(scene.frame_start + f - 1)
            scenes.append(export_scene(bpy.context.evaluated_depsgraph_get()))
        path = os.path.join(out, f"{name}_{size}.pkl")
        with open(path, "wb") as fh:
            pickle.dump({"scenes": scenes, "settings": settings}, fh, protocol=5)
        print(f"{path}: {len(scenes)} frames, {len(scenes[0].geometry)} triangles", flush=True)


# -- one measurement (a fresh process) ---------------------------------------------------------------------------------
def _load_core():
    import importlib.util
    spec = importlib.util.spec_from_file_location("restir_core", os.path.join(CORE_DIR, "__init__.py"),
                                                  submodule_search_locations=[CORE_DIR])
    module = importlib.util.module_from_spec(spec)
    sys.modules["restir_core"] = module
    spec.loader.exec_module(module)
    return module


def one(args) -> dict:
    cores = int(args.cores)
    if hasattr(os, "sched_setaffinity"):  # as taskset -c K-(K+N-1); spawned workers inherit it (K: first_core)
        os.sched_setaffinity(0, set(range(args.first_core, args.first_core + cores)))
    _load_core()
    import dataclasses

    import numpy as np
    from restir_core.parallel import pool, processes, timeline, wire
    from restir_core.pipeline.frame_render import render_frame
    from restir_core.profile import StageClock

    data = wire.loads(open(args.scene, "rb").read(), "restir_engine.core")
    spec = json.loads(args.spec)
    settings = dataclasses.replace(data["settings"], **spec["settings"], samples=spec["samples"], seed=0,
                                   data_passes=False)
    if spec.get("tile"):
        settings = dataclasses.replace(settings, tile_pixels=int(spec["tile"]))
    if spec.get("no_spread"):  # a still's later passes shared out pass by pass (the leader decides: shared_frame)
        from restir_core.pipeline import spread
        spread.passes_at_once = lambda *_args: 0
    # the thread pool of the rendering process holds N threads either way, as the add-on's with Threads = N (it
    # turns the film into passes while the workers wait); the workers get N // processes threads each
    pool.set_thread_count(cores)
    procs = cores if args.mode == "processes" else 1
    if spec["frames"] == "viewport":
        return _viewport(args, data, settings, procs)
    t0 = time.perf_counter()
    team = processes.team(procs) if procs > 1 else None
    if team is not None:
        team.run(("ping",))  # every worker started and imported the core
    start = time.perf_counter() - t0
    hist, rows, digest = None, [], None
    scenes = data["scenes"]
    # a still on several processes: F12 twice (the first starts the workers and builds the BVH); on one core the
    # first F12 is the figure (its BVH build is under 1 % of it)
    still = spec["frames"] == 1 and procs > 1
    for f in range(2 if still else spec["frames"]):
        clock = StageClock()
        timeline.mark("frame", str(f))
        t = time.perf_counter()
        r = render_frame(scenes[0 if still else f % len(scenes)],
                         dataclasses.replace(settings, frame=1 if spec["frames"] == 1 else f + 1),
                         history=hist if spec["frames"] > 1 else None, clock=clock, processes=procs,
                         bands=spec.get("bands") or None)
        wall = time.perf_counter() - t
        hist = r.history
        rows.append({"frame_s": wall, "stages": {k: v["wall"] for k, v in clock.stages.items()},
                     "stages_cpu": {k: v["cpu"] for k, v in clock.stages.items()},
                     "stage_calls": {k: v["calls"] for k, v in clock.stages.items()},
                     "build_s": r.stats.get("build_seconds")})
        digest = hashlib.sha1(np.ascontiguousarray(r.passes["Combined"]).tobytes()).hexdigest()[:16]
    steady = rows[1:] if len(rows) > 1 else rows
    order = sorted(range(len(steady)), key=lambda i: steady[i]["frame_s"])
    med = steady[order[len(order) // 2]]
    timeline.mark("end")
    timeline.dump("main")
    if team is not None:
        processes.shutdown()
    return {"cores": cores, "mode": args.mode, "frame_s": med["frame_s"], "frames_s": [r["frame_s"] for r in rows],
            "stages": med["stages"], "stages_cpu": med["stages_cpu"], "stage_calls": med["stage_calls"],
            "first_frame_s": rows[0]["frame_s"], "team_start_s": start,
            "checksum": digest, "method": r.stats.get("direct_method"), "indirect": r.stats.get("indirect_method")}


def _viewport(args, data, settings, procs: int) -> dict:
    """The viewport's passes at full resolution: a pan of VIEW_MOVES views, then VIEW_REFINE refinement samples."""
    import dataclasses

    import numpy as np
    from restir_core.parallel import processes
    from restir_core.pipeline.frame import FrameRenderer
    from restir_core.pipeline.shared_view import SharedViewRenderer
    from restir_core.scene import Motion
    scene = data["scenes"][0]
    scene.light_groups = None
    full = scene.camera
    _x0, _y0, w, h = full.window
    settings = dataclasses.replace(settings, samples=VIEW_REFINE + VIEW_MOVES, frame=0)
    t0 = time.perf_counter()
    team = processes.borrow(procs) if procs > 1 else None
    start = time.perf_counter() - t0
    t = time.perf_counter()
    r = SharedViewRenderer(team, scene, settings, w * h) if team is not None else FrameRenderer(scene, settings)
    build = time.perf_counter() - t
    mats = getattr(scene, "export_stats", {}).get("instance_matrices")
    mats = np.zeros((0, 4, 4)) if mats is None else mats
    moves, refine = [], []
    for k in range(1, VIEW_MOVES + 1):
        m = full.cam_to_world.copy()
        m[:3, 3] += 0.05 * k * m[:3, 0]
        prev, cam = r.camera, dataclasses.replace(full, cam_to_world=m)
        t = time.perf_counter()
        r.move_camera(cam, k)
        r.set_motion(Motion(current=mats, prev=mats, next=mats, camera_prev=prev))
        r.sample_pass(batch=1, light_candidate_cap=8 if r.reuses_history() else None)
        moves.append(time.perf_counter() - t)
    done = 0
    while done < VIEW_REFINE:
        batch = r.batch_size(VIEW_REFINE - done)
        t = time.perf_counter()
        r.sample_pass(batch=batch)
        refine.append((time.perf_counter() - t) / batch)
        done += batch
    digest = hashlib.sha1(np.ascontiguousarray(r.combined()).tobytes()).hexdigest()[:16]
    r.release()
    if team is not None:
        processes.give_back(team)
        processes.shutdown()
    steady = sorted(moves[1:])
    return {"cores": int(args.cores), "mode": args.mode, "frame_s": steady[len(steady) // 2], "moves_s": moves,
            "refine_sample_s": float(np.median(refine)), "first_frame_s": moves[0] + build, "build_s": build,
            "team_start_s": start, "checksum": digest, "stages": {}, "method": r.method}


# -- the sweep -------------------------------------------------------------------------------------------------------
def run(args) -> None:
    cores = [int(c) for c in args.cores.split(",")]
    avail = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    cores = [c for c in cores if c <= avail]
    modes = args.modes.split(",")
    results = {"meta": {"machine": platform.processor() or platform.machine(), "logical_cores": os.cpu_count(),
                        "python": platform.python_version(), "size": args.size, "tile": args.tile,
                        "bands": args.bands, "no_spread": args.no_spread,
                        "date": time.strftime("%Y-%m-%d")},
               "runs": []}
    os.makedirs(args.out, exist_ok=True)
    for name, scene, settings, samples, frames in RUNS:
        if args.only and not any(o in name for o in args.only.split(",")):
            continue
        spec = json.dumps({"settings": settings, "samples": samples, "frames": frames, "tile": args.tile,
                           "bands": args.bands, "no_spread": args.no_spread})
        path = os.path.join(args.scenes, f"{scene}_{args.size}.pkl")
        entry = {"name": name, "scene": scene, "settings": settings, "samples": samples, "points": []}
        for mode in modes:
            for n in cores:
                if mode == "threads" and n == 1 and "processes" in modes:
                    continue  # one process of one thread: the processes row's 1
                cmd = [sys.executable, __file__, "one", "--scene", path, "--spec", spec, "--cores", str(n),
                       "--mode", mode if n > 1 else "processes"]
                env = dict(os.environ)
                if args.timeline and mode == "processes" and n > 1:  # each process's events (team_timeline.py)
                    env["RESTIR_TIMELINE"] = os.path.join(args.timeline, f"{name.replace(' ', '_')}_{n}")
                    os.makedirs(env["RESTIR_TIMELINE"], exist_ok=True)
                t = time.perf_counter()
                proc = subprocess.run(cmd, capture_output=True, text=True, timeout=args.timeout, env=env)
                if proc.returncode != 0:
                    print(f"{name} {mode} {n}: failed\n{proc.stderr[-3000:]}", flush=True)
                    continue
                point = json.loads(proc.stdout.strip().splitlines()[-1])
                point["mode"] = mode if n > 1 else "one"
                entry["points"].append(point)
                print(f"{name:<26} {point['mode']:<9} {n:>2} cores  frame {point['frame_s']:7.3f} s  "
                      f"first {point['first_frame_s']:6.2f} s  start {point['team_start_s']:.2f} s  "
                      f"[{point['checksum']}] ({time.perf_counter() - t:.0f} s)", flush=True)
        results["runs"].append(entry)
        with open(os.path.join(args.out, "scaling.json"), "w") as fh:
            json.dump(results, fh, indent=1)
    summary(results)


def summary(results) -> None:
    for entry in results["runs"]:
        pts = entry["points"]
        base = next((p for p in pts if p["cores"] == 1), None)
        if base is None:
            continue
        same = len({p["checksum"] for p in pts}) == 1
        line = [f"{entry['name']:<26}"]
        for p in pts:
            if p["cores"] > 1:
                line.append(f"{p['mode'][0]}{p['cores']}: {base['frame_s'] / p['frame_s']:.1f}x")
        print("  ".join(line) + ("  same image" if same else "  IMAGES DIFFER"))


def serial_fraction(speedup: float, n: int) -> float:
    return (n / speedup - 1.0) / (n - 1.0) if n > 1 else 0.0


def chart(args) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    results = json.load(open(args.json))
    out = os.path.dirname(os.path.abspath(args.json))
    runs = [r for r in results["runs"] if any(p["cores"] == 1 for p in r["points"])]
    staged = any(p.get("stages") for r in runs for p in r["points"])  # the viewport runs time no stages
    fig, axes = plt.subplots(1, 2 if staged else 1, figsize=(13 if staged else 7, 5), squeeze=False)
    axes = axes[0]
    colors = plt.get_cmap("tab10").colors
    top = 1
    for i, entry in enumerate(runs):
        base = next(p for p in entry["points"] if p["cores"] == 1)["frame_s"]
        for mode, style in (("processes", "-o"), ("threads", ":x")):
            pts = sorted([p for p in entry["points"] if p["mode"] in (mode, "one")], key=lambda p: p["cores"])
            if len(pts) < 2:
                continue
            xs, ys = [p["cores"] for p in pts], [base / p["frame_s"] for p in pts]
            top = max(top, max(xs))
            axes[0].plot(xs, ys, style, color=colors[i % 10], label=f"{entry['name']} ({mode})")
    axes[0].plot([1, top], [1, top], color="grey", lw=0.8, label="linear")
    axes[0].set_xlabel("cores")
    axes[0].set_ylabel("speed-up over one core")
    axes[0].set_title(f"Frame speed-up, {results['meta'].get('size')} ({results['meta'].get('machine')})")
    axes[0].legend(fontsize=6)
    if staged:
        _stage_chart(axes[1], runs)
    fig.tight_layout()
    path = os.path.join(out, "scaling.png")
    fig.savefig(path, dpi=110)
    print(path)


def _stage_chart(ax, runs) -> None:
    # per-stage speed-up of the processes at the most cores
    stages, labels, vals = [], [], []
    for entry in runs:
        pts = [p for p in entry["points"] if p["mode"] == "processes"]
        if not pts:
            continue
        best = max(pts, key=lambda p: p["cores"])
        base = next(p for p in entry["points"] if p["cores"] == 1)
        for st, wall in best["stages"].items():
            b = base["stages"].get(st)
            if b and wall > 0 and b > 0.01 * base["frame_s"]:
                stages.append(st)
                labels.append(f"{entry['name']}: {st}")
                vals.append(b / wall)
    ax.barh(range(len(vals)), vals, color="tab:blue")
    ax.set_yticks(range(len(vals)))
    ax.set_yticklabels(labels, fontsize=5)
    ax.set_xlabel("stage speed-up at the most cores (processes)")
    ax.set_title("Per stage (stages of at least 1 % of the one-core frame)")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="step", required=True)
    e = sub.add_parser("export")
    e.add_argument("--out", default=os.path.join(ROOT, ".cache", "scaling"))
    e.add_argument("--frames", type=int, default=4)
    e.add_argument("--size", default="360p", choices=tuple(SIZES))
    r = sub.add_parser("run")
    r.add_argument("--scenes", default=os.path.join(ROOT, ".cache", "scaling"))
    r.add_argument("--cores", default="1,2,4,8,16")
    r.add_argument("--modes", default="processes,threads")
    r.add_argument("--size", default="360p", choices=tuple(SIZES))
    r.add_argument("--only", default=None, help="comma-separated parts of run names")
    r.add_argument("--timeout", type=float, default=600)
    r.add_argument("--tile", type=int, default=0, help="pixels per chunk (0: the settings')")
    r.add_argument("--bands", type=int, default=0, help="bands per frame (0: as memory.band_budget plans them)")
    r.add_argument("--no-spread", action="store_true",
                   help="share a still's later passes out pass by pass (not one per worker)")
    r.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "scaling"))
    r.add_argument("--timeline", default=None,
                   help="a folder: record each multi-process run's barrier and message events there "
                        "(read by scripts/bench.py team_timeline)")
    o = sub.add_parser("one")
    o.add_argument("--scene")
    o.add_argument("--spec")
    o.add_argument("--cores")
    o.add_argument("--mode")
    o.add_argument("--first-core", type=int, default=0, help="the first of the cores it is pinned to")
    c = sub.add_parser("chart")
    c.add_argument("--json", default=os.path.join(ROOT, "docs", "results", "scaling", "scaling.json"))
    args = ap.parse_args(argv)
    if args.step == "export":
        export(args.out, args.frames, args.size)
    elif args.step == "run":
        run(args)
    elif args.step == "one":
        print(json.dumps(one(args)))
    else:
        chart(args)


if __name__ == "__main__":
    main()
