"""Adaptive sampling against uniform sampling at equal time, ours and Cycles', on a sky over a dark interior.

The scene (built here through bpy): a sunlit ground under a blue sky and a box room open towards the camera, whose
inside only the sky and the bounce light from the ground reach, so the image holds noiseless sky, a bright and
quickly converging ground and a dark, slowly converging interior. Each engine renders it with a Time Limit of
T seconds (samples capped high enough never to stop first), once sampling every pixel and once with adaptive
sampling at its default Noise Threshold (0.01, automatic minimum); relMSE of each image against Cycles at
REF_SPP samples; the spread of the samples over pixels is reported from our Sample Count pass.

    .venv313/bin/python scripts/bench.py adaptive      # -> docs/results/adaptive/adaptive.{json,png}
"""
from __future__ import annotations

import math
import os
import sys
import tempfile
import time

from benchmarks.common import ROOT, write_json  # noqa: E402, F401
for p in (ROOT, os.path.join(ROOT, "scripts"), os.path.join(ROOT, "tests")):
    sys.path.insert(0, p)

import bpy  # noqa: E402

import restir_engine  # noqa: E402
from bpy_scenes import configure_cycles, configure_restir  # noqa: E402
from harness.metrics import rel_mse  # noqa: E402
from harness.render import read_exr, use_multilayer_exr  # noqa: E402
from harness.scenes import camera, diffuse, enable_nodes, light, plane, reset, set_size  # noqa: E402

SIZE = (240, 135)
BOUNCES = 3
TIMES = (2.0, 4.0, 8.0, 16.0)
CAP = 4096  # samples: never reached within the time limits
REF_SPP = 2048
OUT = os.path.join(ROOT, "docs", "results", "adaptive")


def build_sky_interior():
    """The sky over a sunlit ground and a dark room open towards the camera."""
    scene = reset()
    ground = diffuse("Ground", (0.5, 0.5, 0.5))
    wall = diffuse("Wall", (0.7, 0.7, 0.7))
    plane("Ground", 60, (0, 0, 0), material=ground)
    plane("RoomFloor", 4, (0, 2, 0.01), material=wall)
    plane("Ceiling", 4, (0, 2, 2.5), (math.pi, 0, 0), material=wall)
    plane("Back", 4, (0, 4, 1.25), (math.pi / 2, 0, 0), material=wall, scale=(1, 0.625, 1))
    plane("Left", 4, (-2, 2, 1.25), (0, math.pi / 2, 0), material=wall, scale=(0.625, 1, 1))
    plane("Right", 4, (2, 2, 1.25), (0, -math.pi / 2, 0), material=wall, scale=(0.625, 1, 1))
    plane("Roof", 4.4, (0, 2, 2.55), material=wall)
    light("SUN", (0, 0, 10), (math.radians(50), 0, math.radians(150)), energy=3.0)
    camera((0.0, -7.0, 1.6), (math.radians(84), 0, 0), lens=30)
    world = bpy.data.worlds.new("Sky")
    enable_nodes(world)
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (0.45, 0.6, 1.0, 1.0)
    bg.inputs["Strength"].default_value = 1.0
    scene.world = world
    set_size(scene, SIZE)
    scene.render.resolution_percentage = 100
    return scene


def render(scene, path):
    use_multilayer_exr(scene)
    scene.render.filepath = path
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    seconds = time.perf_counter() - t0
    return read_exr(path), seconds


def chart(runs) -> None:
    """relMSE against wall time per run (docs/results/adaptive/adaptive.png)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    for name, rows in runs.items():
        ax.loglog([r["seconds"] for r in rows], [r["rel_mse"] for r in rows], "o-" if "ours" in name else "s--",
                  label=name)
    ax.set_xlabel("wall time of the render (s)")
    ax.set_ylabel(f"relMSE vs Cycles {REF_SPP} spp")
    ax.set_title("Adaptive vs uniform sampling, sky over a dark room")
    ax.legend()
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "adaptive.png"), dpi=110)


def main():
    if "--chart" in sys.argv:  # redraw the chart from the stored results
        import json
        chart(json.load(open(os.path.join(OUT, "adaptive.json")))["runs"])
        return 0
    if not hasattr(bpy.types.Scene, "restir"):
        restir_engine.register()
    os.makedirs(OUT, exist_ok=True)
    tmp = tempfile.mkdtemp()
    scene = build_sky_interior()
    configure_cycles(scene, REF_SPP, BOUNCES, 0)
    passes, ref_s = render(scene, os.path.join(tmp, "ref.exr"))
    ref = passes["Combined"][..., :3]
    print(f"reference: Cycles {REF_SPP} spp in {ref_s:.1f}s", flush=True)
    runs = {"ours uniform": [], "ours adaptive": [], "Cycles uniform": [], "Cycles adaptive": []}
    scene.view_layers[0].restir.use_pass_sample_count = True
    for t in TIMES:
        for adaptive in (False, True):
            configure_restir(scene, CAP, BOUNCES, 1)
            scene.restir.time_limit = t
            scene.restir.use_adaptive_sampling = adaptive
            out, s = render(scene, os.path.join(tmp, "ours.exr"))
            row = {"time_limit": t, "seconds": s, "rel_mse": rel_mse(out["Combined"][..., :3], ref)}
            if adaptive and "Sample Count" in out:
                counts = out["Sample Count"][..., 0]
                row.update(mean_samples=float(counts.mean()), min_samples=float(counts.min()),
                           max_samples=float(counts.max()))
            runs["ours adaptive" if adaptive else "ours uniform"].append(row)
            configure_cycles(scene, CAP, BOUNCES, 1)
            scene.cycles.time_limit = t
            scene.cycles.use_adaptive_sampling = adaptive
            scene.cycles.adaptive_threshold = 0.01
            scene.cycles.adaptive_min_samples = 0
            out, s = render(scene, os.path.join(tmp, "cycles.exr"))
            runs["Cycles adaptive" if adaptive else "Cycles uniform"].append(
                {"time_limit": t, "seconds": s, "rel_mse": rel_mse(out["Combined"][..., :3], ref)})
        print(f"T {t:4.1f}s: " + "  ".join(f"{k} {v[-1]['rel_mse']:.5f} ({v[-1]['seconds']:.1f}s)"
                                           for k, v in runs.items()), flush=True)
    write_json(os.path.join(OUT, "adaptive.json"), {"size": SIZE, "bounces": BOUNCES, "reference_spp": REF_SPP,
                                                    "runs": runs})
    chart(runs)
    return 0


if __name__ == "__main__":
    sys.exit(main())
