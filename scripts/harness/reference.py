"""Cycles ground truth, cached as .npy keyed by a hash of the scene file and the settings."""
from __future__ import annotations

import hashlib
import json
import os

import bpy
import numpy as np

from .render import render_blend
from .scenes import CACHE


def reference_key(blend: str, frame, bounces: int, samples: int) -> str:
    info = {"blend": os.path.basename(blend), "frame": frame, "bounces": bounces, "samples": samples,
            "blender": bpy.app.version_string, "filter": "box1", "clamp": 0}
    return hashlib.sha256(json.dumps(info, sort_keys=True).encode()).hexdigest()[:16]


def reference_image(blend: str, bounces: int, samples: int, frame=None, refresh: bool = False) -> np.ndarray:
    """(h, w, 3) Cycles render at ``samples`` spp; rendered once, then read from the cache."""
    path = os.path.join(CACHE, "references", reference_key(blend, frame, bounces, samples) + ".npy")
    if os.path.exists(path) and not refresh:
        return np.load(path)
    image, _wall, _core = render_blend(blend, "CYCLES", samples, bounces, seed=12345, frame=frame)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    np.save(path, image)
    return image
