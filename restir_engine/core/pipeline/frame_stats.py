"""A frame's diagnostics, as the render's stats report them: the methods chosen and why, reuse statistics, counts,
timings."""
from __future__ import annotations

from ..modes import DirectMethod
from ..scene import Scene


def frame_stats(fr: FrameRenderer, scene: Scene, clock) -> dict:
    """The frame's diagnostics: methods chosen and why, reuse statistics, counts, timings."""
    ctx = fr.ctx
    stats = {"build_seconds": fr.build_seconds, "light_tiles": fr.used_tiles, "triangles": len(scene.geometry),
             "light_triangles": ctx.lights.n_tri, "suns": ctx.lights.n_sun, "boiling_dropped": fr.boiling_dropped,
             "context_reused": fr.context_reused, "coverage_samples": fr.coverage,
             "direct_method": fr.method, "direct_reason": fr.direct.reason,
             "world_method": fr.direct.world_method, "world_reason": fr.direct.world_reason,
             "spatial_radius": fr.spatial.radius if fr.method == DirectMethod.RESTIR else None,
             "reuse": dict(fr.reuse_stats),
             "coverage_reason": fr.coverage_reason,
             # Auto: the latest choice; otherwise ReSTIR GI unless every pass kept the path-traced light
             "indirect_method": ("OFF" if ctx.max_bounces == 0 else "PATH" if fr.gi is None else fr.indirect_method
                                 if fr.gi_auto else "PATH" if fr.gi_skipped == fr.samples_done else
                                 "RESTIR_GI"),
             "indirect_reason": fr.indirect.reason,
             "gi_skipped_passes": fr.gi_skipped,
             "gi_spatial_radius": fr.gi.radius if fr.gi is not None else None}
    if fr.adaptive is not None:
        stats["adaptive"] = fr.adaptive.stats()
    if clock is not None:
        stats["stages"] = clock.stages
    return stats


def pass_counts(fr: FrameRenderer) -> dict:
    """The frame's pass counts that its stats report, which :func:`add_pass_counts` adds to."""
    return {"gi_skipped": fr.gi_skipped, "boiling_dropped": fr.boiling_dropped, "used_tiles": int(fr.used_tiles)}


def add_pass_counts(fr: FrameRenderer, counts: dict) -> None:
    """Add another process's :func:`pass_counts` (of the passes it rendered for this frame) to ``fr``'s."""
    fr.gi_skipped += int(counts.get("gi_skipped", 0))
    fr.boiling_dropped += int(counts.get("boiling_dropped", 0))
    fr.used_tiles = bool(fr.used_tiles or counts.get("used_tiles", 0))
