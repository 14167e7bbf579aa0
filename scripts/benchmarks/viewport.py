"""Rendered viewport latencies on the demo scene: the first image after a camera move (960x540 view, the
navigation budget's resolution divider), and the update after an edit (material colour, lamp power, object
move, mesh edit) by export level, with the renderer's rebuild.

    .venv/bin/python scripts/bench.py viewport     # -> docs/results/viewport/viewport.{json,png}

The session is driven as Blender drives it (no GPU: view_draw's texture upload is not timed).
"""
from __future__ import annotations

import argparse
import dataclasses
import os
import time

from benchmarks.common import ROOT, write_json  # noqa: E402, F401

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import restir_engine  # noqa: E402
from make_demo_scene import build_demo  # noqa: E402
from restir_engine.core.renderer import FrameRenderer  # noqa: E402
from restir_engine.engine import settings_from_scene  # noqa: E402
from restir_engine.export import export_scene  # noqa: E402
from restir_engine.export.incremental import SceneExporter, update_level  # noqa: E402
from restir_engine.viewport import ViewportSession  # noqa: E402


def wait_for(predicate, timeout=120.0):
    deadline = time.time() + timeout
    while not predicate():
        if time.time() > deadline:
            raise TimeoutError("the viewport worker did not get there in time")
        time.sleep(0.001)


def move_latencies(size, budget, moves):
    """Seconds from set_view to the new view's first image, per move (after a still view was refining)."""
    scene = build_demo(8, size)
    core = export_scene(bpy.context.evaluated_depsgraph_get())
    cam = core.camera
    settings = dataclasses.replace(settings_from_scene(scene), samples=1, data_passes=False, tile_pixels=16384)
    session = ViewportSession(lambda: None, budget=budget)
    session.set_scene(core, settings)
    session.set_view(cam, "start")
    wait_for(lambda: session.stats.divider == 1 and session.stats.samples >= 1)
    full_pass = session.stats.pass_seconds
    out = []
    for k in range(1, moves + 1):
        m = cam.cam_to_world.copy()
        m[:3, 3] += 0.03 * k * m[:3, 0]
        before = session.stats.navigation_passes
        t0 = time.perf_counter()
        session.set_view(dataclasses.replace(cam, cam_to_world=m), ("pan", k))
        wait_for(lambda: session.stats.navigation_passes > before)
        out.append({"latency": time.perf_counter() - t0, "divider": session.stats.divider,
                    "pass_seconds": session.stats.pass_seconds})
        time.sleep(0.3 if k % 2 else 0.05)  # sometimes during a refinement pass, sometimes right after
    session.halt()
    return full_pass, out


def edit_latencies(size, subdivision):
    """Seconds of the export an edit needs (by level) and of the renderer's rebuild, on the demo scene with
    Suzanne subdivided ``subdivision`` times (scene size)."""
    scene = build_demo(8, size)
    monkey = bpy.data.objects["Suzanne"]
    monkey.modifiers["Subdivision"].levels = subdivision
    lamp = bpy.data.lights.new("Lamp", "POINT")
    lamp_obj = bpy.data.objects.new("Lamp", lamp)
    lamp_obj.location = (0.0, -1.0, 3.0)
    scene.collection.objects.link(lamp_obj)
    dg = bpy.context.evaluated_depsgraph_get()
    exporter = SceneExporter()
    settings = dataclasses.replace(settings_from_scene(scene), samples=1, data_passes=False)
    cam = export_scene(dg).camera
    t0 = time.perf_counter()
    first = exporter.export(dg, cam, "FULL")
    t1 = time.perf_counter()
    FrameRenderer(first, settings)
    rows = [{"edit": "first export", "level": "FULL", "export": t1 - t0, "build": time.perf_counter() - t1,
             "triangles": len(first.geometry)}]
    seen = []

    def on_update(_scene, depsgraph):
        level = update_level(depsgraph.updates)
        a = time.perf_counter()
        core = exporter.export(depsgraph, cam, level)
        b = time.perf_counter()
        FrameRenderer(core, settings)
        seen.append({"level": exporter.last_level, "export": b - a, "build": time.perf_counter() - b,
                     "meshes_read": core.export_stats.get("meshes_read", 0)})

    bsdf = bpy.data.materials["Wall"].node_tree.nodes["Principled BSDF"]
    edits = [("material colour", lambda: setattr(bsdf.inputs["Base Color"], "default_value", (0.9, 0.2, 0.2, 1))),
             ("lamp power", lambda: setattr(lamp, "energy", 500.0)),
             ("object move", lambda: setattr(monkey, "location", (0.0, -1.0, 1.0))),
             ("mesh edit (modifier)", lambda: setattr(monkey.modifiers["Subdivision"], "levels", subdivision - 1))]
    bpy.app.handlers.depsgraph_update_post.append(on_update)
    try:
        for name, change in edits:
            seen.clear()
            change()
            bpy.context.view_layer.update()
            rows.append(dict(seen[-1], edit=name))
    finally:
        bpy.app.handlers.depsgraph_update_post.remove(on_update)
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "viewport"))
    ap.add_argument("--budget", type=float, default=0.15)
    args = ap.parse_args()
    restir_engine.register()
    out = {"created": time.strftime("%Y-%m-%d"), "budget": args.budget}
    full_pass, moves = move_latencies((960, 540), args.budget, 10)
    out["view_960x540"] = {"full_resolution_pass_seconds": full_pass, "moves": moves}
    lat = [m["latency"] for m in moves]
    print(f"960x540: full pass {full_pass:.2f} s; first image after a move: median {np.median(lat):.3f} s, "
          f"max {max(lat):.3f} s, dividers {sorted({m['divider'] for m in moves})}", flush=True)
    out["edits"] = {}
    for subdivision in (2, 5):
        rows = edit_latencies((640, 360), subdivision)
        out["edits"][f"suzanne_subdivision_{subdivision}"] = rows
        for r in rows:
            print(f"subdivision {subdivision} ({rows[0]['triangles']} triangles) {r['edit']:<22} {r['level']:<9} "
                  f"export {1000 * r['export']:7.1f} ms  renderer {1000 * r['build']:7.1f} ms", flush=True)
    os.makedirs(args.out, exist_ok=True)
    write_json(os.path.join(args.out, "viewport.json"), out)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
    a.plot(range(1, len(lat) + 1), [1000 * v for v in lat], "o-", label="first image after the move")
    a.axhline(1000 * args.budget, color="k", ls=":", label="navigation budget")
    a.axhline(300, color="r", ls="--", label="target 300 ms")
    a.set_xlabel("move")
    a.set_ylabel("ms")
    a.set_title(f"960x540 demo view (a full pass: {full_pass:.1f} s)")
    a.legend(fontsize=8)
    for k, (key, rows) in enumerate(out["edits"].items()):
        names = [r["edit"] for r in rows]
        tot = [1000 * (r["export"] + r["build"]) for r in rows]
        b.barh(np.arange(len(rows)) + 0.4 * k, tot, height=0.4, label=f"{key} ({rows[0]['triangles']} tris)")
    b.set_yticks(np.arange(len(names)) + 0.2, names)
    b.set_xscale("log")
    b.set_xlabel("ms (export + renderer rebuild)")
    b.set_title("update after an edit (640x360)")
    b.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(args.out, "viewport.png"), dpi=110)


if __name__ == "__main__":
    main()
