"""Metric functions on synthetic images with known answers."""
import numpy as np
import pytest

from harness import metrics


def test_rel_mse_known_value():
    ref = np.full((4, 4, 3), 1.0)
    x = ref * 1.1
    assert metrics.rel_mse(x, ref) == pytest.approx(0.01 / (1 + metrics.EPS))
    assert metrics.rel_mse(ref, ref) == 0.0
    assert metrics.rel_mse(np.zeros_like(ref), np.zeros_like(ref)) == 0.0


def test_rel_bias_over_image_and_mask():
    ref = np.ones((2, 2, 3))
    x = ref.copy()
    x[0, 0] = 3.0
    assert metrics.rel_bias(x, ref) == pytest.approx(0.5)
    mask = np.zeros((2, 2), bool)
    mask[1] = True
    assert metrics.rel_bias(x, ref, mask) == 0.0


def test_flip_zero_for_identical_and_grows_with_error():
    g = np.random.default_rng(0)
    ref = g.random((32, 32, 3)).astype(np.float32)
    assert metrics.flip(ref, ref) == pytest.approx(0.0, abs=1e-6)
    small, large = metrics.flip(ref * 1.05, ref), metrics.flip(ref * 2.0, ref)
    assert 0 < small < large


def test_temporal_flicker_and_lag():
    refs = [np.ones((2, 2, 3))] * 6
    steady = [r * 1.1 for r in refs]  # constant error: no flicker
    assert metrics.temporal_flicker(steady, refs) == 0.0
    alternating = [r * (1.1 if k % 2 else 0.9) for k, r in enumerate(refs)]
    assert metrics.temporal_flicker(alternating, refs) == pytest.approx(0.2)
    # a light switched off at frame 2: the estimate needs 2 more frames to settle
    frames = [r * f for r, f in zip(refs, [1.0, 1.0, 1.5, 1.2, 1.01, 1.0])]
    assert metrics.lag_frames(frames, refs, 2, None, 0.05) == 2
    assert metrics.lag_frames(refs, refs, 2, None, 0.05) == 0


def test_lag_with_statistical_tolerance():
    g = np.random.default_rng(5)
    refs = [np.ones((64, 64, 3))] * 6
    noisy = [r + g.normal(0, 0.2, r.shape) for r in refs]  # unbiased noise: settled at once
    assert metrics.lag_frames(noisy, refs, 2) == 0
    stale = [n + (0.3 if k in (2, 3) else 0.0) for k, n in enumerate(noisy)]  # 2 stale frames after the event
    assert metrics.lag_frames(stale, refs, 2) == 2
    se = metrics.bias_standard_error(noisy[0], refs[0])
    assert se == pytest.approx(0.2 / np.sqrt(3) / 64, rel=0.1)


def test_loglog_interpolation_and_time_to_target():
    times, errors = [1, 10, 100], [1.0, 0.1, 0.01]  # error ∝ 1/time
    assert metrics.interpolate_loglog(times, errors, 31.6227766) == pytest.approx(0.0316227766, rel=1e-6)
    assert metrics.time_to_reach(times, errors, 0.05) == pytest.approx(20.0, rel=1e-6)
    assert metrics.time_to_reach(times, errors, 0.001) == float("inf")
