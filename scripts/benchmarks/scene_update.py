"""Scene updates when one object moves in a 1M-triangle scene: the viewport's transform edit and an animation frame.

A scene of about 1M triangles (50 UV spheres of 20k triangles) and one sphere of 1 % of them. Measured per move
of that sphere, in Blender's process (bpy): the viewport's export at the TRANSFORM level (export/incremental.py:
only the moved object re-placed) and the renderer's context update (core/integrators/context_update.py: only the
moved rows' Embree scene rebuilt; the first move of an object builds the still part once); an animation frame's
full export (no mesh cache) and its context update; for comparison the context built from scratch (the cost of
every move before). Writes scene_update.json and scene_update.png.

The ``cores`` mode needs no bpy (numpy and embreex only, for a many-core machine): a core scene of 1M triangles
(benchmarks.motion_blur.scene) whose instance of 1 % of the triangles moves every frame, 1-sample path-traced
animation frames at 640x360 rendered by N worker processes, each updating its own context; against the same frames
made to rebuild (one far triangle's instance toggled every frame: another layout). Writes scene_update_cores.json.

    .venv313/bin/python scripts/bench.py scene_update [--moves 5]
    python3 scripts/bench.py scene_update cores [--processes 1,4,16] [--frames 6]
"""
from __future__ import annotations

import argparse
import os
import time

import numpy as np

from benchmarks.common import RESULTS, bar_chart, write_json


def build():
    import bpy
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.engine = "RESTIR"
    scene.render.resolution_x, scene.render.resolution_y = 320, 180
    for i in range(50):
        bpy.ops.mesh.primitive_uv_sphere_add(segments=128, ring_count=80, radius=0.4,
                                             location=((i % 10) - 5, (i // 10) - 2, 0))
    bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=80, location=(0, 0, 1.5), radius=0.3)
    mover = bpy.context.active_object
    mover.name = "Mover"
    bpy.ops.object.camera_add(location=(0, -12, 6), rotation=(1.1, 0, 0))
    scene.camera = bpy.context.active_object
    bpy.ops.object.light_add(type="AREA", location=(0, 0, 5))
    return scene, mover


def cores(argv) -> None:
    """Frame times of N worker processes when one object moves every frame (see the module's docstring)."""
    import dataclasses

    from benchmarks.motion_blur import scene as field_scene
    from restir_engine.core.integrators import context_cache
    from restir_engine.core.renderer import RenderSettings, render_frame
    ap = argparse.ArgumentParser()
    ap.add_argument("--processes", default="1,4,16")
    ap.add_argument("--frames", type=int, default=6)
    ap.add_argument("--triangles", type=int, default=1_000_000)
    ap.add_argument("--size", default="640x360")
    ap.add_argument("--out", default=os.path.join(RESULTS, "scene_update", "scene_update_cores.json"))
    a = ap.parse_args(argv)
    w, h = (int(v) for v in a.size.split("x"))
    base, _blur, _cam = field_scene(a.triangles, 0.01, w, h)
    moving = base.geometry.instance == 1
    st = RenderSettings(samples=1, seed=0, max_bounces=1, integrator="PATH")

    def frame_scene(k: int, rebuild: bool):
        verts = base.geometry.verts.copy()
        verts[moving, :, 0] += np.float32(0.05 * k)
        inst = base.geometry.instance.copy()
        if rebuild and k % 2:
            inst[0] = 2  # another layout: the context is built from scratch
        return dataclasses.replace(base, geometry=dataclasses.replace(base.geometry, verts=verts, instance=inst))

    results = {"triangles": len(base.geometry), "size": [w, h], "cpus": os.cpu_count(), "runs": []}
    for n in (int(v) for v in a.processes.split(",")):
        for mode in ("update", "rebuild"):
            context_cache.clear()
            hist, times = None, []
            for k in range(a.frames):
                t0 = time.perf_counter()
                r = render_frame(frame_scene(k, mode == "rebuild"), dataclasses.replace(st, frame=k + 1),
                                 history=hist, processes=n)
                times.append(time.perf_counter() - t0)
                hist = r.history
            steady = float(np.median(times[1:]))
            results["runs"].append({"processes": n, "mode": mode, "frame_seconds": times, "steady": steady})
            print(f"{n:3d} processes, {mode:8s}: steady frame {steady:.3f} s  ({', '.join(f'{t:.2f}' for t in times)})",
                  flush=True)
    write_json(a.out, results)


def main():
    import sys
    if sys.argv[1:2] == ["cores"]:
        return cores(sys.argv[2:])
    ap = argparse.ArgumentParser()
    ap.add_argument("--moves", type=int, default=5)
    ap.add_argument("--out", default=os.path.join(RESULTS, "scene_update", "scene_update.json"))
    a = ap.parse_args()
    import bpy

    import restir_engine
    from restir_engine.core.integrators import context_cache
    from restir_engine.core.pipeline.frame import FrameRenderer
    from restir_engine.core.renderer import RenderSettings
    from restir_engine.export import export_camera, export_scene
    from restir_engine.export.incremental import SceneExporter
    if not hasattr(bpy.types.Scene, "restir"):
        restir_engine.register()
    scene, mover = build()
    st = RenderSettings(samples=1, seed=0, max_bounces=1, integrator="PATH")
    dg = bpy.context.evaluated_depsgraph_get()
    cam = export_camera(dg, None, [])
    exporter = SceneExporter()
    t0 = time.perf_counter()
    first = exporter.export(dg, cam, "FULL")
    full_export = time.perf_counter() - t0
    context_cache.clear()
    t0 = time.perf_counter()
    FrameRenderer(first, st)
    scratch = time.perf_counter() - t0
    n = len(first.geometry)
    mover_index = [k[0] for k in first.export_stats["instance_keys"]].index("Mover")
    share = int((first.geometry.instance == mover_index).sum()) / n

    def timed(export):
        mover.location.x += 0.05
        mover.rotation_euler.z += 0.1
        dg = bpy.context.evaluated_depsgraph_get()
        t0 = time.perf_counter()
        core = export(dg)
        t1 = time.perf_counter()
        FrameRenderer(core, st)
        return t1 - t0, time.perf_counter() - t1

    viewport = [timed(lambda dg: exporter.export(dg, cam, "TRANSFORM")) for _ in range(a.moves)]
    frames = [timed(lambda dg: export_scene(dg, camera=cam)) for _ in range(a.moves)]
    context_cache.clear()
    out = {"triangles": n, "moving_share": share, "full_export_seconds": full_export,
           "context_from_scratch_seconds": scratch,
           "viewport_moves": [{"export": e, "context": c} for e, c in viewport],
           "animation_frames": [{"export": e, "context": c} for e, c in frames]}
    write_json(a.out, out)
    later = viewport[1:] or viewport
    print(f"{n} triangles, the moving object {share:.1%} of them")
    print(f"from scratch: export {full_export:.3f} s, context {scratch:.3f} s")
    for name, rows in (("viewport move", viewport), ("animation frame", frames)):
        for i, (e, c) in enumerate(rows):
            print(f"{name} {i + 1}: export {e:.3f} s, context {c:.3f} s, total {e + c:.3f} s")
    labels = ["from scratch", "first move", "later moves\n(median)", "animation\nframe (median)"]
    values = [full_export + scratch, sum(viewport[0]), float(np.median([e + c for e, c in later])),
              float(np.median([e + c for e, c in frames[1:] or frames]))]
    bar_chart(os.path.splitext(a.out)[0] + ".png", labels, values, "seconds (export + context)",
              f"One object ({share:.0%}) moves in {n / 1e6:.1f}M triangles", ("target 0.3 s", 0.3))


if __name__ == "__main__":
    main()
