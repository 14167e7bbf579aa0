"""The IES Texture node as a vectorized operation: a light's photometric profile (core/lights/ies.py) towards the
node's vector, times its Strength."""
from __future__ import annotations

import numpy as np

from ...lights import ies
from .ops_math import f32


def ies_texture(attrs, params, vector, strength):
    """IES Texture: Fac (n,) = Strength x the profile ``params["table"]`` (an ies.IesTable, None where the file
    could not be read) towards ``vector`` (3, n) in the light's space."""
    n = len(attrs) if attrs is not None else 1
    v = np.broadcast_to(f32(vector).reshape(3, -1), (3, n))
    out = ies.evaluate(params.get("table"), v) * f32(strength)
    return out.astype(np.float32) if attrs is not None else np.float32(out[0])


OPERATIONS = {"ies_texture": ies_texture}
