"""What ReSTIR does on glass: error of the pixels seen through (or in) smooth glass against the pixels that see
rough surfaces directly, for the path tracer and the default integrator (ReSTIR DI + GI), at equal samples.

Scenes: tests/bpy_scenes.glass_scene (three smooth glass spheres before a checkered wall) and the same seen
partly through a 2 cm glass pane (a window), 160x90, 4 bounces.
Reference: Cycles at 2048 samples (same bpy). Pixels are split by what the camera ray through the pixel centre
hits first (a glass closure or not).

    .venv/bin/python scripts/bench.py glass      # -> docs/results/materials/glass.{json,png}
"""
from __future__ import annotations

import os
import sys
import time

from benchmarks.common import ROOT, write_json  # noqa: E402, F401
for p in (ROOT, os.path.join(ROOT, "scripts"), os.path.join(ROOT, "tests")):
    sys.path.insert(0, p)

import bpy  # noqa: E402
import numpy as np  # noqa: E402

import restir_engine  # noqa: E402
from bpy_scenes import configure_cycles, glass_scene, render_passes  # noqa: E402
from restir_engine.core.integrators import camera_paths, trace_context  # noqa: E402
from restir_engine.core.renderer import RenderSettings, render_frame  # noqa: E402
from restir_engine.engine import settings_from_scene  # noqa: E402
from restir_engine.export import export_scene  # noqa: E402

SIZE = (160, 90)
BOUNCES = 4
SPP = (1, 4, 16)
SEEDS = 4
REF_SPP = 2048
OUT = os.path.join(ROOT, "docs", "results", "materials")


def glass_mask(core) -> np.ndarray:
    """(h, w) bool: the camera ray through the pixel centre first meets a glass closure."""
    ctx = trace_context.build_context(core, BOUNCES)
    h, w = SIZE[1], SIZE[0]
    y, x = np.mgrid[0:h, 0:w]
    hits = camera_paths.primary(ctx, (x.ravel() + 0.5).astype(np.float32), (y.ravel() + 0.5).astype(np.float32))
    mask = np.zeros(h * w, bool)
    if hits.surf.glass is not None:
        mask[hits.rows[hits.surf.glass]] = True
    return mask.reshape(h, w)


def rel_mse_in(img, ref, mask):
    """relMSE over the pixels of ``mask``, each pixel's relative squared error clipped at 1 (a 100 % error): with a
    few seeds the whole-image value is ruled by rare caustic and Fresnel-branch fireflies."""
    d = (img[mask] - ref[mask]) ** 2 / (ref[mask] ** 2 + 1e-2)
    return float(np.minimum(d, 1.0).mean())


def main():
    restir_engine.register()
    out = {"created": time.strftime("%Y-%m-%d"), "size": SIZE, "bounces": BOUNCES, "scenes": {}}
    for key, window in (("spheres", False), ("window", True)):
        out["scenes"][key] = measure(window)
    os.makedirs(OUT, exist_ok=True)
    write_json(os.path.join(OUT, "glass.json"), out)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for ax, (key, res) in zip(axes, out["scenes"].items()):
        for (name, rows), color in zip(res["methods"].items(), ("C0", "C1")):
            ax.loglog([r["samples"] for r in rows], [r["glass"] for r in rows], "o-", color=color,
                      label=f"{name}: glass pixels")
            ax.loglog([r["samples"] for r in rows], [r["other"] for r in rows], "s--", color=color,
                      label=f"{name}: other pixels")
        ax.set_xlabel("samples per pixel")
        ax.set_ylabel("relMSE (per pixel clipped at 1) vs Cycles 2048 spp")
        ax.set_title(f"glass_scene ({key}) {SIZE[0]}x{SIZE[1]}, {BOUNCES} bounces")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "glass.png"), dpi=110)


def measure(window: bool) -> dict:
    scene = glass_scene(SIZE, window=window)
    configure_cycles(scene, REF_SPP, BOUNCES, 0)
    t0 = time.perf_counter()
    ref = render_passes(scene)["Combined"][..., :3]
    print(f"reference: {time.perf_counter() - t0:.1f} s", flush=True)
    scene = glass_scene(SIZE, window=window)
    core = export_scene(bpy.context.evaluated_depsgraph_get())
    mask = glass_mask(core)
    base = settings_from_scene(scene)
    out = {"glass_pixels": int(mask.sum()), "methods": {}}
    for name, integrator in (("path tracer", "PATH"), ("default (ReSTIR DI + GI)", "RESTIR")):
        rows = []
        for spp in SPP:
            g, o, secs = [], [], []
            for seed in range(SEEDS):
                st = RenderSettings(**{**base.__dict__, "samples": spp, "seed": seed + 1, "max_bounces": BOUNCES,
                                       "integrator": integrator, "data_passes": False})
                res = render_frame(core, st)
                img = res.passes["Combined"][..., :3]
                g.append(rel_mse_in(img, ref, mask))
                o.append(rel_mse_in(img, ref, ~mask))
                secs.append(res.seconds)
            rows.append({"samples": spp, "glass": float(np.mean(g)), "other": float(np.mean(o)),
                         "seconds": float(np.median(secs))})
            print(f"{'window' if window else 'spheres'}: {name:<26} {spp:3d} spp  through glass "
                  f"{rows[-1]['glass']:.4f}  elsewhere {rows[-1]['other']:.4f}  {rows[-1]['seconds']:.2f} s",
                  flush=True)
        out["methods"][name] = rows
    return out


if __name__ == "__main__":
    main()
