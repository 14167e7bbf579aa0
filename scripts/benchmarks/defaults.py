"""Default against default: each engine as a new file renders (ours: the add-on's defaults, Denoise and Noise
Threshold on; Cycles: its defaults, adaptive sampling, Open Image Denoise, indirect clamp 10, light threshold 0.01),
at several sample counts, on the harness scenes; relMSE against Cycles without denoising, clamping or adaptive
sampling at 1024 samples (Cycles' default bounces and film, Blackman-Harris 1.5 px as both engines' default) and
the wall time of the whole render (export, render, denoising).

    .venv313/bin/python scripts/bench.py defaults [--scenes cornell,interior_gi] [--size medium] [--chart]
        -> docs/results/defaults/defaults.{json,png}
"""
from __future__ import annotations

import argparse
import os
import tempfile


from benchmarks.common import RESULTS, render_rgb as render, write_json

OUT = os.path.join(RESULTS, "defaults")
SCENES = {"cornell": "default", "many_lights": "1k", "glossy": "0.2", "interior_gi": "default",
          "default_cube": "default"}
OURS_SPP = (4, 16, 64)
CYCLES_SPP = (8, 32, 128, 512)
REF_SPP = 1024


def cycles_defaults(scene, samples: int, seed: int) -> None:
    """Cycles as a new file has it (CPU), at ``samples``."""
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device, c.samples, c.seed = "CPU", samples, seed
    c.use_adaptive_sampling, c.adaptive_threshold, c.adaptive_min_samples = True, 0.01, 0
    c.use_denoising, c.denoiser = True, "OPENIMAGEDENOISE"
    c.sample_clamp_direct, c.sample_clamp_indirect, c.light_sampling_threshold = 0.0, 10.0, 0.01
    c.max_bounces, c.diffuse_bounces, c.glossy_bounces = 12, 4, 4
    c.transmission_bounces, c.volume_bounces, c.transparent_max_bounces = 12, 0, 8
    c.pixel_filter_type, c.filter_width = "BLACKMAN_HARRIS", 1.5
    c.blur_glossy = 1.0
    c.time_limit = 0.0
    scene.render.film_transparent = False


def reference(scene, seed: int) -> None:
    """Cycles' defaults without what trades bias or blur for noise: no denoising, clamping, light threshold,
    glossy filter or adaptive sampling."""
    cycles_defaults(scene, REF_SPP, seed)
    c = scene.cycles
    c.use_adaptive_sampling = c.use_denoising = False
    c.sample_clamp_indirect = c.light_sampling_threshold = c.blur_glossy = 0.0


def ours_defaults(scene, samples: int, seed: int) -> None:
    """The add-on's defaults (every scene.restir setting at its default) at ``samples``."""
    from restir_engine.properties import SCENE_FIELDS
    scene.render.engine = "RESTIR"
    for f in SCENE_FIELDS:
        scene.restir.property_unset(f.name)
    scene.restir.samples, scene.restir.seed = samples, seed


def chart(results: dict, path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker
    names = list(results)
    fig, axes = plt.subplots(1, len(names), figsize=(3.2 * len(names), 3.2), squeeze=False)
    for ax, name in zip(axes[0], names):
        for label, style in (("ours", "o-"), ("Cycles", "s--")):
            rows = results[name][label]
            ax.loglog([r["seconds"] for r in rows], [r["rel_mse"] for r in rows], style, label=label)
        ax.set_title(name, fontsize=9)
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xlabel("seconds (wall)", fontsize=8)
        ax.grid(True, which="both", alpha=0.3)
    axes[0][0].set_ylabel(f"relMSE vs Cycles {REF_SPP} spp", fontsize=8)
    axes[0][0].legend(fontsize=8)
    fig.suptitle("Default against default (denoised, adaptive sampling on in both)", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", default=",".join(SCENES))
    ap.add_argument("--size", default="medium")
    ap.add_argument("--chart", action="store_true", help="redraw the chart from the stored JSON")
    a = ap.parse_args()
    if a.chart:
        import json
        with open(os.path.join(OUT, "defaults.json")) as fh:
            chart(json.load(fh)["results"], os.path.join(OUT, "defaults.png"))
        return
    import bpy

    import restir_engine
    from harness.metrics import rel_mse
    from harness.scenes import ensure_blend
    if not hasattr(bpy.types.Scene, "restir"):
        restir_engine.register()
    os.makedirs(OUT, exist_ok=True)
    tmp = tempfile.mkdtemp()
    results = {}
    for name in a.scenes.split(","):
        bpy.ops.wm.open_mainfile(filepath=ensure_blend(name, SCENES[name], a.size))
        scene = bpy.context.scene
        reference(scene, 0)
        ref, ref_s = render(scene, os.path.join(tmp, "ref.exr"))
        runs = {"ours": [], "Cycles": [], "reference_seconds": ref_s}
        for spp in OURS_SPP:
            ours_defaults(scene, spp, 1)
            img, s = render(scene, os.path.join(tmp, "ours.exr"))
            runs["ours"].append({"spp": spp, "seconds": s, "rel_mse": rel_mse(img, ref)})
        for spp in CYCLES_SPP:
            cycles_defaults(scene, spp, 1)
            img, s = render(scene, os.path.join(tmp, "cycles.exr"))
            runs["Cycles"].append({"spp": spp, "seconds": s, "rel_mse": rel_mse(img, ref)})
        results[name] = runs
        print(name, "  ".join(f"{k} " + " ".join(f"{r['spp']}:{r['rel_mse']:.4f}@{r['seconds']:.1f}s" for r in v)
                              for k, v in runs.items() if isinstance(v, list)), flush=True)
        write_json(os.path.join(OUT, "defaults.json"), {"size": a.size, "reference_spp": REF_SPP,
                                                        "results": results})
    chart(results, os.path.join(OUT, "defaults.png"))


if __name__ == "__main__":
    main()
