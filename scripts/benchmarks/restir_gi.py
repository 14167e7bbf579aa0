"""ReSTIR GI against path-traced indirect light and Cycles: stills (interior_gi) and a camera pan through the same
room (interior_gi_pan), one bounce, error versus wall time.

    .venv/bin/python scripts/bench.py restir_gi --size large       # -> docs/results/restir_gi/*.{json,png}

Stills: every method renders interior_gi at a ladder of sample counts (each point a fresh render through the
engine: export, BVH, passes); relMSE of Combined against a cached Cycles reference (--reference-spp); the
equal-time ratio of the path-traced indirect light over ReSTIR GI is read on log-log interpolations of the ladders.
Animation: frames 1..PAN_FRAMES at one sample per frame with the history carried as in `blender -a`, per-frame
relMSE against a Cycles reference of each frame; Cycles renders the steady frames (the last three) at a ladder and
is interpolated to our time per frame. Direct light is the engine's Auto choice (light sampling: one panel).
"""
from __future__ import annotations

import argparse
import os
import time

from benchmarks.common import ROOT, write_json  # noqa: E402, F401

import numpy as np  # noqa: E402

import restir_engine  # noqa: E402
from harness.metrics import interpolate_loglog, rel_mse  # noqa: E402
from harness.reference import reference_image  # noqa: E402
from harness.render import render_blend_passes  # noqa: E402
from harness.scenes import PAN_FRAMES, ensure_blend  # noqa: E402

BOUNCES = 1
STILL_METHODS = {
    "path": ("Path-traced indirect (Auto direct)", {"indirect_method": "PATH"}, (1, 2, 4, 8, 16)),
    "gi": ("ReSTIR GI, unbiased (defaults)", {"indirect_method": "RESTIR_GI"}, (1, 2, 4, 8)),
    "gi_biased": ("ReSTIR GI, biased (1/M)", {"indirect_method": "RESTIR_GI", "bias_correction": "NONE"}, (1, 2, 4, 8)),
    "gi_1pass": ("ReSTIR GI, unbiased, 1 spatial pass", {"indirect_method": "RESTIR_GI", "gi_spatial_passes": 1},
                 (1, 2, 4, 8)),
}
ANIM_RUNS = {
    "path": {"indirect_method": "PATH"},
    "gi": {"indirect_method": "RESTIR_GI"},
    "gi_spatial_only": {"indirect_method": "RESTIR_GI", "temporal_reuse": False},
    "gi_temporal_only": {"indirect_method": "RESTIR_GI", "gi_spatial_neighbors": 0},
    "gi_biased": {"indirect_method": "RESTIR_GI", "bias_correction": "NONE"},
}
CYCLES_LADDER = (1, 2, 4, 8, 16, 32, 64)
STEADY = 3


def ladder_at(ladder, seconds):
    return interpolate_loglog([p[0] for p in ladder], [p[1] for p in ladder], seconds)


def stills(size, ref_spp, out):
    from restir_engine.engine import LAST_FRAME_STATS
    blend = ensure_blend("interior_gi", "default", size)
    ref = reference_image(blend, BOUNCES, ref_spp)
    render_blend_passes(blend, "RESTIR", 1, BOUNCES, seed=99, settings={"indirect_method": "RESTIR_GI"})  # warm-up
    result = {"scene": f"interior_gi-{size}", "bounces": BOUNCES, "reference_spp": ref_spp, "methods": {}}
    for key, (label, st, ladder) in STILL_METHODS.items():
        pts = []
        for spp in ladder:
            passes, wall, core = render_blend_passes(blend, "RESTIR", spp, BOUNCES, seed=spp, settings=st)
            pts.append((wall, rel_mse(passes["Combined"][..., :3], ref), core))
            print(f"{key:<10} {spp:3d} spp  wall {wall:.2f}s  relMSE {pts[-1][1]:.4f}", flush=True)
        result["methods"][key] = {"label": label, "settings": st, "spp": list(ladder), "points": pts,
                                  "stages": LAST_FRAME_STATS.get("stages")}
    cyc = []
    render_blend_passes(blend, "CYCLES", 1, BOUNCES, seed=0)
    for spp in CYCLES_LADDER:
        passes, wall, _ = render_blend_passes(blend, "CYCLES", spp, BOUNCES, seed=spp)
        cyc.append((wall, rel_mse(passes["Combined"][..., :3], ref)))
        print(f"cycles     {spp:3d} spp  wall {wall:.2f}s  relMSE {cyc[-1][1]:.4f}", flush=True)
    result["cycles"] = cyc
    path = result["methods"]["path"]["points"]
    for key, m in result["methods"].items():
        m["path_over_ours"] = [ladder_at(path, w) / e for w, e, _c in m["points"]]
        m["cycles_over_ours"] = [ladder_at(cyc, w) / e for w, e, _c in m["points"]]
        print(f"{key:<10} equal time: path/ours " + " ".join(f"{r:.1f}" for r in m["path_over_ours"])
              + " | Cycles/ours " + " ".join(f"{r:.2f}" for r in m["cycles_over_ours"]), flush=True)
    write_json(os.path.join(out, f"stills-{size}.json"), result)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    for key, m in result["methods"].items():
        ax.loglog([p[0] for p in m["points"]], [p[1] for p in m["points"]], "o-", label=m["label"])
    ax.loglog([p[0] for p in cyc], [p[1] for p in cyc], "k.--", label="Cycles (CPU)")
    ax.set_xlabel("wall seconds per image (export + render)")
    ax.set_ylabel("relMSE of Combined")
    ax.set_title(f"{result['scene']}, {BOUNCES} bounce, still")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, f"stills-{size}.png"), dpi=110)
    return result


def animation(size, ref_spp, out):
    from restir_engine.engine import LAST_FRAME_STATS
    blend = ensure_blend("interior_gi_pan", "default", size)
    frames = list(range(1, PAN_FRAMES + 1))
    refs = [reference_image(blend, BOUNCES, ref_spp, frame=f) for f in frames]
    result = {"scene": f"interior_gi_pan-{size}", "bounces": BOUNCES, "reference_spp": ref_spp, "frames": frames,
              "runs": {}, "cycles": {}}

    def sequence(st, seed):
        seq = []
        for f in frames:
            passes, wall, core = render_blend_passes(blend, "RESTIR", 1, BOUNCES, seed=seed, frame=f, settings=st)
            seq.append((passes["Combined"][..., :3], wall, core, dict(LAST_FRAME_STATS)))
        return seq

    sequence(ANIM_RUNS["gi"], 99)  # warm-up
    for key, st in ANIM_RUNS.items():
        seq = sequence(st, 1)
        r = result["runs"][key] = {"settings": st, "rel_mse": [rel_mse(s[0], ref) for s, ref in zip(seq, refs)],
                                   "wall_s": [s[1] for s in seq], "core_s": [s[2] for s in seq],
                                   "gi_temporal_accepted": [s[3].get("reuse", {}).get("gi_temporal_accepted")
                                                            for s in seq],
                                   "stages": seq[-1][3].get("stages")}
        print(f"{key:<16} relMSE per frame " + " ".join(f"{e:.3f}" for e in r["rel_mse"])
              + f" | wall {np.mean(r['wall_s'][1:]):.2f}s core {np.mean(r['core_s'][1:]):.2f}s", flush=True)
    for f in frames[-STEADY:]:
        render_blend_passes(blend, "CYCLES", 1, BOUNCES, seed=0, frame=f)
        lad = []
        for spp in CYCLES_LADDER:
            passes, wall, _ = render_blend_passes(blend, "CYCLES", spp, BOUNCES, seed=f * 100 + spp, frame=f)
            lad.append((wall, rel_mse(passes["Combined"][..., :3], refs[f - 1])))
        result["cycles"][f] = lad
        print(f"cycles frame {f}: " + "  ".join(f"{s}spp {w:.2f}s {e:.3f}" for s, (w, e) in zip(CYCLES_LADDER, lad)),
              flush=True)
    path = result["runs"]["path"]
    for key, r in result["runs"].items():
        steady = frames[-STEADY:]
        r["cycles_over_ours"] = float(np.mean([ladder_at(result["cycles"][f], r["wall_s"][f - 1]) / r["rel_mse"][f - 1]
                                               for f in steady]))
        # the path tracer at our time per frame: its relMSE scales as 1 / samples (independent frames)
        r["path_over_ours"] = float(np.mean([path["rel_mse"][f - 1] * path["wall_s"][f - 1] / r["wall_s"][f - 1]
                                             / r["rel_mse"][f - 1] for f in steady]))
        print(f"{key:<16} steady frames at equal time: Cycles/ours {r['cycles_over_ours']:.2f}, "
              f"path/ours {r['path_over_ours']:.1f}", flush=True)
    write_json(os.path.join(out, f"pan-{size}.json"), result)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
    for key, r in result["runs"].items():
        a.semilogy(frames, r["rel_mse"], "o-", label=key.replace("_", " "))
    gi = result["runs"]["gi"]
    a.semilogy(frames[-STEADY:], [ladder_at(result["cycles"][f], gi["wall_s"][f - 1]) for f in frames[-STEADY:]],
               "kx--", label="Cycles at the time of 'gi'")
    a.set_xlabel("frame (1 sample per frame, history carried)")
    a.set_ylabel("relMSE of Combined")
    a.set_title(result["scene"])
    a.legend(fontsize=7)
    for key, r in result["runs"].items():
        b.loglog([r["wall_s"][f - 1] for f in frames[-STEADY:]], [r["rel_mse"][f - 1] for f in frames[-STEADY:]], "o",
                 label=key.replace("_", " "))
    for i, (f, lad) in enumerate(result["cycles"].items()):
        b.loglog([p[0] for p in lad], [p[1] for p in lad], "k.-", alpha=0.5, label="Cycles ladder" if i == 0 else None)
    b.set_xlabel("wall seconds per frame")
    b.set_ylabel("relMSE of Combined")
    b.set_title("steady frames: error versus time")
    b.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out, f"pan-{size}.png"), dpi=110)
    return result


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--size", default="large")
    ap.add_argument("--reference-spp", type=int, default=512)
    ap.add_argument("--part", choices=("stills", "animation", "both"), default="both")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results", "restir_gi"))
    args = ap.parse_args()
    restir_engine.register()
    os.makedirs(args.out, exist_ok=True)
    t0 = time.time()
    if args.part in ("stills", "both"):
        stills(args.size, args.reference_spp, args.out)
    if args.part in ("animation", "both"):
        animation(args.size, args.reference_spp, args.out)
    print(f"done in {time.time() - t0:.0f} s", flush=True)


if __name__ == "__main__":
    main()
