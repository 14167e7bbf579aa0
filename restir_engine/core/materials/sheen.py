"""Sheen (Cycles' microfibre lobe: the Sheen BSDF and the Principled BSDF's Sheen layer) as a separable lobe of its
measured albedo.

Cycles' lobe reflects R(μo, r) of uniform light toward a view at μo = cos θo (roughness r; a table measured from
Cycles: data/sheen_albedo.json, scripts/make_sheen_table.py; R is held below its first μ node). Here
    f(ωo, ωi) = Color · R(μo) R(μi) / (π Ē),    Ē = 2 ∫ R(μ) μ dμ (the lobe's cosine-weighted mean albedo)
which reflects exactly R(μo) of uniform light toward every view, is reciprocal, and, like Cycles' lobe, is bright
where both the view and the light are grazing (its spread over light directions is a product form, not Cycles'
fitted one). Sampled with the diffuse lobe's cosine distribution. Surfaces: the sheen rows are diffuse rows
(Color as base colour) whose ViewTerms carry :class:`SheenRows`.
"""
from __future__ import annotations

import json
import os
from dataclasses import dataclass

import numpy as np

from .anisotropy import renumbered

_TABLE = None


def table():
    """(roughness nodes (r,), μ nodes (m,), R (r, m), Ē (r,)) float32, read on first use."""
    global _TABLE
    if _TABLE is None:
        with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "sheen_albedo.json")) as f:
            d = json.load(f)
        rs, ms = np.asarray(d["roughness"], np.float64), np.asarray(d["mu"], np.float64)
        r = np.asarray(d["albedo"], np.float64)
        mu = np.linspace(0.0, 1.0, 2001)
        y = np.stack([2 * np.interp(mu, ms, row) * mu for row in r])
        mean = ((y[:, 1:] + y[:, :-1]) * 0.5 * np.diff(mu)).sum(axis=1)  # trapezoids (numpy 1.26 has no trapezoid)
        _TABLE = tuple(a.astype(np.float32) for a in (rs, ms, r, mean))
    return _TABLE


def albedo(roughness, mu) -> np.ndarray:
    """R(μ, roughness) (broadcast shape), bilinear in the table."""
    rs, ms, r_tab, _mean = table()
    r = np.clip(np.asarray(roughness, np.float32), rs[0], rs[-1])
    m = np.clip(np.asarray(mu, np.float32), ms[0], ms[-1])
    r, m = np.broadcast_arrays(r, m)
    i = np.clip(np.searchsorted(rs, r, side="right") - 1, 0, len(rs) - 2)
    j = np.clip(np.searchsorted(ms, m, side="right") - 1, 0, len(ms) - 2)
    fr = (r - rs[i]) / (rs[i + 1] - rs[i])
    fm = (m - ms[j]) / (ms[j + 1] - ms[j])
    top = r_tab[i, j] * (1 - fm) + r_tab[i, j + 1] * fm
    bottom = r_tab[i + 1, j] * (1 - fm) + r_tab[i + 1, j + 1] * fm
    return (top * (1 - fr) + bottom * fr).astype(np.float32)


def mean_albedo(roughness) -> np.ndarray:
    """Ē(roughness), interpolated between the table's roughness nodes."""
    rs, _ms, _r, mean = table()
    return np.interp(np.asarray(roughness, np.float32), rs, mean).astype(np.float32)


@dataclass
class SheenRows:
    """The sheen surfaces of a batch: ``rows`` (k,) and their roughness (k,)."""

    rows: np.ndarray
    roughness: np.ndarray

    def take(self, idx, n: int) -> "SheenRows | None":
        """The rows of surfaces ``idx`` (index array or slice into the ``n`` surfaces), renumbered; None if none."""
        got = renumbered(self.rows, idx, n)
        return None if got is None else SheenRows(got[0], self.roughness[got[1]])

    def view_factor(self, mu_o: np.ndarray) -> np.ndarray:
        """R(μo)/Ē (k,): what the Lambert lobe's kd of these rows is scaled by toward their views."""
        return (albedo(self.roughness, mu_o) / np.maximum(mean_albedo(self.roughness), np.float32(1e-6))
                ).astype(np.float32)

    def light_factor(self, mu_i: np.ndarray) -> np.ndarray:
        """R(μi) (k,) toward local light directions of cosine ``mu_i`` (0 below the surface)."""
        return np.where(mu_i > 0, albedo(self.roughness, mu_i), np.float32(0.0)).astype(np.float32)
