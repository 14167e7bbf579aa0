"""Statistics for comparing stochastic renders, shared by every statistical test.

Repetitions are independent renders (different seeds); a render is reduced to per-cell means (image blocks,
spheres, floor cells), so a comparison works on (repetitions, cells) arrays. Standard errors come from the spread
over repetitions; agreement is judged with Welch z-scores against Z_MAX plus a relative MARGIN; every comparison
with a reference also shows its power (that it would see a 3 % error).
"""
from __future__ import annotations

import json
import os

import numpy as np

Z_MAX = 5.0  # two-sided p ≈ 2e-5 per comparison for t with ~30 degrees of freedom
MARGIN = 0.005  # equivalence margin relative to the reference (6x below the 3 % error each test must see)
POWER_ERROR = 0.03  # the error every comparison with a reference must be able to detect


def standard_error(x: np.ndarray, axis: int = 0) -> np.ndarray:
    """Standard error of the mean of independent repetitions along ``axis`` (sample SD with ddof 1 / sqrt(k))."""
    x = np.asarray(x, np.float64)
    return x.std(axis=axis, ddof=1) / np.sqrt(x.shape[axis])


def welch_se(a: np.ndarray, b: np.ndarray, axis: int = 0) -> np.ndarray:
    """Standard error of the difference of the means of two independent sets of repetitions along ``axis``."""
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    return np.sqrt(a.var(axis=axis, ddof=1) / a.shape[axis] + b.var(axis=axis, ddof=1) / b.shape[axis])


def pattern_agrees(ours: np.ndarray, ref: np.ndarray, float_tol: float = 1e-3) -> np.ndarray:
    """Per cell (bool): |mean ours - mean ref| <= Z_MAX SE + MARGIN |ref| + ``float_tol`` for two sets of
    repetitions (k, cells) of a noiseless pattern (what differs between seeds is where each pixel's samples fall):
    the absolute term absorbs float32 differences in black cells."""
    ma, mb = ours.mean(axis=0), ref.mean(axis=0)
    return np.abs(ma - mb) <= Z_MAX * welch_se(ours, ref) + MARGIN * np.abs(mb) + float_tol


def robust_var(x: np.ndarray) -> float:
    """The variance of normal data with the spread of ``x`` (1.4826 x its median absolute deviation, squared)."""
    return float((1.4826 * np.median(np.abs(x - np.median(x)))) ** 2)


def block_means(images: np.ndarray, blocks: int) -> np.ndarray:
    """(k, h, w, c) repetitions -> (k, blocks*blocks + 1) channel-mean per block, with the whole image as the
    last column."""
    k, h, w = images.shape[:3]
    flat = images.reshape(k, h, w, -1).mean(axis=3)
    ys = np.linspace(0, h, blocks + 1).astype(int)
    xs = np.linspace(0, w, blocks + 1).astype(int)
    cols = [flat[:, ys[i]:ys[i + 1], xs[j]:xs[j + 1]].mean(axis=(1, 2)) for i in range(blocks) for j in range(blocks)]
    cols.append(flat.mean(axis=(1, 2)))
    return np.stack(cols, axis=1)


def cell_means(images: np.ndarray, masks: np.ndarray) -> np.ndarray:
    """(k, cells) means of the channel-averaged images (k, h, w, c) (row 0 at the bottom) over each mask
    (cells, h, w) whose row 0 is the top."""
    flat = images.mean(axis=3)[:, ::-1]
    return np.stack([flat[:, m].mean(axis=1) for m in masks], axis=1)


def image_cells(size, n: int = 4) -> np.ndarray:
    """(n*n, h, w) bool masks of an n x n grid of image cells, row 0 at the top."""
    w, h = size
    cells = np.zeros((n * n, h, w), bool)
    for i in range(n):
        for j in range(n):
            cells[i * n + j, i * h // n:(i + 1) * h // n, j * w // n:(j + 1) * w // n] = True
    return cells


def compare_cells(a: np.ndarray, b: np.ndarray):
    """Welch z-scores of the difference of per-cell means between two sets of independent repetitions (k, cells),
    and the standard error of the difference relative to the reference ``b``.
    Returns (z (cells,), mean_a (cells,), mean_b (cells,), rel_se (cells,))."""
    a, b = np.asarray(a, np.float64), np.asarray(b, np.float64)
    ma, mb = a.mean(axis=0), b.mean(axis=0)
    se = np.sqrt(a.var(axis=0, ddof=1) / len(a) + b.var(axis=0, ddof=1) / len(b))
    z = (ma - mb) / np.maximum(se, 1e-12)
    return z, ma, mb, se / np.maximum(np.abs(mb), 1e-12)


def compare(ours: np.ndarray, ref: np.ndarray, blocks: int = 2):
    """:func:`compare_cells` of the :func:`block_means` of two sets of images (k, h, w, c)."""
    return compare_cells(block_means(ours, blocks), block_means(ref, blocks))


def agree(mean_ours, mean_ref, se) -> np.ndarray:
    """Per cell: |ours - reference| within Z_MAX standard errors (absolute ``se``) plus MARGIN x the reference."""
    return np.abs(mean_ours - mean_ref) <= Z_MAX * se + MARGIN * np.abs(mean_ref)


def _probed(ours: np.ndarray) -> np.ndarray:
    """``ours`` scaled by ``RESTIR_SCALE_OURS`` when it is set (e.g. 1.03: a 3 % error that every comparison with a
    reference must then fail on; scripts/power_report.py's docstring says how to run it)."""
    factor = os.environ.get("RESTIR_SCALE_OURS")
    return ours if not factor else ours * float(factor)


def _log_power(ours: np.ndarray, ref: np.ndarray, cells, limit: float, spread=robust_var) -> None:
    """With ``RESTIR_POWER_LOG=FILE``: append per power cell the per-repetition variances (``spread``) of both sides
    relative to the reference mean squared, the repetitions, and ``limit``, the relative standard error of the
    difference the power check allows (a record tells how much precision a comparison has beyond its power check)."""
    path = os.environ.get("RESTIR_POWER_LOG")
    if not path:
        return
    mb = ref.mean(axis=0)
    record = {"test": os.environ.get("PYTEST_CURRENT_TEST", "?").rsplit(" ", 1)[0], "n_ours": len(ours),
              "n_ref": len(ref), "limit": limit,
              "var_ours": [spread(ours[:, i]) / mb[i] ** 2 for i in cells],
              "var_ref": [spread(ref[:, i]) / mb[i] ** 2 for i in cells]}
    with open(path, "a") as f:
        f.write(json.dumps(record) + "\n")


def assert_cells_match(ours: np.ndarray, ref: np.ndarray, names, power=()) -> None:
    """Every cell of ``ours`` (k, cells) in :func:`agree` with ``ref`` (k', cells); every cell in ``power`` (indices)
    able to see a POWER_ERROR error: the bound of the means scaled by 1 + POWER_ERROR, at their expected
    difference, lies inside that error, whatever side of the reference the measured mean fell on. The spread per
    repetition for the power is the robust one (1.4826 MAD): a rare firefly in one repetition (a caustic path
    through rough glass) inflates the sample variance, and with it the agreement bound, without changing how
    finely the bulk of the estimator resolves the cell; for light-tailed cells the two spreads agree."""
    ours, ref = _probed(np.asarray(ours, np.float64)), np.asarray(ref, np.float64)
    assert np.isfinite(ours).all()
    ma, mb = ours.mean(axis=0), ref.mean(axis=0)
    se = np.sqrt(ours.var(axis=0, ddof=1) / len(ours) + ref.var(axis=0, ddof=1) / len(ref))
    ok = agree(ma, mb, se)
    with np.errstate(invalid="ignore", divide="ignore"):  # a black cell reads nan
        report = [f"{n}: ours/reference {a / b:.4f} (rel SE {s / b:.4f})" for n, a, b, s in zip(names, ma, mb, se)]
    assert ok.all(), "\n".join(r for r, good in zip(report, ok) if not good)
    k = 1.0 + POWER_ERROR
    _log_power(ours, ref, list(power), (POWER_ERROR - MARGIN) / Z_MAX)
    for i in power:
        se3 = np.sqrt(k ** 2 * robust_var(ours[:, i]) / len(ours) + robust_var(ref[:, i]) / len(ref))
        assert POWER_ERROR * abs(mb[i]) > Z_MAX * se3 + MARGIN * abs(mb[i]), f"cannot see a 3 % error in {report[i]}"


def assert_blocks_match(ours: np.ndarray, ref: np.ndarray, max_rel_se: float = 0.006) -> None:
    """Block means (k, cells; the whole image last, :func:`block_means`): finite, lit (reference mean above 0.01),
    precise enough to see a POWER_ERROR error (relative SE of the whole image's difference below ``max_rel_se``,
    checked by scaling ours by 1 + POWER_ERROR, which must fail) and every block in :func:`agree` with the
    reference."""
    ours, ref = _probed(np.asarray(ours, np.float64)), np.asarray(ref, np.float64)
    assert np.isfinite(ours).all()
    z, mean_ours, mean_ref, rel_se = compare_cells(ours, ref)
    assert mean_ref[-1] > 0.01  # the scene is lit
    _log_power(ours, ref, [-1], max_rel_se, lambda x: float(np.var(x, ddof=1)))
    assert rel_se[-1] < max_rel_se, f"too noisy to detect a 3% error: relative SE {rel_se[-1]:.4f}"
    assert agree(mean_ours, mean_ref, rel_se * np.abs(mean_ref)).all(), \
        f"z={np.round(z, 2)} ours={mean_ours} reference={mean_ref}"
    _z, wrong, ref_mean, wrong_se = compare_cells(ours * (1.0 + POWER_ERROR), ref)
    assert not agree(wrong[-1:], ref_mean[-1:], (wrong_se * np.abs(ref_mean))[-1:]).all(), \
        "the comparison could not detect a 3% unit error"
