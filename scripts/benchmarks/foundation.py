"""Foundation benchmark: export speed, Embree wrapper overhead, reference path tracer frame time.

Prints the figures and writes docs/results/foundation_benchmark.json and .png.
Usage: python scripts/bench.py foundation [--quick]
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import time

from benchmarks.common import ROOT, write_json  # noqa: E402, F401

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import restir_engine  # noqa: E402
from restir_engine.core.geometry import camera as camera_mod  # noqa: E402
from restir_engine.core.geometry.accel import Accel  # noqa: E402
from restir_engine.core.parallel.pool import thread_count  # noqa: E402
from restir_engine.core.renderer import RenderSettings, render_frame  # noqa: E402
from restir_engine.export import export_scene  # noqa: E402


def best_of(fn, repeat):
    times = []
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), float(np.median(times)), out


def bench_export(repeat):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=708, y_subdivisions=708, size=10)
    bpy.ops.object.camera_add(location=(0, 0, 10))
    bpy.context.scene.camera = bpy.context.active_object
    dg = bpy.context.evaluated_depsgraph_get()
    tmin, tmed, s = best_of(lambda: export_scene(dg), repeat)
    single = {"triangles": len(s.geometry), "seconds_min": tmin, "seconds_median": tmed,
              "triangles_per_second": len(s.geometry) / tmin}
    # instancing: 100 linked copies of a 10k-triangle mesh (one mesh read, 100 transforms)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=71, y_subdivisions=71, size=1)
    src = bpy.context.active_object
    for i in range(99):
        o = src.copy()
        o.location = (i % 10 * 1.5, i // 10 * 1.5, 0)
        bpy.context.scene.collection.objects.link(o)
    bpy.ops.object.camera_add(location=(0, 0, 10))
    bpy.context.scene.camera = bpy.context.active_object
    dg = bpy.context.evaluated_depsgraph_get()
    tmin, tmed, s = best_of(lambda: export_scene(dg), repeat)
    inst = {"triangles": len(s.geometry), "instances": 100, "seconds_min": tmin, "seconds_median": tmed,
            "triangles_per_second": len(s.geometry) / tmin}
    return {"single_mesh_1M": single, "instanced_100x10k": inst}


def demo_scene(percentage=100):
    from make_demo_scene import build_demo
    scene = build_demo(frames=8, resolution=(640, 360))
    scene.render.resolution_percentage = percentage
    return export_scene(bpy.context.evaluated_depsgraph_get())


def bench_rays(scene, repeat):
    cam = scene.camera
    h, w = cam.height, cam.width
    yy, xx = np.mgrid[0:h, 0:w]
    o, d, tmax = camera_mod.generate_rays(cam, (xx.ravel() + 0.5).astype(np.float32), (yy.ravel() + 0.5).astype(np.float32))
    accel = Accel(scene.geometry.verts)
    n = o.shape[1]  # rays are (3, n) rows
    tmin_wrap, _, _ = best_of(lambda: accel.intersect(o, d, tmax), repeat)
    # direct embreex: one single-threaded call on one wrapper-sized chunk, scaled to rays/s
    from restir_engine.core.geometry.accel import CHUNK_RAYS
    oc, dc = np.ascontiguousarray(o[:, :CHUNK_RAYS].T), np.ascontiguousarray(d[:, :CHUNK_RAYS].T)
    tmin_direct, _, _ = best_of(lambda: accel._scene.run(oc, dc, output=1), repeat)
    direct_rps = len(oc) / tmin_direct
    wrap_rps = n / tmin_wrap
    return {"rays": n, "threads": thread_count(), "wrapper_rays_per_second": wrap_rps,
            "embreex_direct_one_chunk_rays_per_second": direct_rps,
            "wrapper_per_thread_vs_direct": wrap_rps / thread_count() / direct_rps}


def bench_frame(scene, samples, bounces, repeat, **settings):
    st = RenderSettings(samples=samples, max_bounces=bounces, **settings)
    tmin, tmed, r = best_of(lambda: render_frame(scene, st), repeat)
    label = settings.get("direct_method", "path") if settings.get("integrator") == "RESTIR" else "path"
    return {"method": label, "resolution": [scene.camera.width, scene.camera.height], "samples": samples,
            "max_bounces": bounces,
            "seconds_min": tmin, "seconds_median": tmed, "seconds_per_sample": tmin / samples,
            "triangles": len(scene.geometry)}


def chart(results, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 3, figsize=(13, 3.6))
    e = results["export"]
    ax[0].bar(["1M tris, 1 mesh", "1M tris, 100 instances"],
              [e["single_mesh_1M"]["triangles_per_second"] / 1e6, e["instanced_100x10k"]["triangles_per_second"] / 1e6])
    ax[0].set_ylabel("million triangles / s")
    ax[0].set_title("Depsgraph export")
    r = results["rays"]
    ax[1].bar(["embreex direct\n(1 thread, 1 chunk)", f"wrapper\n({r['threads']} threads, full frame)"],
              [r["embreex_direct_one_chunk_rays_per_second"] / 1e6, r["wrapper_rays_per_second"] / 1e6])
    ax[1].set_ylabel("million primary rays / s")
    ax[1].set_title("Primary rays, demo scene 640x360")
    f = results["frames"]
    ax[2].bar([f"{k['method']}\n{k['samples']} spp, {k['max_bounces']} b." for k in f], [k["seconds_min"] for k in f])
    ax[2].tick_params(axis="x", labelsize=7)
    ax[2].set_ylabel("seconds per frame")
    ax[2].set_title("Frame time, demo 640x360 (b. = bounces)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer repetitions")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results"))
    args = ap.parse_args()
    repeat = 1 if args.quick else 3
    if not hasattr(bpy.types.Scene, "restir"):
        restir_engine.register()
    results = {"machine": {"cpu_count": os.cpu_count(), "python": platform.python_version(),
                           "numpy": np.__version__, "blender": bpy.app.version_string},
               "export": bench_export(repeat)}
    scene = demo_scene()
    results["rays"] = bench_rays(scene, repeat)
    results["frames"] = [bench_frame(scene, 1, 4, repeat), bench_frame(scene, 16, 4, 1 if args.quick else 2),
                         bench_frame(scene, 16, 0, 1 if args.quick else 2),
                         bench_frame(scene, 1, 0, repeat, integrator="RESTIR", direct_method="RIS"),
                         bench_frame(scene, 1, 0, repeat, integrator="RESTIR", direct_method="RESTIR")]
    os.makedirs(args.out, exist_ok=True)
    write_json(os.path.join(args.out, "foundation_benchmark.json"), results, indent=2)
    chart(results, os.path.join(args.out, "foundation_benchmark.png"))
    print(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
