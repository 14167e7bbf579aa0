"""Shader node graphs compiled into vectorized programs (:mod:`.program`) and evaluated per hit: the operations
(:mod:`.ops_math`, :mod:`.ops_texture`), Cycles' hashes and noise (:mod:`.hashing`, :mod:`.noise`) and the hit
attributes they read (:mod:`.attributes`). :func:`run_programs` evaluates a batch's programs."""
from __future__ import annotations

import numpy as np

from .attributes import HitAttributes
from .program import Program

__all__ = ["HitAttributes", "Program", "run_programs", "emission_programs"]


def run_programs(mats, mat: np.ndarray, make_attrs, fields=None):
    """For hits on materials ``mat`` (n,): yields (rows, outputs) per node program among them, ``rows`` the hits
    (indices into ``mat``) of that program and ``outputs`` its fields there (all, or those in ``fields``; a
    program with none of them is skipped). ``make_attrs(rows)`` gives those hits' HitAttributes. Loops over
    programs, not hits."""
    index = getattr(mats, "program", None)
    if index is None or not mats.programs or not len(mat):
        return
    prog = index[mat]
    for p in np.unique(prog[prog >= 0]):
        program = mats.programs[int(p)]
        if fields is not None and not any(program.has(f) for f in fields):
            continue
        rows = np.flatnonzero(prog == p)
        yield rows, program.run(make_attrs(rows), fields)


def emission_programs(mats) -> np.ndarray:
    """(m,) bool: the materials whose node program computes their emission."""
    index = getattr(mats, "program", None)
    if index is None or not mats.programs:
        return np.zeros(len(mats.emission), bool)
    has = np.array([p.has("emission") for p in mats.programs], bool)
    return (index >= 0) & has[np.maximum(index, 0)]
