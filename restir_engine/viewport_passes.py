"""The Rendered viewport's passes: which there are, and each as an image of a renderer's running mean (the light
passes scene-linear; reservoir confidences and weights, depth, normals and motion as false colours or display
values, documented in docs/USAGE.md)."""
from __future__ import annotations

import numpy as np

# viewport pass: (label, description); the RESTIR_* false colours are documented in docs/USAGE.md
VIEWPORT_PASSES = (
    ("COMBINED", "Combined", "The image"),
    ("DIRECT", "Direct", "Direct light"),
    ("INDIRECT", "Indirect", "Indirect light"),
    ("EMISSION", "Emission", "Emission seen directly"),
    ("RES_M", "Reservoir M", "ReSTIR DI confidence M, false colour (log scale, 1 to 64)"),
    ("RES_UCW", "Reservoir UCW", "ReSTIR DI unbiased contribution weight, false colour (log scale, auto range)"),
    ("GI_M", "GI Reservoir M", "ReSTIR GI confidence M, false colour (log scale, 1 to 64)"),
    ("GI_UCW", "GI Reservoir UCW", "ReSTIR GI unbiased contribution weight, false colour (log scale, auto range)"),
    ("DEPTH", "Depth", "Distance along the view axis, grey (near dark, far bright)"),
    ("NORMAL", "Normal", "World-space shading normal, 0.5 + 0.5 n"),
    ("VECTOR", "Motion", "Screen motion since the previous view, 0.5 + v / 32 px in red/green"),
)
RESERVOIR_PASSES = {"RES_M", "RES_UCW"}  # passes that make the Auto direct method resample
GI_RESERVOIR_PASSES = {"GI_M", "GI_UCW"}  # passes that make the Auto indirect method resample
DATA_PASSES = {"RES_M", "RES_UCW", "GI_M", "GI_UCW", "DEPTH", "NORMAL", "VECTOR"}  # shown without view transform
M_FULL_SCALE = 64.0  # Reservoir M at the top of its colour ramp

# a perceptual ramp from dark blue through teal and green to yellow (control points, linearly interpolated)
_RAMP = np.array([[0.267, 0.005, 0.329], [0.229, 0.322, 0.546], [0.128, 0.567, 0.551], [0.369, 0.789, 0.383],
                  [0.993, 0.906, 0.144]], np.float32)


def false_colour(t: np.ndarray) -> np.ndarray:
    """(h, w) values in [0, 1] -> (h, w, 3) colours of the ramp."""
    x = np.clip(np.nan_to_num(t), 0.0, 1.0) * (len(_RAMP) - 1)
    i = np.minimum(x.astype(np.int64), len(_RAMP) - 2)
    f = (x - i)[..., None].astype(np.float32)
    return _RAMP[i] * (1 - f) + _RAMP[i + 1] * f


def m_colour(m: np.ndarray) -> np.ndarray:
    """Reservoir confidence M -> colour: log2(1 + M) / log2(1 + 64), so 0 is the ramp's start (and black where
    nothing was hit), 1 a quarter-way, 64 or more its end."""
    out = false_colour(np.log2(1.0 + np.maximum(m, 0)) / np.log2(1.0 + M_FULL_SCALE))
    out[m <= 0] = 0.0
    return out


def ucw_colour(w: np.ndarray) -> tuple[np.ndarray, tuple[float, float]]:
    """Unbiased contribution weight -> colour on a log10 scale from its 1st to its 99th percentile over the
    pixels where it is positive (black elsewhere); returns the colours and that range."""
    pos = w > 0
    if not pos.any():
        return np.zeros(w.shape + (3,), np.float32), (0.0, 0.0)
    lw = np.log10(w[pos])
    lo, hi = (float(v) for v in np.percentile(lw, [1, 99]))
    out = np.zeros(w.shape + (3,), np.float32)
    out[pos] = false_colour((lw - lo) / max(hi - lo, 1e-6))
    return out, (10.0 ** lo, 10.0 ** hi)


def pass_image(renderer, name: str) -> tuple[np.ndarray, dict]:
    """The viewport pass ``name`` (a VIEWPORT_PASSES key) of the running mean of ``renderer`` (a FrameRenderer or a
    SharedViewRenderer) as (h, w, 4) float32 and facts about its mapping (for the header); a pass the renderer does not have (Reservoir M when the
    direct light is not resampled) is black, with the reason."""
    _x0, _y0, w, h = renderer.camera.window
    out = np.zeros((h, w, 4), np.float32)
    out[..., 3] = 1.0
    info: dict = {}
    if name == "COMBINED":
        return renderer.combined(), info
    light = {"DIRECT": "direct", "INDIRECT": "indirect", "EMISSION": "emit"}
    if name in light:
        out[..., :3] = renderer.mean(light[name])
        return out, info
    if name in ("RES_M", "RES_UCW", "GI_M", "GI_UCW"):
        key = {"RES_M": "res_m", "RES_UCW": "res_w", "GI_M": "gi_m", "GI_UCW": "gi_w"}[name]
        if not renderer.has_pass_data(key) or (name.startswith("RES") and not renderer.resamples_direct):
            info["missing"] = "no reservoirs: " + ("ReSTIR GI is off" if name.startswith("GI")
                                                   else f"the direct light uses {renderer.method}")
            return out, info
        mean = renderer.mean(key)[..., 0]
        if name.endswith("_M"):
            out[..., :3] = m_colour(mean)
            info["mean"] = float(mean[mean > 0].mean()) if (mean > 0).any() else 0.0
        else:
            out[..., :3], info["range"] = ucw_colour(mean)
        return out, info
    depth, normal, vector = renderer.data_passes()
    if name == "DEPTH":
        d = depth[..., 0]
        hit = d < 1e9
        far = float(d[hit].max()) if hit.any() else 1.0
        out[..., :3] = np.where(hit, d / max(far, 1e-6), 0.0)[..., None]
        info["range"] = (0.0, far)
    elif name == "NORMAL":
        out[..., :3] = np.where(np.any(normal != 0, axis=-1, keepdims=True), 0.5 + 0.5 * normal, 0.0)
    elif name == "VECTOR":
        out[..., :2] = 0.5 + vector[..., :2] / 32.0
        out[..., 2] = 0.5
    else:
        raise ValueError(f"unknown viewport pass {name!r}")
    return out, info
