"""Render loops of the comparisons with Cycles: our side rendered on every run, Cycles' side from the stored
reference data (tests/cycles_reference.py), both reduced to per-seed cell means (REPS, cells) for tests/stats.py."""
from __future__ import annotations

import numpy as np
from bpy_scenes import configure_cycles, configure_restir, render_passes
from cycles_reference import cycles_cells

REPS = 16  # independent seeds per side


def _combined(scene) -> np.ndarray:
    return render_passes(scene)["Combined"][..., :3]


def ours_cells(build, bounces: int, samples: int, reduce, fresh_per_seed: bool = False, reps: int = REPS,
               **settings) -> np.ndarray:
    """(reps, cells): ``reduce`` of our renders of ``build()`` at seeds 0..reps-1 (the scene built once, or again
    for every seed with ``fresh_per_seed``), the add-on's settings ``settings`` on top of scene.restir's."""
    scene = None
    images = []
    for seed in range(reps):
        if scene is None or fresh_per_seed:
            scene = build()
        configure_restir(scene, samples, bounces, seed, **settings)
        images.append(_combined(scene))
    return np.asarray(reduce(np.array(images)), np.float64)


def cycles_reference(case: str, build, bounces: int, samples: int, reduce, transparent_max_bounces=None,
                     reps: int = REPS) -> np.ndarray:
    """(reps, cells): ``reduce`` of Cycles' renders of ``build()`` at seeds 0..reps-1 (configure_cycles; with
    ``transparent_max_bounces`` that many transparent bounces, as cut-outs need), stored as ``case``."""
    def configure(scene, seed):
        configure_cycles(scene, samples, bounces, seed)
        if transparent_max_bounces is not None:
            scene.cycles.transparent_max_bounces = transparent_max_bounces

    return cycles_cells(case, build, configure, _combined, reduce, reps, samples, bounces)
