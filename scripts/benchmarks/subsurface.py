"""What subsurface scattering costs: F12 seconds of the six subsurface spheres (tests/bpy_scenes.SSS_GRID, 288x48,
16 samples) with their walks and with the share rendered as a diffuse lobe, for our path tracer, ReSTIR DI and
Cycles, at 0 and 4 bounces (the fastest of two renders after a warm-up; worker processes as Auto chooses).

Writes docs/results/subsurface/cost.json and cost.png. Usage:
  python scripts/bench.py subsurface [--samples 16] [--out DIR]
"""
from __future__ import annotations

import argparse
import os

from benchmarks.common import RESULTS, bar_chart, write_json

RUNS = (("path", dict(integrator="PATH")), ("ReSTIR DI", dict(integrator="RESTIR", direct_method="RESTIR")))


def _seconds(build, configure, seed0: int = 1) -> float:
    from harness.render import render_scene
    scene = build()
    configure(scene, 0)
    render_scene(scene)
    best = float("inf")
    for rep in range(2):
        configure(scene, seed0 + rep)
        best = min(best, render_scene(scene)[1])
    return best


def main() -> int:
    import restir_engine
    from bpy_scenes import configure_cycles, configure_restir, subsurface_spheres
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=16)
    parser.add_argument("--out", default=os.path.join(RESULTS, "subsurface"))
    args = parser.parse_args()
    restir_engine.register()
    size = (288, 48)
    out = {"size": list(size), "samples": args.samples, "seconds": {}}
    for bounces in (0, 4):
        for sss in (True, False):
            kind = "walks" if sss else "as diffuse"
            for name, settings in RUNS:
                out["seconds"][f"{name}, {kind}, {bounces} bounces"] = _seconds(
                    lambda: subsurface_spheres(size, sss=sss),
                    lambda scene, seed: configure_restir(scene, args.samples, bounces, seed, **settings))
            out["seconds"][f"Cycles, {kind}, {bounces} bounces"] = _seconds(
                lambda: subsurface_spheres(size, sss=sss),
                lambda scene, seed: configure_cycles(scene, args.samples, bounces, seed))
    for key, value in out["seconds"].items():
        print(f"{key:40s} {value:6.2f} s")
    write_json(os.path.join(args.out, "cost.json"), out)
    keys = list(out["seconds"])
    bar_chart(os.path.join(args.out, "cost.png"), [k.replace(", ", "\n") for k in keys],
              [out["seconds"][k] for k in keys], "seconds (F12)", "Subsurface spheres, 288x48, "
              f"{args.samples} samples")
    return 0
