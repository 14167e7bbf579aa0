"""Object, Instancer and View Layer attributes (the Attribute node's types other than Geometry): a property of each
instance's object, read once per instance at export and looked up per hit by its instance (core
ObjectTable.properties); a View Layer attribute is one value for the whole render (a constant of the graph), looked
up on the view layer, then the scene, then its world.

As Cycles reads them: the attribute name is an RNA path (``color``, ``location``) or a custom property's name
(``prop`` or ``["prop"]``), looked up on the object, then on its data (the mesh); the Instancer type looks first on
the object that instances it (a collection instance's empty, a particle emitter), then as the Object type does. A
number or boolean v reads (v, v, v) with alpha 1, an array of 2 to 4 numbers (x, y[, z][, w]) with alpha w or 1;
anything else (a string, a missing name) reads 0 with alpha 0. Values are taken as they are (no colour space).
"""
from __future__ import annotations

from numbers import Real

from ..core.materials.nodes.attributes import OBJECT_PROPERTY, OBJECT_PROPERTY_ALPHA

MISSING = (0.0, 0.0, 0.0, 0.0)


def read_names(kind: str, name: str) -> tuple[str, str]:
    """The hit attribute names (colour, alpha) a node program reads for an Attribute node of ``kind`` and ``name``."""
    key = f"{kind}:{name}"
    return OBJECT_PROPERTY + key, OBJECT_PROPERTY_ALPHA + key


def key_of(read: str) -> str | None:
    """The property key ("KIND:name") of a hit attribute name a program reads, or None for other reads."""
    for prefix in (OBJECT_PROPERTY_ALPHA, OBJECT_PROPERTY):
        if read.startswith(prefix):
            return read[len(prefix):]
    return None


def _as_rgba(value) -> tuple | None:
    if isinstance(value, Real):  # bool and int too
        v = float(value)
        return (v, v, v, 1.0)
    if isinstance(value, str):
        return None
    try:
        items = [float(x) for x in value]
    except (TypeError, ValueError):
        return None
    if not 1 <= len(items) <= 4:
        return None
    if len(items) == 1:
        return (items[0],) * 3 + (1.0,)
    return tuple(items[:3]) + (0.0,) * (3 - min(3, len(items))) + ((items[3],) if len(items) == 4 else (1.0,))


def _lookup(idb, name: str) -> tuple | None:
    """``name`` on the ID ``idb`` as an RNA path, then as a custom property; None where neither gives a value."""
    if idb is None:
        return None
    for path in (name, f'["{name}"]') if not name.startswith("[") else (name,):
        try:
            value = idb.path_resolve(path)
        except (ValueError, TypeError, AttributeError):
            continue
        rgba = _as_rgba(value)
        if rgba is not None:
            return rgba
    return None


def instance_values(inst, obj, keys) -> dict:
    """{key: (r, g, b, a)} of the property keys ("KIND:name") for the depsgraph instance ``inst`` of ``obj``."""
    out = {}
    parent = getattr(inst, "parent", None) if getattr(inst, "is_instance", False) else None
    for key in keys:
        kind, name = key.split(":", 1)
        places = ([parent] if kind == "INSTANCER" else []) + [obj, getattr(obj, "data", None)]
        out[key] = first_value(places, name)
    return out


def unread_instance_attributes(inst, values: dict) -> list[str]:
    """The Instancer attribute names ``values`` found nowhere for an instance ``inst`` that something instances:
    Cycles may find them among the instance attributes of Geometry Nodes instances, which Blender's Python API does
    not expose (they read 0 here)."""
    if not getattr(inst, "is_instance", False):
        return []
    return [key.split(":", 1)[1] for key, v in values.items() if key.startswith("INSTANCER:") and v == MISSING]


class Places(tuple):
    """Where View Layer attributes are looked up (:func:`view_layer_places`); ``read`` turns True once a graph reads
    one (the viewport then compiles the graphs again when the scene's properties are edited)."""

    read = False


def view_layer_places(view_layer, scene) -> Places:
    """Where a View Layer attribute is looked up, in order: the view layer, the scene, the scene's world."""
    return Places(p for p in (view_layer, scene, getattr(scene, "world", None)) if p is not None)


def first_value(places, name: str) -> tuple:
    """(r, g, b, a) of ``name`` on the first of ``places`` (None entries skipped) that has it (MISSING where none
    does)."""
    for place in places:
        value = _lookup(place, name)
        if value is not None:
            return value
    return MISSING
