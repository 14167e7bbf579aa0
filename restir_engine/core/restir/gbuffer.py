"""The G-buffer of one sample pass: the primary-hit surfaces of the window, compact.

Surface i (only pixels whose camera ray hit something) lies at window pixel pix[i] (row-major, row 0 at the
bottom); ``slot`` maps a pixel back to its surface (-1: nothing hit). Per surface: planar depth along the camera
axis (scene units), material and instance indices, the target function's packed terms (target.ShadingTerms,
(target.WIDTH, n)) and their shading-normal rows ``normals`` (3, n) for similarity tests."""
from __future__ import annotations

import numpy as np

from .target import ShadingTerms


class GBuffer:
    def __init__(self, pix: np.ndarray, width: int, height: int, depth: np.ndarray, instance: np.ndarray,
                 material: np.ndarray, terms: ShadingTerms):
        self.pix = pix
        self.width, self.height = width, height
        self.depth = depth
        self.instance = instance
        self.material = material
        self.terms = terms
        self.normals = getattr(terms, "ns", None)
        self.slot = np.full(width * height, -1, np.int64)
        self.slot[pix] = np.arange(len(pix))

    def __len__(self) -> int:
        return len(self.pix)

    def with_terms(self, terms: ShadingTerms) -> "GBuffer":
        """The same surfaces with other target terms (ReSTIR GI's): a shallow copy sharing every other array."""
        out = GBuffer.__new__(GBuffer)
        out.__dict__.update(self.__dict__)
        out.terms = terms
        out.normals = getattr(terms, "ns", None)
        return out
