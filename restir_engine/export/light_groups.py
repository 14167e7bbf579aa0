"""The view layer's Light Groups -> core.lights.groups.LightGroups: the groups' names in the view layer's order and
the group of each exported instance and of the world (lamps take theirs in export/lights.py)."""
from __future__ import annotations

import numpy as np

from ..core.lights.groups import LightGroups


def group_index(depsgraph) -> dict:
    """{name: index} of the view layer's light groups (empty without any)."""
    groups = getattr(depsgraph.view_layer, "lightgroups", None) or ()
    return {g.name: i for i, g in enumerate(groups)}


def export_light_groups(depsgraph, geometry, index: dict) -> LightGroups | None:
    """The scene's light groups (None without any): an object or the world whose Light Group names no group of
    the view layer belongs to none, as in Cycles."""
    if not index:
        return None
    names = tuple(sorted(index, key=index.get))
    objects = getattr(geometry, "objects", None)
    object_group = None
    if objects is not None and len(objects.names):
        by_name = {}
        for name in set(objects.names):
            obj = depsgraph.objects.get(name)
            by_name[name] = index.get(getattr(obj, "lightgroup", "") if obj is not None else "", -1)
        object_group = np.array([by_name[n] for n in objects.names], np.int16)
    world = depsgraph.scene.world
    return LightGroups(names, object_group=object_group,
                       world_group=index.get(getattr(world, "lightgroup", "") if world is not None else "", -1))
