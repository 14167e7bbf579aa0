"""A frame's peak memory per pixel by method, measured (tracemalloc peak of two frames with history, as an
animation renders them, and of one still frame, as F12 renders it: no history kept) against the estimate the engine
refuses or warns by (core/pipeline/memory.py).

Prints and writes docs/results/memory.json. Usage: python scripts/bench.py memory [--percent 200]
(the demo scene at 640x360 x percent/100).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import os
import tracemalloc

from benchmarks.common import RESULTS, write_json

# (name, settings that differ from the ReSTIR integrator's defaults)
CONFIGS = (
    ("path tracer", dict(integrator="PATH")),
    ("path tracer + denoising data", dict(integrator="PATH", denoise_data=True)),
    ("light sampling", dict(direct_method="LIGHT_SAMPLING", indirect_method="PATH")),
    ("ReSTIR DI", dict(direct_method="RESTIR", indirect_method="PATH")),
    ("ReSTIR GI", dict(direct_method="LIGHT_SAMPLING", indirect_method="RESTIR_GI")),
    ("ReSTIR DI + GI", dict(direct_method="RESTIR", indirect_method="RESTIR_GI")),
    ("Auto direct and indirect", dict(direct_method="AUTO", indirect_method="AUTO")),
)


def peak_bytes(scene, settings, frames: int = 2, keep_history: bool = True) -> int:
    """tracemalloc's peak over ``frames`` frames rendered in turn in this process (each with the history of the one
    before where ``keep_history``)."""
    from restir_engine.core.pipeline import film
    from restir_engine.core.renderer import render_frame
    film.BUFFERS.free.clear()  # the film's accumulators are counted: none come from an earlier frame's pool
    tracemalloc.start()
    base = tracemalloc.get_traced_memory()[0]
    history = None
    for f in range(1, frames + 1):
        history = render_frame(scene, dataclasses.replace(settings, frame=f), history=history, processes=1,
                               bands=1, keep_history=keep_history).history
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return peak - base


def main():
    p = argparse.ArgumentParser(prog="bench.py memory")
    p.add_argument("--percent", type=int, default=200)
    p.add_argument("--samples", type=int, default=2)
    args = p.parse_args()
    import bpy

    import restir_engine
    from make_demo_scene import build_demo
    from restir_engine.core.pipeline import memory
    from restir_engine.core.renderer import RenderSettings
    from restir_engine.export import export_scene
    if not hasattr(bpy.types.Scene, "restir"):
        restir_engine.register()
    w, h = 640 * args.percent // 100, 360 * args.percent // 100
    build_demo(resolution=(w, h))
    scene = export_scene(bpy.context.evaluated_depsgraph_get())
    rows = []
    for name, kw in CONFIGS:
        st = RenderSettings(**{"samples": args.samples, "max_bounces": 1, "integrator": "RESTIR", **kw})
        measured = peak_bytes(scene, st)
        still = peak_bytes(scene, st, frames=1, keep_history=False)
        est = memory.frame_estimate(scene, st)
        rows.append({"config": name, "settings": kw, "measured_bytes_per_pixel": round(measured / (w * h)),
                     "still_bytes_per_pixel": round(still / (w * h)),
                     "estimate_low_bytes_per_pixel": round(est.low / (w * h)),
                     "estimate_high_bytes_per_pixel": round(est.high / (w * h))})
        print(json.dumps(rows[-1]), flush=True)
    out = {"resolution": [w, h], "samples": args.samples, "bounces": 1, "rows": rows,
           "note": "tracemalloc peak of the core (NumPy arrays) over two frames with history (measured) and of "
                   "one frame keeping none (still); the estimate adds a fixed 64 MB and the scene"}
    write_json(os.path.join(RESULTS, "memory.json"), out, indent=2)


if __name__ == "__main__":
    main()
