"""Run an evaluation: every method of harness.methods on the scene library against Cycles references.

Timing: ``wall`` is the wall clock of a complete frame render through Blender (bpy.ops.render.render,
export included); ``core`` is the renderer's own time for our methods (LAST_FRAME_STATS). Charts say
which one they show.
"""
from __future__ import annotations

import json
import os
import time
from dataclasses import dataclass, replace

import numpy as np

from . import metrics, report
from .methods import by_key, settings_for
from .reference import reference_image, reference_lit
from .render import render_blend, render_blend_passes
from .scenes import ANIM_FRAMES, LIGHT_OFF_FRAME, SIZES, ensure_blend


@dataclass(frozen=True)
class Spec:
    name: str
    variant: str
    size: str
    bounces: int
    reference_spp: int

    @property
    def title(self):
        base = self.name if self.variant == "default" else f"{self.name} {self.variant}"
        return base + (" (direct light)" if self.bounces == 0 else "")

    @property
    def slug(self):
        return f"{self.name}-{self.variant}".replace(".", "p") + ("-direct" if self.bounces == 0 else "")


QUICK = [Spec("cornell", "default", "tiny", 3, 1024), Spec("many_lights", "1k", "tiny", 1, 1024),
         Spec("many_lights", "1k", "tiny", 0, 1024), Spec("interior_gi", "default", "tiny", 3, 2048)]
FULL = [Spec("cornell", "default", "small", 4, 4096), Spec("many_lights", "1k", "small", 1, 4096),
        Spec("many_lights", "10k", "small", 0, 4096),
        Spec("many_lights", "10k", "small", 1, 4096), Spec("many_lights", "100k", "small", 1, 4096),
        Spec("glossy", "0.05", "small", 2, 4096), Spec("glossy", "0.2", "small", 2, 4096),
        Spec("glossy", "0.5", "small", 2, 4096), Spec("interior_gi", "default", "small", 4, 8192)]
TARGET_RELMSE = 0.02


def evaluate_scene(spec: Spec, methods, quick: bool, refresh: bool = False, log=print):
    blend = ensure_blend(spec.name, spec.variant, spec.size)
    t0 = time.perf_counter()
    # direct-light scenes also score the light reflected by surfaces alone (Combined - Emission): emitters
    # seen directly add pixel-coverage noise that no direct-light method changes
    lit = spec.bounces == 0
    ref_lit = reference_lit(blend, spec.bounces, spec.reference_spp, refresh=refresh) if lit else None
    ref = reference_image(blend, spec.bounces, spec.reference_spp, refresh=refresh)
    log(f"[{spec.title}] reference ready ({time.perf_counter() - t0:.1f}s)")
    points, images = [], {}
    for m in methods:
        settings = settings_for(m, SIZES[spec.size][0])
        render_blend(blend, m.engine, 1, spec.bounces, settings=settings)  # warm-up, not timed
        for spp in (m.ladder_quick if quick else m.ladder_full):
            passes, wall, core = render_blend_passes(blend, m.engine, spp, spec.bounces, seed=1, settings=settings,
                                                     emission=lit)
            img = passes["Combined"][..., :3]
            p = {"method": m.key, "spp": spp, "wall": wall, "core": core, "relmse": metrics.rel_mse(img, ref),
                 "bias": metrics.rel_bias(img, ref), "flip": metrics.flip(img, ref)}
            if lit:
                p["relmse_lit"] = metrics.rel_mse(img - passes["Emission"][..., :3], ref_lit)
            points.append(p)
            images[(m.key, spp)] = img
            log(f"[{spec.title}] {m.key:8s} {spp:4d} spp  wall {wall:6.2f}s  relMSE {p['relmse']:.4g}  "
                f"bias {p['bias'] * 100:+.2f}%" + (f"  relMSE lit {p['relmse_lit']:.4g}" if lit else ""))
    h, w = ref.shape[:2]
    result = {"title": spec.title, "scene": spec.name, "variant": spec.variant, "size": [w, h],
              "bounces": spec.bounces, "reference_spp": spec.reference_spp, "points": points}
    return result, images, ref


def evaluate_animation(size: str, spp: int, ref_spp: int, methods, quick: bool, refresh=False, log=print):
    """Per-frame error of each method on the animated scene, flicker and lag after the light switches off."""
    blend = ensure_blend("animated", "default", size)
    frames = list(range(1, ANIM_FRAMES + 1))
    refs = [reference_image(blend, 2, ref_spp, frame=f, refresh=refresh) for f in frames]
    # pixels the switched-off lamp lit: where the reference changes most between the two frames
    delta = np.abs(refs[LIGHT_OFF_FRAME - 2] - refs[LIGHT_OFF_FRAME - 1]).mean(axis=2)
    mask = delta > np.percentile(delta, 80)
    out = {"frames": frames, "light_off_frame": LIGHT_OFF_FRAME, "per_method": {}}
    for m in methods:
        imgs, walls = [], []
        for f in frames:
            img, wall, _core = render_blend(blend, m.engine, spp, 2, seed=f, frame=f,
                                            settings=settings_for(m, SIZES[size][0]))
            imgs.append(img)
            walls.append(wall)
        out["per_method"][m.key] = {
            "spp": spp, "relmse": [metrics.rel_mse(i, r) for i, r in zip(imgs, refs)],
            "flicker": metrics.temporal_flicker(imgs, refs),
            "lag_frames": metrics.lag_frames(imgs, refs, LIGHT_OFF_FRAME - 1, mask, z=4.0),
            "mean_wall": float(np.mean(walls))}
        log(f"[animated] {m.key}: flicker {out['per_method'][m.key]['flicker']:.4f}, "
            f"lag {out['per_method'][m.key]['lag_frames']} frames")
    return out


def evaluate_growth(quick: bool, log=print):
    """Frame time of the path tracer versus emissive triangles, resolution and scene triangles."""
    spp, bounces = 1, 1
    lights = ["100", "1k", "10k"] if quick else ["100", "1k", "10k", "100k", "1m"]
    sizes = ["tiny", "small"] if quick else ["tiny", "small", "medium", "large"]
    subdiv = [0, 3, 5] if quick else [0, 2, 4, 6, 7]
    out = {"lights": [], "resolution": [], "triangles": []}

    def run(key, x, blend):
        _img, wall, core = render_blend(blend, "RESTIR", spp, bounces, settings={"integrator": "PATH"})
        from restir_engine.engine import LAST_FRAME_STATS
        out[key].append({"x": x, "wall": wall, "core": core, "spp": spp, "bounces": bounces,
                         "stats": {k: v for k, v in LAST_FRAME_STATS.items() if isinstance(v, (int, float))}})
        log(f"[growth] {key} {x}: wall {wall:.2f}s core {core:.2f}s")

    for v in lights:
        blend = ensure_blend("many_lights", v, "tiny")
        run("lights", {"100": 100, "1k": 1000, "10k": 10000, "100k": 100000, "1m": 1000000}[v], blend)
    for s in sizes:
        from .scenes import SIZES
        run("resolution", SIZES[s][0] * SIZES[s][1], ensure_blend("cornell", "default", s))
    for k in subdiv:
        run("triangles", 14 + (20 * 4 ** k if k else 0), ensure_blend("cornell", f"subdiv-{k}" if k else "default",
                                                                       "tiny"))
    return out


def run(mode: str, out_dir: str, method_keys=None, scenes=None, refresh=False, log=print,
        animation=True, growth=True, size: str | None = None, reference_spp: int | None = None,
        anim_spp: int = 4) -> dict:
    """``size`` / ``reference_spp``: override every scene's image size (a key of scenes.SIZES) and the
    Cycles reference's samples; ``anim_spp``: samples per frame of the animated scene."""
    quick = mode == "quick"
    methods = by_key(method_keys)
    specs = [s for s in (QUICK if quick else FULL) if scenes is None or s.name in scenes or s.slug in scenes]
    specs = [replace(s, size=size or s.size, reference_spp=reference_spp or s.reference_spp) for s in specs]
    os.makedirs(out_dir, exist_ok=True)
    summary = {"mode": mode, "scenes": [], "target_relmse": TARGET_RELMSE}
    lines = ["| scene | method | relMSE at equal time | surfaces only (Combined - Emission) at equal time | "
             "time to relMSE %.2g | bias (highest spp) | FLIP |" % TARGET_RELMSE, "|---|---|---|---|---|---|---|"]
    for spec in specs:
        result, images, ref = evaluate_scene(spec, methods, quick, refresh, log)
        path_pts = [p for p in result["points"] if p["method"] == "path"] or result["points"]
        budget = sorted(p["wall"] for p in path_pts)[len(path_pts) // 2]
        result["equal_time_budget"] = budget
        report.chart_scene(result, methods, os.path.join(out_dir, f"{spec.slug}.png"))
        report.strip_scene(result, images, ref, methods, budget, os.path.join(out_dir, f"{spec.slug}-strip.png"))
        lines += report.table_rows(result, methods, budget, TARGET_RELMSE)
        summary["scenes"].append(result)
    if animation:
        size = "tiny" if quick else "small"
        anim = evaluate_animation(size, anim_spp, 512 if quick else 2048, methods, quick, refresh, log)
        report.chart_animation(anim, methods, os.path.join(out_dir, "animated.png"))
        summary["animation"] = anim
    if growth:
        g = evaluate_growth(quick, log)
        report.chart_growth(g, os.path.join(out_dir, "growth.png"))
        summary["growth"] = g
    with open(os.path.join(out_dir, "results.json"), "w") as f:
        json.dump(summary, f, indent=1)
    md = [f"# Evaluation ({mode} mode)", "",
          "Wall = complete frame through Blender (export included); relMSE uses EPS = 0.01; equal time = the "
          "median wall time of the path tracer's points; bias is the relative difference of image means at the "
          "highest sample count (its noise shrinks with spp).", ""] + lines
    if animation:
        md += ["", "| animated: method | spp | flicker | lag after the light switches off (frames) |", "|---|---|---|---|"]
        for key, s in summary["animation"]["per_method"].items():
            md.append(f"| {key} | {s['spp']} | {s['flicker']:.4f} | {s['lag_frames']} |")
    md += ["", "Charts: " + ", ".join(f"`{s.slug}.png` / `{s.slug}-strip.png`" for s in specs)
           + (", `animated.png`" if animation else "") + (", `growth.png`" if growth else "")]
    with open(os.path.join(out_dir, "summary.md"), "w") as f:
        f.write("\n".join(md) + "\n")
    return summary
