"""Every integrator renders the same images (within noise) as before the core was restructured.

The baseline (tests/regression.py, tests/data/regression_baseline.npz) was made by the old code with seeds
1000..1031; the current code renders the same configurations with seeds 2000..2031 (independent noise).
Per configuration 19 statistics are compared by Welch z-scores; |z| < 5 for all 95 keeps the chance of a
false failure below 1e-3 (t with ~60 degrees of freedom: P(|t| > 5) ≈ 5e-6 each), while the standard
errors (checked below) let a 2-3 % change of the lit surfaces fail it.
"""
import numpy as np
import pytest
from regression import BASELINE, CONFIGS, SEEDS, render_stats
from stats import welch_se


@pytest.mark.parametrize("name", sorted(CONFIGS))
def test_same_image_as_before_the_restructuring(name):
    before = np.load(BASELINE)[name]
    now = np.array([render_stats(name, 2000 + s) for s in range(SEEDS)])
    assert np.isfinite(now).all()
    se = welch_se(before, now)
    direct = before[:, -2].mean()
    assert se[-2] < 0.01 * direct  # the comparison can see a 3 % change of the direct light
    z = (now.mean(axis=0) - before.mean(axis=0)) / np.maximum(se, 1e-12)
    z = np.where(se > 1e-12, z, 0.0)
    worst = int(np.argmax(np.abs(z)))
    assert np.abs(z).max() < 5.0, (name, worst, z[worst], now.mean(axis=0)[worst], before.mean(axis=0)[worst])
    # statistics that are exactly zero (no indirect light at max_bounces 0) must stay exactly zero
    assert np.array_equal(before.mean(axis=0) == 0, now.mean(axis=0) == 0)
