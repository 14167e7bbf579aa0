"""Cycles ground truth, cached as .npy keyed by a hash of the scene file and the settings."""
from __future__ import annotations

import hashlib
import json
import os

import bpy
import numpy as np

from .render import render_blend, render_blend_passes
from .scenes import CACHE


def reference_key(blend: str, frame, bounces: int, samples: int, what: str = "combined") -> str:
    info = {"blend": os.path.basename(blend), "frame": frame, "bounces": bounces, "samples": samples,
            "blender": bpy.app.version_string, "filter": "box1", "clamp": 0}
    if what != "combined":
        info["what"] = what
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


def reference_lit(blend: str, bounces: int, samples: int, frame=None, refresh: bool = False) -> np.ndarray:
    """(h, w, 3) Cycles Combined minus its Emit pass (the light reflected by surfaces, without emitters seen
    directly) at ``samples`` spp; rendered once with :func:`reference_image`'s image, then cached."""
    path = os.path.join(CACHE, "references", reference_key(blend, frame, bounces, samples, "lit") + ".npy")
    if os.path.exists(path) and not refresh:
        return np.load(path)
    passes, _wall, _core = render_blend_passes(blend, "CYCLES", samples, bounces, seed=12345, frame=frame,
                                               emission=True)
    combined = passes["Combined"][..., :3]
    lit = combined - passes["Emission"][..., :3]
    os.makedirs(os.path.dirname(path), exist_ok=True)
    np.save(path, lit)
    np.save(os.path.join(CACHE, "references", reference_key(blend, frame, bounces, samples) + ".npy"), combined)
    return lit
