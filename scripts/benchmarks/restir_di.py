"""ReSTIR DI benchmark: frame time versus emissive-triangle count, and where light tiles pay off.

1. Growth: many_lights with 100 .. 1M emissive triangles at 640x360, direct light, ReSTIR DI unbiased
   (temporal + spatial, the add-on's defaults), one sample per frame: export seconds, build seconds (BVH +
   light table; later frames of the unchanged scene reuse them), and the steady-state sample pass (frames
   2-4 of a sequence, history reused).
2. Light tiles: many_lights 10k at 64x48 .. 640x360 (and 1280x720), one RIS sample pass with tiles ON and
   OFF; the AUTO rule's choice at each size.

Prints the figures and writes docs/results/restir_di/benchmark.json and .png.
Usage: python scripts/bench.py restir_di [--quick] [--out DIR]
"""
from __future__ import annotations

import argparse
import os
import platform
import time

from benchmarks.common import ROOT, write_json  # noqa: E402, F401

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import restir_engine  # noqa: E402
from harness.scenes import ensure_blend  # noqa: E402
from restir_engine.core.lights.tiles import TileSettings  # noqa: E402
from restir_engine.core.renderer import RenderSettings, render_frame  # noqa: E402
from restir_engine.export import export_scene  # noqa: E402

RESTIR_DEFAULTS = dict(integrator="RESTIR", direct_method="RESTIR", bias_correction="UNBIASED", temporal_reuse=True,
                       spatial_neighbors=5, spatial_radius=30.0, light_candidates=32, bsdf_candidates=1,
                       max_bounces=0, samples=1, data_passes=False)  # Combined only, as a render without Z/Normal/Vector
LIGHT_COUNTS = {"100": 100, "1k": 1000, "10k": 10000, "100k": 100000, "1m": 1000000}


def load(name, variant, size):
    """(core scene, export seconds) of a harness scene."""
    bpy.ops.wm.open_mainfile(filepath=ensure_blend(name, variant, size))
    dg = bpy.context.evaluated_depsgraph_get()
    t0 = time.perf_counter()
    scene = export_scene(dg)
    return scene, time.perf_counter() - t0


def growth(variants, frames=4):
    out = []
    for v in variants:
        scene, export_s = load("many_lights", v, "large")
        hist, passes, builds = None, [], []
        for f in range(frames):
            r = render_frame(scene, RenderSettings(**RESTIR_DEFAULTS, seed=0, frame=f), history=hist)
            hist = r.history
            builds.append(r.stats["build_seconds"])
            passes.append(r.seconds - r.stats["build_seconds"])
        # frame 0 builds the BVH and light table; later frames of the unchanged scene reuse them
        row = {"variant": v, "emissive_triangles": int(r.stats["light_triangles"]), "export_s": export_s,
               "build_first_s": builds[0], "build_s": float(np.median(builds[1:])),
               "pass_s": float(np.median(passes[1:])), "frame_s": float(np.median(builds[1:]) + np.median(passes[1:])),
               "light_tiles": bool(r.stats["light_tiles"])}
        print(f"[growth] {v:>4}: {row['emissive_triangles']:>8} emitters  export {export_s:5.2f}s  build "
              f"{row['build_first_s']:5.2f}s (reused: {row['build_s']:5.2f}s)  pass {row['pass_s']:5.2f}s  "
              f"tiles {row['light_tiles']}", flush=True)
        out.append(row)
    return out


def tiles(sizes, repeat=3):
    out = []
    for size in sizes:
        scene, _ = load("many_lights", "10k", size)
        w, h = scene.camera.window[2:]
        row = {"width": w, "height": h, "pixels": w * h,
               "auto_uses_tiles": TileSettings("AUTO").wanted(w * h, RESTIR_DEFAULTS["light_candidates"])}
        for mode in ("OFF", "ON"):
            st = RenderSettings(**{**RESTIR_DEFAULTS, "direct_method": "RIS"}, light_tiles=mode)
            times = []
            for k in range(repeat):
                r = render_frame(scene, RenderSettings(**{**st.__dict__, "seed": k}))
                times.append(r.seconds - r.stats["build_seconds"])
            row[f"pass_s_{mode.lower()}"] = float(np.median(times))
        print(f"[tiles] {w}x{h}: off {row['pass_s_off']:.3f}s  on {row['pass_s_on']:.3f}s  AUTO -> "
              f"{'on' if row['auto_uses_tiles'] else 'off'}", flush=True)
        out.append(row)
    return out


def chart(result, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
    g = result["growth"]
    x = [r["emissive_triangles"] for r in g]
    a.plot(x, [r["pass_s"] for r in g], "o-", label="sample pass (temporal + spatial, unbiased)")
    a.plot(x, [r["frame_s"] for r in g], "s--", label="pass + scene check (BVH/light table reused)")
    a.plot(x, [r["build_first_s"] for r in g], "v:", label="BVH + light-table build (first frame)")
    a.plot(x, [r["export_s"] for r in g], "^:", label="export from Blender")
    a.axhline(1.5, color="grey", lw=0.8, ls="--")
    a.set_xscale("log")
    a.set_xlabel("emissive triangles")
    a.set_ylabel("seconds (640x360, 1 spp, 2 threads)")
    a.set_title("ReSTIR DI frame time versus light count")
    a.legend(fontsize=8)
    t = result["tiles"]
    px = [r["pixels"] for r in t]
    b.plot(px, [r["pass_s_off"] for r in t], "o-", label="tiles off (candidates from the power table)")
    b.plot(px, [r["pass_s_on"] for r in t], "s-", label="tiles on (128 x 1024 presampled points)")
    b.set_xscale("log")
    b.set_yscale("log")
    b.set_xlabel("pixels")
    b.set_ylabel("RIS sample pass, seconds")
    b.set_title("Light tiles: crossover (many_lights 10k, 32 candidates)")
    b.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="100 .. 10k lights, sizes up to 320x180")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "restir_di"))
    args = ap.parse_args()
    if not hasattr(bpy.types.Scene, "restir"):
        restir_engine.register()
    variants = ["100", "1k", "10k"] if args.quick else list(LIGHT_COUNTS)
    sizes = ["tiny", "small", "medium"] if args.quick else ["tiny", "small", "medium", "large", (1280, 720)]
    result = {"machine": {"python": platform.python_version(), "cpus": os.cpu_count(), "numpy": np.__version__},
              "date": time.strftime("%Y-%m-%d"), "growth": growth(variants), "tiles": tiles(sizes)}
    os.makedirs(args.out, exist_ok=True)
    write_json(os.path.join(args.out, "benchmark.json"), result)
    chart(result, os.path.join(args.out, "benchmark.png"))
    g = result["growth"]
    print(f"pass time growth {g[0]['variant']} -> {g[-1]['variant']}: {g[-1]['pass_s'] / g[0]['pass_s']:.2f}x; "
          f"wrote {args.out}/benchmark.json and .png")


if __name__ == "__main__":
    main()
