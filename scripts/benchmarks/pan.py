"""Many lights under a camera pan (harness scene many_lights_pan): per-frame relMSE of our default integrator with
and without temporal reuse, one sample per frame with the history carried as in `blender -a`, against Cycles
at equal time, direct light only.

    .venv/bin/python scripts/bench.py pan --size medium     # -> docs/results/pan/pan-medium.{json,png}

Every frame is rendered through the engine (bpy.ops.render.render: export, motion vectors, history), scored
against a cached Cycles reference of that frame (--reference-spp). Cycles renders the steady frames (the last
three) at a ladder of sample counts; its relMSE at our time per frame is interpolated on that ladder (log-log, clamped to its range).
The ratio Cycles relMSE / ours at equal time is what the ReSTIR DI issue targets (>= 2).
"""
from __future__ import annotations

import argparse
import os
import time

from benchmarks.common import ROOT, write_json  # noqa: E402, F401

import numpy as np  # noqa: E402

import restir_engine  # noqa: E402
from harness.metrics import interpolate_loglog, rel_mse  # noqa: E402
from harness.reference import reference_image, reference_lit  # noqa: E402
from harness.render import render_blend_passes  # noqa: E402
from harness.scenes import PAN_FRAMES, ensure_blend  # noqa: E402

CYCLES_LADDER = (1, 2, 4, 8, 16)
STEADY = 3  # the last frames, where the history has built up


def render_sequence(blend, settings, seed):
    """Frames 1..PAN_FRAMES through the engine: per frame (Combined, Combined - Emission, wall s, core s, stats)."""
    from restir_engine.engine import LAST_FRAME_STATS
    out = []
    for f in range(1, PAN_FRAMES + 1):
        passes, wall, core = render_blend_passes(blend, "RESTIR", 1, 0, seed=seed, frame=f, settings=settings,
                                                 emission=True)
        c = passes["Combined"][..., :3]
        out.append((c, c - passes["Emission"][..., :3], wall, core, dict(LAST_FRAME_STATS)))
    return out


def equal_time(ladder, seconds):
    """relMSE of a [(seconds, relMSE)] ladder at ``seconds`` (metrics.interpolate_loglog, clamped to its range)."""
    return interpolate_loglog([p[0] for p in ladder], [p[1] for p in ladder], seconds)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", default="medium")
    ap.add_argument("--variant", default="10k")
    ap.add_argument("--reference-spp", type=int, default=1024)
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "pan"))
    args = ap.parse_args()
    restir_engine.register()
    blend = ensure_blend("many_lights_pan", args.variant, args.size)
    frames = list(range(1, PAN_FRAMES + 1))
    lits = [reference_lit(blend, 0, args.reference_spp, frame=f) for f in frames]  # caches Combined too
    refs = [reference_image(blend, 0, args.reference_spp, frame=f) for f in frames]
    runs = {"temporal": {"temporal_reuse": True}, "no_temporal": {"temporal_reuse": False}}
    result = {"scene": f"many_lights_pan-{args.variant}-{args.size}", "frames": frames, "created": time.strftime("%Y-%m-%d"),
              "reference_spp": args.reference_spp, "runs": {}, "cycles": {}}
    render_sequence(blend, runs["temporal"], seed=99)  # warm-up (untimed)
    for key, st in runs.items():
        seq = render_sequence(blend, st, seed=1)
        result["runs"][key] = {
            "settings": st, "direct_method": seq[-1][4].get("direct_method"),
            "rel_mse": [rel_mse(s[0], r) for s, r in zip(seq, refs)],
            "rel_mse_surfaces": [rel_mse(s[1], r) for s, r in zip(seq, lits)],
            "wall_s": [s[2] for s in seq], "core_s": [s[3] for s in seq],
            "temporal_accepted": [s[4].get("reuse", {}).get("temporal_accepted") for s in seq],
            "temporal_mean_M": [s[4].get("reuse", {}).get("temporal_mean_M") for s in seq],
            "final_M_p10_p50_p90": [s[4].get("reuse", {}).get("final_M_p10_p50_p90") for s in seq]}
        r = result["runs"][key]
        print(f"{key:<12} ({r['direct_method']}) relMSE per frame " + " ".join(f"{e:.3f}" for e in r["rel_mse"])
              + " | surfaces " + " ".join(f"{e:.3f}" for e in r["rel_mse_surfaces"])
              + f" | wall {np.mean(r['wall_s'][1:]):.2f}s core {np.mean(r['core_s'][1:]):.2f}s", flush=True)
        if key == "temporal":
            print("  history accepted per frame " + " ".join(f"{a:.2f}" if a is not None else "-"
                                                           for a in r["temporal_accepted"])
                  + " | mean M after temporal " + " ".join(f"{m:.1f}" if m is not None else "-"
                                                           for m in r["temporal_mean_M"])
                  + f" | final M p10/p50/p90 (last frame) {r['final_M_p10_p50_p90'][-1]}", flush=True)
    for f in frames[-STEADY:]:
        ladder, ladder_lit = [], []
        render_blend_passes(blend, "CYCLES", 1, 0, seed=0, frame=f)  # warm-up
        for spp in CYCLES_LADDER:
            passes, wall, _ = render_blend_passes(blend, "CYCLES", spp, 0, seed=f, frame=f, emission=True)
            c = passes["Combined"][..., :3]
            ladder.append((wall, rel_mse(c, refs[f - 1])))
            ladder_lit.append((wall, rel_mse(c - passes["Emission"][..., :3], lits[f - 1])))
        result["cycles"][f] = {"ladder": ladder, "ladder_surfaces": ladder_lit}
        print(f"cycles frame {f}: " + "  ".join(f"{s}spp {w:.2f}s {e:.3f}" for s, (w, e) in zip(CYCLES_LADDER, ladder)),
              flush=True)
    for key, r in result["runs"].items():
        ratios, ratios_lit = [], []
        for f in frames[-STEADY:]:
            t = r["wall_s"][f - 1]
            ratios.append(equal_time(result["cycles"][f]["ladder"], t) / r["rel_mse"][f - 1])
            ratios_lit.append(equal_time(result["cycles"][f]["ladder_surfaces"], t) / r["rel_mse_surfaces"][f - 1])
        r["cycles_over_ours"] = float(np.mean(ratios))
        r["cycles_over_ours_surfaces"] = float(np.mean(ratios_lit))
        print(f"{key:<12} steady frames: Cycles relMSE / ours at equal wall time {r['cycles_over_ours']:.2f} "
              f"(surfaces {r['cycles_over_ours_surfaces']:.2f})", flush=True)
    os.makedirs(args.out, exist_ok=True)
    name = f"pan-{args.size}"
    write_json(os.path.join(args.out, name + ".json"), result)
    chart(result, os.path.join(args.out, name + ".png"))


def chart(result, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
    frames = result["frames"]
    for key, r in result["runs"].items():
        a.semilogy(frames, r["rel_mse"], "o-", label=f"ours, {key.replace('_', ' ')} ({r['direct_method']})")
        cyc = [equal_time(result["cycles"][f]["ladder"], r["wall_s"][f - 1]) for f in frames[-STEADY:]]
        a.semilogy(frames[-STEADY:], cyc, "x--", label=f"Cycles at the time of '{key.replace('_', ' ')}'")
        b.loglog([r["wall_s"][f - 1] for f in frames[-STEADY:]], [r["rel_mse"][f - 1] for f in frames[-STEADY:]],
                 "o", label=f"ours, {key.replace('_', ' ')}")
    for f, c in result["cycles"].items():
        b.loglog([p[0] for p in c["ladder"]], [p[1] for p in c["ladder"]], "k.-", alpha=0.5,
                 label="Cycles 1..16 spp" if f == list(result["cycles"])[0] else None)
    a.set_xlabel("frame (1 sample per frame, history carried)")
    a.set_ylabel("relMSE of Combined")
    a.legend(fontsize=7)
    a.set_title(result["scene"])
    b.set_xlabel("wall seconds per frame")
    b.set_ylabel("relMSE of Combined")
    b.legend(fontsize=7)
    b.set_title("steady frames: error versus time")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
