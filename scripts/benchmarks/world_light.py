"""Equal-time gain of sampling the world as a light (core/lights/world.py) over collecting it by BSDF rays alone.

Scene: tests/bpy_scenes.world_scene (three spheres on a floor, no lamps) under an environment image with a small
sun (the sky of the tests) and under a constant colour, 160x90, direct light only and 3 bounces. Reference: Cycles
at 2048 samples (same bpy). Ours: the path tracer at 1..32 samples with the world light-sampled (the default) and
with that sampling switched off; relMSE of Combined against the reference and the render time (core, after export).

    .venv/bin/python scripts/bench.py world_light      # -> docs/results/world/world_light.{json,png}
"""
from __future__ import annotations

import os
import sys
import time

from benchmarks.common import ROOT, write_json  # noqa: E402, F401
for p in (ROOT, os.path.join(ROOT, "scripts"), os.path.join(ROOT, "tests")):
    sys.path.insert(0, p)

import bpy  # noqa: E402

import restir_engine  # noqa: E402
from bpy_scenes import configure_cycles, render_passes, world_scene  # noqa: E402
from harness.metrics import interpolate_loglog, rel_mse  # noqa: E402
from restir_engine.core.integrators import context_cache  # noqa: E402
from restir_engine.core.lights.world import World  # noqa: E402
from restir_engine.core.renderer import RenderSettings, render_frame  # noqa: E402
from restir_engine.export import export_scene  # noqa: E402

SIZE = (160, 90)
SPP = (1, 2, 4, 8, 16, 32)
REF_SPP = 2048
OUT = os.path.join(ROOT, "docs", "results", "world")


def reference(kind, bounces):
    scene = world_scene(kind, SIZE, rotation_z=0.8)
    configure_cycles(scene, REF_SPP, bounces, 0)
    return render_passes(scene)["Combined"][..., :3]


def ladder(core_scene, bounces, sampled: bool, ref):
    orig = World.__init__

    def patched(self, *a, **k):
        orig(self, *a, **k)
        if not sampled:
            self.sampled = False
    World.__init__ = patched
    context_cache.clear()
    try:
        render_frame(core_scene, RenderSettings(integrator="PATH", max_bounces=bounces, samples=1, seed=99))
        rows = []
        for spp in SPP:
            t0 = time.perf_counter()
            r = render_frame(core_scene, RenderSettings(integrator="PATH", max_bounces=bounces, samples=spp, seed=1))
            rows.append({"spp": spp, "seconds": time.perf_counter() - t0,
                         "rel_mse": rel_mse(r.passes["Combined"][..., :3], ref)})
    finally:
        World.__init__ = orig
        context_cache.clear()
    return rows


def main():
    if not hasattr(bpy.types.Scene, "restir"):
        restir_engine.register()
    os.makedirs(OUT, exist_ok=True)
    results = []
    for kind in ("IMAGE", "CONSTANT"):
        for bounces in (0, 3):
            ref = reference(kind, bounces)
            world_scene(kind, SIZE, rotation_z=0.8)
            core_scene = export_scene(bpy.context.evaluated_depsgraph_get())
            on = ladder(core_scene, bounces, True, ref)
            off = ladder(core_scene, bounces, False, ref)
            # equal-time ratio: relMSE of BSDF-only sampling at the time light sampling took, over light sampling's
            t_on = [r["seconds"] for r in on]
            gain = [float(interpolate_loglog([r["seconds"] for r in off], [r["rel_mse"] for r in off], t) / e)
                    for t, e in zip(t_on, [r["rel_mse"] for r in on])]
            res = {"world": kind, "bounces": bounces, "light_sampled": on, "bsdf_only": off,
                   "equal_time_gain": gain}
            results.append(res)
            print(f"{kind:<8} bounces {bounces}: gain at equal time " + ", ".join(f"{g:.2f}" for g in gain),
                  flush=True)
    write_json(os.path.join(OUT, "world_light.json"), {"size": SIZE, "reference_spp": REF_SPP, "runs": results})
    chart(results, os.path.join(OUT, "world_light.png"))


def chart(results, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(results), figsize=(4 * len(results), 3.4))
    for ax, r in zip(axes, results):
        for key, label in (("light_sampled", "world light-sampled + MIS"), ("bsdf_only", "BSDF rays only")):
            ax.loglog([x["seconds"] for x in r[key]], [x["rel_mse"] for x in r[key]], "o-", label=label)
        ax.set_title(f"{r['world'].lower()} world, {r['bounces']} bounces", fontsize=9)
        ax.set_xlabel("seconds (160x90)")
    axes[0].set_ylabel("relMSE vs Cycles 2048 spp")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
