"""Blackbody colour as Blender gives it (the Blackbody node, a light's Temperature): scene-linear Rec.709 with a
luminance of 1, from a table of Blender's own values (data/blackbody.json, written by
scripts/make_blackbody_table.py) interpolated linearly in log temperature; clamped to the table's 800-40000 K."""
from __future__ import annotations

import json
import os
from functools import lru_cache

import numpy as np


@lru_cache(maxsize=1)
def _table():
    with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "blackbody.json")) as f:
        data = json.load(f)
    return np.log(np.asarray(data["kelvin"], np.float64)), np.asarray(data["rgb"], np.float64)


def blackbody_rgb(kelvin) -> np.ndarray:
    """(3, ...) float32 colours of temperatures ``kelvin`` (any shape)."""
    log_t, rgb = _table()
    x = np.log(np.clip(np.asarray(kelvin, np.float64), np.exp(log_t[0]), np.exp(log_t[-1])))
    out = np.stack([np.interp(x, log_t, rgb[:, c]) for c in range(3)])
    return out.astype(np.float32)
