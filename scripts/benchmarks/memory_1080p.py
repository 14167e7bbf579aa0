"""Peak memory and time of one 1920x1080 ReSTIR DI + ReSTIR GI frame of the demo scene (target: RSS under 4 GB).

Prints and writes docs/results/memory_1080p.json. Usage: python scripts/bench.py memory_1080p
"""
from __future__ import annotations

import json
import os
import resource
import time

from benchmarks.common import ROOT, write_json  # noqa: E402, F401

import bpy  # noqa: E402

import restir_engine  # noqa: E402
from make_demo_scene import build_demo  # noqa: E402
from restir_engine.core.renderer import RenderSettings, render_frame  # noqa: E402
from restir_engine.export import export_scene  # noqa: E402


def peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # Linux: kilobytes


def main():
    if not hasattr(bpy.types.Scene, "restir"):
        restir_engine.register()
    build_demo(resolution=(1920, 1080))
    scene = export_scene(bpy.context.evaluated_depsgraph_get())
    before = peak_mb()
    t0 = time.perf_counter()
    render_frame(scene, RenderSettings(samples=1, max_bounces=1, integrator="RESTIR", direct_method="RESTIR",
                                       indirect_method="RESTIR_GI"))
    out = {"resolution": [1920, 1080], "method": "ReSTIR DI + ReSTIR GI (defaults), 1 spp, 1 bounce",
           "seconds": time.perf_counter() - t0, "peak_rss_mb": peak_mb(), "rss_before_render_mb": before}
    path = os.path.join(ROOT, "docs", "results", "memory_1080p.json")
    write_json(path, out, indent=2)
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
