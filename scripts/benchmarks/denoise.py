"""Raw versus denoised versus Cycles-denoised at equal time on the demo room.

Renders the built-in demo scene (scripts/make_demo_scene.py, frame 1, 4 bounces) at 320x180 through Blender (bpy):
ours at 1..128 samples without and with Denoise (Open Image Denoise in the engine, guided by the Denoising Albedo /
Normal, the defaults), and Cycles at 1..128 samples with its own Open Image Denoise; at 128 samples also both with
adaptive sampling on (the defaults of a new file in both engines; below 64 samples it changes nothing). Both with a
1-pixel box filter, as the reference. relMSE of each image against Cycles at 1024 samples, and the wall time of the
whole render (export, render, denoising).

    .venv/bin/python scripts/bench.py denoise      # -> docs/results/denoise/denoise.{json,png}
"""
from __future__ import annotations

import os
import sys
import tempfile

from benchmarks.common import ROOT, render_rgb as render, write_json  # noqa: E402, F401
for p in (ROOT, os.path.join(ROOT, "scripts"), os.path.join(ROOT, "tests")):
    sys.path.insert(0, p)

import bpy  # noqa: E402

import restir_engine  # noqa: E402
from bpy_scenes import configure_cycles, configure_restir  # noqa: E402
from harness.metrics import rel_mse  # noqa: E402
from make_demo_scene import build_demo  # noqa: E402

SIZE = (320, 180)
SPP = (1, 2, 4, 8, 16, 32, 64, 128)
ADAPTIVE_SPP = (128,)
REF_SPP = 1024
OUT = os.path.join(ROOT, "docs", "results", "denoise")


def main():
    if not hasattr(bpy.types.Scene, "restir"):
        restir_engine.register()
    os.makedirs(OUT, exist_ok=True)
    tmp = tempfile.mkdtemp()
    scene = build_demo(frames=2, resolution=SIZE)
    scene.render.resolution_percentage = 100
    scene.frame_set(1)
    configure_cycles(scene, REF_SPP, 4, 0)
    ref, ref_s = render(scene, os.path.join(tmp, "ref.exr"))
    print(f"reference: Cycles {REF_SPP} spp in {ref_s:.1f}s", flush=True)
    runs = {"ours raw": [], "ours denoised": [], "Cycles denoised (OIDN)": [],
            "ours adaptive + denoised": [], "Cycles adaptive + OIDN": []}

    def ours(name, spp, denoised, adaptive):
        configure_restir(scene, spp, 4, 1)
        scene.restir.use_denoising, scene.restir.use_adaptive_sampling = denoised, adaptive
        img, s = render(scene, os.path.join(tmp, "ours.exr"))
        from restir_engine.engine import LAST_FRAME_STATS
        runs[name].append({"spp": spp, "seconds": s, "rel_mse": rel_mse(img, ref),
                           "denoise_seconds": LAST_FRAME_STATS.get("denoise_seconds", 0.0)})

    def cycles(name, spp, adaptive):
        configure_cycles(scene, spp, 4, 1)
        scene.cycles.use_denoising, scene.cycles.use_adaptive_sampling = True, adaptive
        scene.cycles.denoiser = "OPENIMAGEDENOISE"
        img, s = render(scene, os.path.join(tmp, "cyc.exr"))
        scene.cycles.use_denoising = scene.cycles.use_adaptive_sampling = False
        runs[name].append({"spp": spp, "seconds": s, "rel_mse": rel_mse(img, ref)})

    for spp in SPP:
        ours("ours raw", spp, False, False)
        ours("ours denoised", spp, True, False)
        cycles("Cycles denoised (OIDN)", spp, False)
        if spp in ADAPTIVE_SPP:  # below Min Samples (64 at the default threshold) adaptive sampling changes nothing
            ours("ours adaptive + denoised", spp, True, True)
            cycles("Cycles adaptive + OIDN", spp, True)
        print(f"{spp:3d} spp: " + "  ".join(f"{k} {v[-1]['rel_mse']:.4f} ({v[-1]['seconds']:.2f}s)"
                                             for k, v in runs.items() if v and v[-1]["spp"] == spp), flush=True)
    write_json(os.path.join(OUT, "denoise.json"), {"size": SIZE, "reference_spp": REF_SPP, "runs": runs,
                                                   "adaptive_spp": ADAPTIVE_SPP})
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5.5, 3.8))
    for name, rows in runs.items():
        if rows:
            ax.loglog([r["seconds"] for r in rows], [r["rel_mse"] for r in rows], "s" if len(rows) == 1 else "o-",
                      label=name)
    ax.set_xlabel("seconds per frame (320x180, wall, incl. export and denoising)")
    ax.set_ylabel(f"relMSE vs Cycles {REF_SPP} spp")
    ax.set_title("Demo room: raw, denoised, Cycles denoised", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "denoise.png"), dpi=110)


if __name__ == "__main__":
    main()
