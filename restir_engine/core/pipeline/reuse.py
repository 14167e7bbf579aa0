"""Reuse stages: the whole-image stages that read other pixels' reservoirs.

DI: temporal (the first pass of a frame with a history: merge with the previous frame's reservoirs, reprojected by
the motion of Blender's transforms), the boiling filter (biased mode only; 16x16 blocks) and spatial passes. GI:
temporal and spatial passes, each followed in the unbiased mode by a visibility check. Inputs and outputs are
whole-image buffers indexed by the frame's surface order: the G-buffer (restir/gbuffer.py), the reservoirs
(restir/reservoir.py) and the history (restir/history.py); each stage maps over spans of surfaces and gathers them
into a new whole-image reservoir array.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..parallel.tasks import run_job
from ..restir import gi, reuse
from ..restir.boiling import boiling_filter
from ..sampling import STREAM_GI_SPATIAL, STREAM_GI_TEMPORAL, STREAM_SPATIAL, STREAM_TEMPORAL
from .runner import PassRunner


def temporal(run: PassRunner, space, gb, res, hist, motion, cap, stream, possible, bias_correction, stage):
    """One temporal merge of every surface's reservoir with its previous frame's (reuse.temporal_reuse)."""
    with run.stage(stage):
        prepared = space.prepare(hist.res, run.spans(len(hist.res)), run.team)
        now = space.prepare(res, run.spans(len(res)), run.team) if bias_correction == "UNBIASED" else None
        jobs = [(rows, (space, gb, res, now, hist, prepared, rows, cap, bias_correction, motion,
                        run.plan.rng(stream, i), possible))
                for i, rows in enumerate(run.spans(len(gb)))]
        del prepared, now  # released with the jobs once merged
        parts = run.map(run_job(reuse.temporal_reuse), jobs)
        del jobs
        return run.gather(space.kind, parts, len(gb))


def spatial(run: PassRunner, space, gb, res, cfg, stream, stage):
    """One spatial pass over every surface (reuse.spatial_reuse)."""
    with run.stage(stage):
        prepared = space.prepare(res, run.spans(len(res)), run.team)
        jobs = [(rows, (space, gb, res, prepared, rows, cfg, run.plan.rng(stream, i)))
                for i, rows in enumerate(run.spans(len(gb)))]
        del prepared  # released with the jobs once merged
        parts = run.map(run_job(reuse.spatial_reuse), jobs)
        del jobs
        return run.gather(space.kind, parts, len(gb))


PERCENTILE_STRIDE = 16  # the confidence percentiles (a diagnostic) are read from every 16th reservoir


def m_percentiles(m: np.ndarray) -> list:
    """The 10th, 50th and 90th percentiles of the confidences ``m``, estimated from every PERCENTILE_STRIDE-th (the
    leader computes them while the team waits at the next barrier)."""
    return [float(v) for v in np.percentile(m[::PERCENTILE_STRIDE], [10, 50, 90])]


def reuse_di(run: PassRunner, st, ctx, space, spatial_cfg, gb, res, hist, stats: dict):
    """Temporal (where the plan says), boiling filter, spatial passes. Returns (the final reservoirs, the number
    of reservoirs the boiling filter emptied)."""
    dropped = 0
    if run.plan.temporal:
        # object motion is known for the previous frame only; a history from another frame gets none
        motion = ctx.scene.motion if hist.frame == st.frame - 1 else None
        had = hist.had_light
        possible = None if had is None else (lambda rows, res=res: had[np.maximum(res.light[rows], 0)])
        res = temporal(run, space, gb, res, hist, motion, st.confidence_cap, STREAM_TEMPORAL, possible,
                       st.bias_correction, "temporal")
        if run.team.leader:  # every fresh reservoir has M = 1 and a merged history adds at least 1
            stats["temporal_accepted"] = float((res.M > 1.5).mean()) if len(res.M) else 0.0
            stats["temporal_mean_M"] = float(res.M.mean()) if len(res.M) else 0.0
    if st.boiling_filter and st.bias_correction == "NONE":  # biased by design: never in the unbiased mode
        with run.stage("boiling"):
            if run.team.leader:  # whole 16x16 blocks, in place: one process filters, the others wait
                dropped = int(boiling_filter(res, gb.pix, gb.width, gb.height, st.boiling_threshold).sum())
            run.team.barrier()
    for k in range(spatial_cfg.passes if spatial_cfg.neighbors else 0):
        res = spatial(run, space, gb, res, spatial_cfg, STREAM_SPATIAL + k, "spatial")
    if len(res.M) and run.team.leader:
        stats["final_M_p10_p50_p90"] = m_percentiles(res.M)
    return res, dropped


def gi_visible(run: PassRunner, ctx, gb, res, unbiased: bool, stage):
    """Unbiased mode: empty the GI samples their surfaces cannot see (gi.clear_occluded), one ray per surface.
    (The biased mode gains nothing from it: docs/RESULTS.md, "ReSTIR GI".)"""
    if not unbiased:
        return res
    with run.stage(stage):
        # slices: each task's reservoirs and terms are views, cleared in place
        run.map(lambda rows: gi.clear_occluded(ctx.geom_accel, gb.terms.take(rows), res.take(rows)),
                run.spans(len(gb)))
        run.team.barrier()
    return res


def reuse_gi(run: PassRunner, st, ctx, gi_cfg, gi_space, gi_spatial, gb, res, hist, stats: dict):
    """ReSTIR GI: temporal (where the plan says) and spatial passes. Returns (the final reservoirs, the reservoirs
    before the spatial passes: the next frame's history, which is not fed the spatially merged reservoirs, whose
    neighbours' samples are correlated with the next frame's spatial pass)."""
    unbiased = st.bias_correction == "UNBIASED"
    if run.plan.gi_temporal:
        motion = ctx.scene.motion if hist.frame == st.frame - 1 else None
        view = dataclasses.replace(hist, gbuf=hist.gbuf.with_terms(hist.gi_terms), res=hist.gi_res)
        res = temporal(run, gi_space, gb, res, view, motion, gi_cfg.confidence_cap, STREAM_GI_TEMPORAL, None,
                       st.bias_correction, "gi_temporal")
        if run.team.leader:
            stats["gi_temporal_accepted"] = float((res.M > 1.5).mean()) if len(res.M) else 0.0
        res = gi_visible(run, ctx, gb, res, unbiased, "gi_temporal")
    history = res
    for k in range(gi_cfg.passes if gi_cfg.neighbors else 0):
        res = spatial(run, gi_space, gb, res, gi_spatial, STREAM_GI_SPATIAL + k, "gi_spatial")
        res = gi_visible(run, ctx, gb, res, unbiased, "gi_spatial")
    if len(res.M) and run.team.leader:
        stats["gi_final_M_p10_p50_p90"] = m_percentiles(res.M)
    return res, history


def age_history(gi_cfg, res):
    """GI reservoirs for the next frame: confidence capped, samples older than max_age dropped."""
    return gi.age_history(res.replace(M=np.minimum(res.M, np.float32(gi_cfg.confidence_cap))), gi_cfg.max_age)
