"""Motion blur's cost per sample pass on a core scene of about 1M triangles of which 1 % move (core only, no bpy).

Each pass of a motion-blurred frame poses the scene at its own shutter time: the moving instances' triangles are
moved and only their Embree scene is rebuilt (geometry/accel.py SplitAccel; the still ones' is built once per
frame). Measured: the frame time per pass (the frame's seconds over its passes, the still BVH's one build
included) sharp, blurred with only the camera moving, blurred with 1 % of the triangles moving, and for comparison
the full Embree build a naive per-pass rebuild would pay. Writes motion_blur.json and motion_blur.png.

    .venv313/bin/python scripts/bench.py motion_blur [--triangles N] [--moving 0.01] [--samples 8]
"""
from __future__ import annotations

import argparse
import os
import time

import numpy as np

from benchmarks.common import RESULTS, bar_chart, write_json


def scene(n_triangles: int, moving_share: float, width: int, height: int):
    """A field of small diffuse quads (two triangles each) under a quad light, seen from above; the first
    ``moving_share`` of them form instance 1, which moves 0.5 m along x over the shutter."""
    from scenes_core import perspective_camera

    from restir_engine.core.geometry.motion_blur import ShutterMotion
    from restir_engine.core.scene import Lamps, MaterialTable, Scene, TriangleSet
    quads = n_triangles // 2
    side = int(np.ceil(np.sqrt(quads)))
    i = np.arange(quads)
    cx, cy = (i % side) / side * 4 - 2, (i // side) / side * 4 - 2
    h = 4.0 / side * 0.45
    z = 0.05 * np.sin(cx * 7) * np.cos(cy * 5)
    c = np.stack([cx, cy, z], axis=1)
    p = [c + [-h, -h, 0], c + [h, -h, 0], c + [h, h, 0], c + [-h, h, 0]]
    verts = np.concatenate([np.stack([p[0], p[1], p[2]], 1), np.stack([p[0], p[2], p[3]], 1)]).astype(np.float32)
    normals = np.zeros_like(verts)
    normals[..., 2] = 1.0
    n = len(verts)
    light = np.array([[[-0.5, -0.5, 2], [0.5, 0.5, 2], [0.5, -0.5, 2]], [[-0.5, -0.5, 2], [-0.5, 0.5, 2],
                                                                         [0.5, 0.5, 2]]], np.float32)
    verts = np.concatenate([verts, light])
    normals = np.concatenate([normals, np.repeat(np.array([0, 0, -1.0], np.float32)[None, None], 2, 0).repeat(3, 1)])
    material = np.concatenate([np.zeros(n, np.int32), np.ones(2, np.int32)])
    instance = np.zeros(len(verts), np.int32)
    instance[:int(n * moving_share)] = 1
    mats = MaterialTable.build([{"base_color": (0.6, 0.6, 0.6), "f0": 0.04},
                                {"base_color": (0, 0, 0), "emission": (8.0, 8.0, 8.0)}])
    geom = TriangleSet(verts, normals.astype(np.float32), material, instance=instance)
    cam = perspective_camera((0.0, -3.5, 3.0), (0.0, 0.0, 0.0), width, height)
    out = Scene(geom, mats, Lamps.empty(), cam)
    steps = np.repeat(np.eye(4)[None, None], 3, axis=0).repeat(2, axis=1)
    steps[:, 1, 0, 3] = [-0.25, 0.0, 0.25]
    moving = ShutterMotion(steps, np.repeat(np.eye(4)[None], 2, axis=0))
    cams = np.repeat(cam.cam_to_world[None], 3, axis=0).copy()
    cams[:, 0, 3] += [-0.1, 0.0, 0.1]
    camera_only = ShutterMotion(np.repeat(np.eye(4)[None, None], 3, axis=0).repeat(2, axis=1),
                                np.repeat(np.eye(4)[None], 2, axis=0), camera_steps=cams)
    return out, moving, camera_only


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--triangles", type=int, default=1_000_000)
    ap.add_argument("--moving", type=float, default=0.01)
    ap.add_argument("--samples", type=int, default=8)
    ap.add_argument("--size", default="320x180")
    ap.add_argument("--out", default=os.path.join(RESULTS, "motion_blur", "motion_blur.json"))
    a = ap.parse_args()
    import dataclasses

    from restir_engine.core.geometry.accel import Accel
    from restir_engine.core.integrators import context_cache
    from restir_engine.core.renderer import RenderSettings, render_frame
    w, h = (int(v) for v in a.size.split("x"))
    base, moving, camera_only = scene(a.triangles, a.moving, w, h)
    t0 = time.perf_counter()
    Accel(base.geometry.verts)
    full_build = time.perf_counter() - t0
    st = RenderSettings(samples=a.samples, seed=0, max_bounces=1, integrator="PATH")
    runs = {}
    for name, blur in (("sharp", None), ("camera moves", camera_only), ("1% of triangles move", moving)):
        context_cache.clear()
        sc = dataclasses.replace(base, blur=blur)
        t0 = time.perf_counter()
        res = render_frame(sc, st, processes=1)
        runs[name] = {"seconds": time.perf_counter() - t0, "per_pass": (time.perf_counter() - t0) / a.samples,
                      "samples": res.samples_done}
        print(f"{name:24s} {runs[name]['seconds']:.2f} s for {a.samples} passes "
              f"({runs[name]['per_pass']:.3f} s per pass)")
    print(f"full Embree build of {len(base.geometry)} triangles: {full_build:.3f} s (a naive per-pass rebuild)")
    write_json(a.out, {"triangles": len(base.geometry), "moving_share": a.moving, "size": [w, h],
                       "samples": a.samples, "full_embree_build_seconds": full_build, "runs": runs})
    bar_chart(os.path.splitext(a.out)[0] + ".png", list(runs), [r["per_pass"] for r in runs.values()],
              "seconds per sample pass", f"Motion blur cost, {len(base.geometry) / 1e6:.1f}M triangles, {w}x{h}",
              ("full BVH build (a naive per-pass rebuild)", full_build))


if __name__ == "__main__":
    main()
