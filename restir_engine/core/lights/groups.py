"""Light groups (Blender's View Layer > Light Groups): each lamp, emissive object and the world may belong to one
named group, and the render gets one Combined pass per group with the light its members sent to the camera, by
whatever path (emission seen directly, direct light, bounces), as Cycles' "Combined_<group>" passes.

Every estimator adds its contributions to the totals and, where the frame has groups, to per-group sums (G, 3, n)
(RGB radiance, W·sr⁻¹·m⁻², scene-linear) by the group of the light that made each one, so the groups' passes sum
to the light of grouped lights exactly (to float rounding); light of lights in no group is in Combined only.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..sampling import cols


@dataclass
class LightGroups:
    """The scene's light groups: ``names`` (G,), in the view layer's order; ``object_group`` (k,) int16 the group of
    each ObjectTable instance (-1: none), or ``tri_group`` (n,) per geometry triangle where the scene has no
    instance table; ``world_group`` the world's (-1: none). Lamps carry theirs (scene.Lamps.group, sun_group)."""

    names: tuple
    object_group: np.ndarray | None = None
    tri_group: np.ndarray | None = None
    world_group: int = -1

    def __len__(self) -> int:
        return len(self.names)

    def of_triangles(self, geometry, tri: np.ndarray) -> np.ndarray:
        """(k,) int16 groups of geometry triangles ``tri``."""
        if self.tri_group is not None:
            return self.tri_group[tri].astype(np.int16)
        inst = getattr(geometry, "instance", None)
        if self.object_group is None or inst is None:
            return np.full(len(tri), -1, np.int16)
        return self.object_group[inst[tri]].astype(np.int16)


@dataclass
class GroupMap:
    """Per light of a lights.LightTable its group: ``light`` (n_tri + n_sun,) int16 (-1: none); ``world`` the
    world's; ``env_index`` the table's index of world points in reservoirs; ``count`` G."""

    count: int
    light: np.ndarray
    world: int
    env_index: int

    @staticmethod
    def of(lights, scene) -> "GroupMap | None":
        """The map of a light table built from ``scene`` (None when the scene has no light groups)."""
        groups = getattr(scene, "light_groups", None)
        if groups is None or not len(groups):
            return None
        lamps = scene.lamps
        lamp_group = getattr(lamps, "group", None)
        sun_group = getattr(lamps, "sun_group", None)
        parts = [groups.of_triangles(scene.geometry, lights.geom_ids),
                 np.full(len(lights.lamp_ids), -1, np.int16) if lamp_group is None else
                 lamp_group[lights.lamp_ids].astype(np.int16),
                 np.full(lights.n_sun, -1, np.int16) if sun_group is None else sun_group.astype(np.int16)]
        return GroupMap(len(groups), np.concatenate(parts).astype(np.int16), int(groups.world_group),
                        int(lights.env_index))

    def of_lights(self, light: np.ndarray, reservoirs: bool = False) -> np.ndarray:
        """(k,) groups of light indices ``light`` (-1: no light): indices of the light table's samples (triangles,
        then suns), or with ``reservoirs`` of DI reservoirs' samples (triangles, then world points at
        ``env_index``, which have the world's group)."""
        light = np.asarray(light)
        ok = (light >= 0) & (light < len(self.light))
        if reservoirs:
            ok &= light != self.env_index
        out = np.where(ok, self.light[np.where(ok, light, 0)], -1).astype(np.int16)
        if reservoirs and self.world >= 0:
            out[light == self.env_index] = self.world
        return out


def zeros(groups: GroupMap | None, n: int) -> np.ndarray | None:
    """(G, 3, n) float32 zeros, or None without groups."""
    return None if groups is None else np.zeros((groups.count, 3, n), np.float32)


def add(sums: np.ndarray | None, rows, group, value: np.ndarray) -> None:
    """sums[group_i, :, rows_i] += value[:, i] for each i (rows unique; group (k,) or one int; -1 skipped)."""
    if sums is None or not len(value[0]):
        return
    rows = np.asarray(rows)
    group = np.broadcast_to(np.asarray(group, np.int64), rows.shape)
    keep = group >= 0
    if not keep.all():
        rows, group, value = rows[keep], group[keep], cols(value, np.flatnonzero(keep))
    if rows.size:
        sums[group, :, rows] += value.T


class Tap(NamedTuple):
    """Where an estimator's per-row contributions also go: ``sums`` (G, 3, m), its rows ``rows`` (n,) (the caller's
    row of each of the estimator's rows; None: the same), each contribution times ``weight`` (3, n) or None."""

    sums: np.ndarray
    rows: np.ndarray | None = None
    weight: np.ndarray | None = None


def tap_add(taps, sel: np.ndarray, group, value: np.ndarray) -> None:
    """Contributions ``value`` (3, k) of the estimator's rows ``sel`` (k,), from lights of groups ``group``, into
    every tap."""
    for tap in taps:
        v = value if tap.weight is None else value * cols(tap.weight, sel)
        add(tap.sums, sel if tap.rows is None else tap.rows[sel], group, v)
