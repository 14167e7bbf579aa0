"""The Principled BSDF's subsurface lobe as the surface sees it: the share of the diffuse lobe that scatters beneath
the surface (SurfaceParams ``sss``) under the diffuse lobe's layering weight. Scene-linear RGB."""
from __future__ import annotations

import numpy as np

from .bsdf import ViewTerms
from .params import PARAM_ROWS, SurfaceParams
from ..sampling import cols


def lobe_weight(surf, rows: np.ndarray) -> np.ndarray:
    """The subsurface lobe's weight (3, k) toward the viewer at surfaces ``rows``: its ``sss`` colour under the
    diffuse lobe's layering weight (the specular layer's albedo toward the viewer taken off, as Cycles layers the
    Principled lobes)."""
    p = surf.params.take(rows)
    block = p.block.copy()
    block[PARAM_ROWS["diffuse"]] = block[PARAM_ROWS["sss"]]
    block[PARAM_ROWS["on_a"]] = 1.0 / np.pi
    block[PARAM_ROWS["on_b"]] = 0.0
    block[PARAM_ROWS["on_ems"]] = 0.0
    q = SurfaceParams(block, p.lobes - {"rough_diffuse"})
    view = ViewTerms.of(q, cols(surf.wo_l, rows))
    return (view.kd * np.float32(np.pi)).astype(np.float32)
