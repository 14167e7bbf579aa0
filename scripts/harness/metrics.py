"""Error metrics of a rendered image against a reference (both (h, w, 3) scene-linear float).

relMSE    mean over pixels and channels of (x - ref)² / (ref² + EPS), EPS = 0.01 (keeps black pixels finite)
rel_bias  (mean(x) - mean(ref)) / mean(ref) over the image or a boolean mask
flip      mean HDR-FLIP (flip-evaluator, default 67 pixels per degree)
temporal  flicker: mean over frames of mean |e_t - e_{t-1}|, e_t = x_t - ref_t, relative to mean(ref)
lag       frames after an event until the masked relative bias stays within a tolerance
"""
from __future__ import annotations

import numpy as np

EPS = 0.01


def rel_mse(x: np.ndarray, ref: np.ndarray, eps: float = EPS) -> float:
    x = np.asarray(x, np.float64)[..., :3]
    ref = np.asarray(ref, np.float64)[..., :3]
    return float(np.mean((x - ref) ** 2 / (ref * ref + eps)))


def rel_bias(x: np.ndarray, ref: np.ndarray, mask: np.ndarray | None = None) -> float:
    x = np.asarray(x, np.float64)[..., :3]
    ref = np.asarray(ref, np.float64)[..., :3]
    if mask is not None:
        x, ref = x[mask], ref[mask]
    m = ref.mean()
    return float((x.mean() - m) / m) if m > 0 else float("nan")


def flip(x: np.ndarray, ref: np.ndarray) -> float:
    import flip_evaluator
    x = np.ascontiguousarray(np.clip(np.asarray(x, np.float32)[..., :3], 0, None))
    ref = np.ascontiguousarray(np.clip(np.asarray(ref, np.float32)[..., :3], 0, None))
    if ref.max() <= 0 and x.max() <= 0:
        return 0.0
    return float(flip_evaluator.evaluate(ref, x, "HDR", applyMagma=False)[1])


def temporal_flicker(frames: list, refs: list) -> float:
    """Mean absolute frame-to-frame change of the error, relative to the mean reference."""
    errs = [np.asarray(f, np.float64)[..., :3] - np.asarray(r, np.float64)[..., :3] for f, r in zip(frames, refs)]
    if len(errs) < 2:
        return 0.0
    scale = np.mean([np.asarray(r, np.float64)[..., :3].mean() for r in refs]) or 1.0
    return float(np.mean([np.abs(b - a).mean() for a, b in zip(errs[:-1], errs[1:])]) / scale)


def bias_standard_error(x: np.ndarray, ref: np.ndarray, mask: np.ndarray | None = None) -> float:
    """Standard error of :func:`rel_bias` from the pixel residuals (pixels' errors are independent)."""
    d = (np.asarray(x, np.float64)[..., :3] - np.asarray(ref, np.float64)[..., :3]).mean(axis=-1)
    r = np.asarray(ref, np.float64)[..., :3].mean(axis=-1)
    if mask is not None:
        d, r = d[mask], r[mask]
    return float(d.std(ddof=1) / np.sqrt(d.size) / r.mean()) if d.size > 1 and r.mean() > 0 else float("inf")


def lag_frames(frames: list, refs: list, event_index: int, mask: np.ndarray | None = None, tolerance: float | None = None,
               z: float = 4.0) -> int:
    """Frames after ``event_index`` until |relative bias| in ``mask`` stays within tolerance for the rest of
    the sequence (0 = immediately correct); len(frames) - event_index if it never settles. Without an
    explicit ``tolerance`` each frame's is ``z`` standard errors of its own noise."""
    ok = [abs(rel_bias(f, r, mask)) <= (tolerance if tolerance is not None else z * bias_standard_error(f, r, mask))
          for f, r in zip(frames, refs)]
    for k in range(event_index, len(frames)):
        if all(ok[k:]):
            return k - event_index
    return len(frames) - event_index


def interpolate_loglog(times, errors, at_time: float) -> float:
    """Error at ``at_time`` on the log-log line through (time, error) points (clamped to the range)."""
    t = np.log(np.asarray(times, float))
    e = np.log(np.asarray(errors, float))
    order = np.argsort(t)
    return float(np.exp(np.interp(np.log(at_time), t[order], e[order])))


def time_to_reach(times, errors, target: float) -> float:
    """Time at which the log-log curve first reaches ``target`` error; inf if it never does."""
    t = np.log(np.asarray(times, float))
    e = np.log(np.asarray(errors, float))
    order = np.argsort(t)
    t, e = t[order], e[order]
    lt = np.log(target)
    below = np.flatnonzero(e <= lt)
    if below.size == 0:
        return float("inf")
    k = below[0]
    if k == 0:
        return float(np.exp(t[0]))
    f = (lt - e[k - 1]) / (e[k] - e[k - 1])
    return float(np.exp(t[k - 1] + f * (t[k] - t[k - 1])))
