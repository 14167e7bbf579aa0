"""Peak memory of F12 at 3840x2160 and 7680x4320 with the demo file's own settings (Auto methods), one process.

Each resolution renders in a fresh Python process (its peak RSS is the process's own: ru_maxrss), through
bpy.ops.render.render as F12 does, 1 sample, Processes 1 (the worker processes' shared film would otherwise be
counted in every process's RSS); the engine then renders in bands when the frame's working set exceeds
memory.BAND_BYTES, and denoises the frame (the default). Targets (issue 31): 4K within 4 GB, 8K within 12 GB.

    .venv313/bin/python scripts/bench.py memory_bands     # -> docs/results/memory_bands.json
"""
from __future__ import annotations

import json
import os
import subprocess
import sys

from benchmarks.common import ROOT, write_json

SIZES = ((3840, 2160), (7680, 4320))

CHILD = r"""
import json, resource, sys, time
sys.path[:0] = [{root!r}, {root!r} + "/scripts", {root!r} + "/tests"]
import bpy
import restir_engine
from make_demo_scene import build_demo
restir_engine.register()
scene = build_demo(resolution=({w}, {h}))
scene.render.resolution_percentage = 100
scene.render.engine = "RESTIR"
scene.restir.samples = 1
scene.restir.processes = 1
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
t0 = time.perf_counter()
bpy.ops.render.render()
from restir_engine.engine import LAST_FRAME_STATS
print("RESULT", json.dumps({{"resolution": [{w}, {h}], "seconds": time.perf_counter() - t0,
      "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, "rss_before_render_mb": before,
      "bands": LAST_FRAME_STATS.get("bands", 1),
      "denoise_seconds": LAST_FRAME_STATS.get("denoise_seconds"), "direct_method": LAST_FRAME_STATS.get("direct_method"),
      "indirect_method": LAST_FRAME_STATS.get("indirect_method")}}))
"""


def main():
    only = [tuple(int(v) for v in a.split("x")) for a in sys.argv[1:]] or SIZES
    rows = []
    for w, h in only:
        out = subprocess.run([sys.executable, "-c", CHILD.format(root=ROOT, w=w, h=h)], capture_output=True,
                             text=True)
        line = [x for x in out.stdout.splitlines() if x.startswith("RESULT ")]
        if not line:
            print(out.stdout[-2000:], out.stderr[-2000:])
            rows.append({"resolution": [w, h], "failed": out.returncode})
            continue
        rows.append(json.loads(line[0][7:]))
        print(rows[-1], flush=True)
    path = os.path.join(ROOT, "docs", "results", "memory_bands.json")
    old = json.load(open(path))["runs"] if os.path.exists(path) else []
    keep = [r for r in old if tuple(r["resolution"]) not in {tuple(x["resolution"]) for x in rows}]
    write_json(path, {"runs": sorted(keep + rows, key=lambda r: r["resolution"])})
    return 0


if __name__ == "__main__":
    sys.exit(main())
