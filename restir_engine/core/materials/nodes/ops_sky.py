"""The Sky Texture node as a vectorized operation: the sky model's scene-linear radiance (core/lights/sky.py)
towards the node's vector."""
from __future__ import annotations

import numpy as np

from .ops_math import f32


def sky_texture(attrs, params, vector):
    """Sky Texture: Color (3, n) of ``params["sky"]`` (a sky.AtmosphereSky, HosekSky or PreethamSky) towards
    ``vector`` (3, n); ``params["plain"]``: the vector is the node's default (in a world, the direction itself).
    Where the attributes say ``without_sun`` (a world's image for sampling, whose sun discs are sampled apart) a
    plain sky leaves its sun's disc out."""
    n = len(attrs) if attrs is not None else 1
    v = np.broadcast_to(f32(vector).reshape(3, -1), (3, n))
    sun = not (params.get("plain") and getattr(attrs, "without_sun", False))
    out = params["sky"].radiance(np.ascontiguousarray(v), sun)
    return out if attrs is not None else out[:, :1]


OPERATIONS = {"sky_texture": sky_texture}
