"""ReSTIR GI on glossy materials and with the alternative target function.

    .venv/bin/python scripts/bench.py gi_materials          # -> docs/results/restir_gi/{roughness,target}.{json,png}

roughness: a closed room lit by a panel on its floor (the floor sees only bounced light), floor roughness 0.05 .. 1
as a dielectric (f0 0.04) and as a metal; relMSE of the indirect light against the path tracer at 1024 samples, for
ReSTIR GI (defaults, unbiased, still) and the path tracer at 4 samples, with their times (core only, no Blender).
target: interior_gi (exported through Blender) rendered with the GI target lum(f · Lo) |cos θ1| G (the default)
and lum(Lo) G, relMSE of Combined against the harness's Cycles reference.
"""
from __future__ import annotations

import argparse
import os
import time

from benchmarks.common import ROOT, write_json  # noqa: E402, F401


from harness.metrics import rel_mse  # noqa: E402
from restir_engine.core.renderer import RenderSettings, render_frame  # noqa: E402
from scenes_core import bounce_room  # noqa: E402

ROUGHNESS = (0.05, 0.1, 0.2, 0.3, 0.5, 0.75, 1.0)


WALL = {"base_color": (0.7, 0.7, 0.7), "roughness": 1.0, "f0": 0.0}


def room(floor: dict, width=96, height=72):
    """The closed room of tests/scenes_core.bounce_room (white Lambert walls, a panel on the floor), the floor
    material given, the camera looking a little lower than the tests' (more floor in view)."""
    return bounce_room(floor, WALL, width, height, look_at=(0.0, 0.5, 0.4))


def _indirect(scene, spp, seed, **kw):
    t0 = time.perf_counter()
    r = render_frame(scene, RenderSettings(samples=spp, max_bounces=1, seed=seed, integrator="RESTIR",
                                           direct_method="LIGHT_SAMPLING", **kw))
    return r.passes["Indirect"], time.perf_counter() - t0


def roughness(out, ref_spp, spp):
    result = {"roughness": list(ROUGHNESS), "ref_spp": ref_spp, "spp": spp, "runs": {}}
    for kind, base in (("dielectric", {"base_color": (0.6, 0.6, 0.6), "f0": 0.04}),
                       ("metal", {"base_color": (0.9, 0.8, 0.6), "metallic": 1.0})):
        rows = []
        for r in ROUGHNESS:
            scene = room({**base, "roughness": r})
            ref, _ = _indirect(scene, ref_spp, 999, indirect_method="PATH")
            _indirect(scene, 1, 5, indirect_method="RESTIR_GI")  # warm-up
            g, tg = _indirect(scene, spp, 1, indirect_method="RESTIR_GI")
            p, tp = _indirect(scene, spp, 1, indirect_method="PATH")
            row = {"roughness": r, "gi": rel_mse(g, ref), "gi_s": tg, "path": rel_mse(p, ref), "path_s": tp,
                   "bias_gi": float(g.mean() / ref.mean() - 1)}
            row["equal_time_path_over_gi"] = row["path"] * tp / (row["gi"] * tg)
            rows.append(row)
            print(f"{kind:<10} r {r:4.2f}: GI relMSE {row['gi']:.4f} ({tg:.2f}s)  path {row['path']:.4f} ({tp:.2f}s)"
                  f"  equal time path/GI {row['equal_time_path_over_gi']:.1f}  GI mean {row['bias_gi']:+.2%}",
                  flush=True)
        result["runs"][kind] = rows
    write_json(os.path.join(out, "roughness.json"), result)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
    for kind, rows in result["runs"].items():
        rr = [x["roughness"] for x in rows]
        a.semilogy(rr, [x["gi"] for x in rows], "o-", label=f"ReSTIR GI, {kind} floor")
        a.semilogy(rr, [x["path"] for x in rows], "x--", label=f"path tracer, {kind} floor")
        b.semilogy(rr, [x["equal_time_path_over_gi"] for x in rows], "o-", label=f"{kind} floor")
    a.set_xlabel("floor roughness")
    a.set_ylabel(f"relMSE of Indirect at {spp} spp (reference: path tracer, {ref_spp} spp)")
    a.legend(fontsize=7)
    b.axhline(1.0, color="k", lw=0.8)
    b.set_xlabel("floor roughness")
    b.set_ylabel("path relMSE / ReSTIR GI relMSE at equal time")
    b.legend(fontsize=7)
    fig.suptitle("ReSTIR GI versus roughness (room lit by bounced light, 96x72, still)")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "roughness.png"), dpi=110)


def target(out, size, ref_spp):
    import bpy

    import restir_engine
    from harness.reference import reference_image
    from harness.scenes import ensure_blend
    from restir_engine.export import export_scene
    restir_engine.register()
    blend = ensure_blend("interior_gi", "default", size)
    ref = reference_image(blend, 1, ref_spp)
    bpy.ops.wm.open_mainfile(filepath=blend)
    scene = export_scene(bpy.context.evaluated_depsgraph_get())
    result = {"scene": f"interior_gi-{size}", "runs": {}}
    render_frame(scene, RenderSettings(samples=1, max_bounces=1, integrator="RESTIR", direct_method="AUTO",
                                       indirect_method="RESTIR_GI"))  # warm-up
    for kind in ("INTEGRAND", "RADIANCE"):
        pts = []
        for spp in (1, 2, 4):
            t0 = time.perf_counter()
            r = render_frame(scene, RenderSettings(samples=spp, max_bounces=1, seed=spp, integrator="RESTIR",
                                                   direct_method="AUTO", indirect_method="RESTIR_GI", gi_target=kind))
            pts.append((time.perf_counter() - t0, rel_mse(r.passes["Combined"][..., :3], ref)))
            print(f"target {kind:<9} {spp} spp: {pts[-1][0]:.2f}s relMSE {pts[-1][1]:.4f}", flush=True)
        result["runs"][kind] = pts
    write_json(os.path.join(out, "target.json"), result)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--part", choices=("roughness", "target", "both"), default="both")
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--spp", type=int, default=4)
    ap.add_argument("--size", default="large")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "restir_gi"))
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    if args.part in ("roughness", "both"):
        roughness(args.out, args.ref_spp, args.spp)
    if args.part in ("target", "both"):
        target(args.out, args.size, 512)


if __name__ == "__main__":
    main()
