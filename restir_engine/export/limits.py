"""Value ranges the core's float32 arithmetic holds: radiance above ``MAX_RADIANCE`` would overflow once it is
summed over samples and strata or squared for a variance, so the export clamps it and says so."""
from __future__ import annotations

import numpy as np

# W·sr⁻¹·m⁻² (scene-linear): float32 ends at 3.4e38, and a frame sums a pixel's radiance over up to ~1e6 samples
MAX_RADIANCE = 1e30


def clamped_radiance(values, what: str, warnings: list):
    """``values`` (array-like, any shape) with entries of magnitude above MAX_RADIANCE clamped to ±MAX_RADIANCE (a
    warning names ``what``; negative entries are a light that subtracts), NaN entries left to the caller's checks."""
    arr = np.asarray(values, np.float64)
    if np.nanmax(np.abs(arr), initial=0.0) > MAX_RADIANCE * (1.0 + 1e-6):  # 1e30 itself rounds up in float32
        warnings.append(f"{what}: radiance above {MAX_RADIANCE:g} W/sr/m² cannot be held in float32 sums and was "
                        f"clamped to {MAX_RADIANCE:g}")
        arr = np.clip(arr, -MAX_RADIANCE, MAX_RADIANCE)
    return arr
