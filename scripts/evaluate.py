"""Speed versus accuracy: every method against Cycles on the scene library; charts into docs/results.

Usage: python scripts/evaluate.py [--mode quick|full] [--methods path cycles] [--scenes cornell ...]
                                  [--refresh-references] [--out docs/results/quick] [--no-animation] [--no-growth]
                                  [--size tiny|small|medium|large] [--reference-spp N] [--anim-spp N]
quick: tiny scenes, short sample ladders (a few minutes on 2 cores); full: the published charts.
"""
from __future__ import annotations

import argparse
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.join(ROOT, "scripts"))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--mode", choices=("quick", "full"), default="quick")
    ap.add_argument("--methods", nargs="*")
    ap.add_argument("--scenes", nargs="*", help="scene names (all their variants) or slugs such as many_lights-10k-direct")
    ap.add_argument("--refresh-references", action="store_true", help="re-render the cached Cycles references")
    ap.add_argument("--out")
    ap.add_argument("--no-animation", action="store_true")
    ap.add_argument("--no-growth", action="store_true")
    ap.add_argument("--size", choices=("tiny", "small", "medium", "large"), help="override every scene's size")
    ap.add_argument("--reference-spp", type=int, help="override the Cycles references' samples")
    ap.add_argument("--anim-spp", type=int, default=4, help="samples per frame of the animated scene")
    args = ap.parse_args()
    import bpy

    import restir_engine
    from harness.evaluate import run
    if not hasattr(bpy.types.Scene, "restir"):
        restir_engine.register()
    out = args.out or os.path.join(ROOT, "docs", "results", args.mode)
    run(args.mode, out, args.methods, args.scenes, args.refresh_references,
        animation=not args.no_animation, growth=not args.no_growth, size=args.size,
        reference_spp=args.reference_spp, anim_spp=args.anim_spp)
    print(f"Wrote {out}/summary.md and charts")


if __name__ == "__main__":
    main()
