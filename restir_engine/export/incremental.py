"""Viewport edits without a full export: what changed (``depsgraph.updates``) decides what is exported again.

Levels, from cheapest:

- ``NONE``: nothing the image depends on (the scene camera: the viewport renders the view's own camera);
- ``SETTINGS``: only the scene's properties (render settings); the exported scene is reused as it is;
- ``SHADING``: materials, lamps, the world: the material table, lamps and world are exported again around the
  previous triangles (no mesh is read, no triangle is transformed; the Embree scene is reused);
- ``TRANSFORM``: objects moved (or their material slots changed): the triangles are transformed again from the
  meshes read before (the mesh cache), nothing is read from Blender's meshes; where only objects' matrices
  changed, only the moved objects' triangles are (the others are the last export's; the renderer then updates
  its Embree scene for the moved rows only: core/integrators/context_update.py);
- ``FULL``: geometry edited, objects added/removed/hidden, anything unknown: everything, meshes read again.
"""
from __future__ import annotations

import dataclasses

import bpy

from . import export_scene, export_shading
from .materials import MaterialRegistry
from .meshes import slot_signature
from .object_properties import view_layer_places

LEVELS = ("NONE", "SETTINGS", "SHADING", "TRANSFORM", "FULL")
_SHADING_TYPES = (bpy.types.Material, bpy.types.World, bpy.types.NodeTree, bpy.types.Image, bpy.types.Light,
                  bpy.types.Texture)
_GEOMETRY_DATA = (bpy.types.Mesh, bpy.types.Curve, bpy.types.MetaBall) + \
    tuple(getattr(bpy.types, n) for n in ("Curves", "PointCloud", "Volume", "TextCurve") if hasattr(bpy.types, n))


def update_level(updates, object_properties: bool = False, view_layer: bool = False) -> str:
    """The export level that a depsgraph's ``updates`` need (one of LEVELS); ``object_properties``: the last
    export's materials read objects' properties (the Attribute node's Object / Instancer types), which an object's
    edit (a custom property) may change without moving it: the instances are then gathered again (TRANSFORM);
    ``view_layer``: its graphs read View Layer attributes (folded into them), which an edit of the scene's or the
    view layer's properties may change: the graphs are compiled again (SHADING)."""
    level = 0
    for u in updates:
        idv = u.id
        if isinstance(idv, _SHADING_TYPES):
            need = 2
        elif isinstance(idv, bpy.types.Object):
            if idv.type == "LIGHT":
                need = 2
            elif idv.type == "CAMERA":
                need = 0
            elif u.is_updated_geometry:
                need = 4
            elif u.is_updated_transform:
                need = 3
            else:  # shading flag: a material edit, another material in a slot (checked by the exporter), a property
                need = 3 if object_properties else 2
        elif isinstance(idv, _GEOMETRY_DATA):
            need = 4 if u.is_updated_geometry else 2
        elif isinstance(idv, bpy.types.Scene):
            need = 2 if view_layer else 1
        else:  # collections (visibility, objects added or removed), anything else
            need = 4
        level = max(level, need)
    return LEVELS[level]


OBJECT_VALUES = frozenset({"object_color", "object_alpha", "object_index"})  # Object Info reads an edit may change


def reads_object_properties(scene) -> bool:
    """Whether the exported ``scene``'s materials read what an edit of an object may change without moving it:
    its properties (ObjectTable.properties) or its Object Info Color, Alpha or Pass Index."""
    objs = getattr(getattr(scene, "geometry", None), "objects", None)
    if getattr(objs, "properties", None) is not None:
        return True
    mats = getattr(scene, "materials", None)
    programs = list(getattr(mats, "programs", None) or []) + list(getattr(mats, "aov_programs", None) or [])
    return any(OBJECT_VALUES & set(prog.reads) for prog in programs)


def reads_view_layer(scene) -> bool:
    """Whether the exported ``scene``'s node graphs (materials, lamps, world) read View Layer attributes."""
    return bool(getattr(scene, "export_stats", {}).get("reads_view_layer", False))


class SceneExporter:
    """Keeps the last exported scene and the meshes it read, and exports only what an update needs.
    ``counts`` tallies the exports by level actually run (a level may fall back to a fuller one)."""

    def __init__(self):
        self.last = None
        self.mesh_cache: dict = {}
        self.counts = {level: 0 for level in LEVELS}
        self.last_level = None

    def export(self, depsgraph, camera, level: str = "FULL"):
        """The core Scene for ``depsgraph`` seen by ``camera`` (a core Camera), doing the ``level`` of work
        (update_level) when the previous export allows it."""
        out, done = None, level
        if self.last is None:
            done = "FULL"
        elif level in ("NONE", "SETTINGS"):  # a copy: the worker may be rendering the last one
            out = dataclasses.replace(self.last, camera=camera)
            out.export_stats = dict(self.last.export_stats, meshes_read=0)
        elif level == "SHADING":
            out = self._shading(depsgraph, camera)
            if out is None:
                done = "TRANSFORM"
        if out is None:
            if done == "FULL":
                self.mesh_cache.clear()
            # a transform edit re-places only the instances that moved (export.meshes._retransformed)
            out = export_scene(depsgraph, camera=camera, mesh_cache=self.mesh_cache,
                               last=self.last if done == "TRANSFORM" else None)
            out.export_stats["material_needs"] = _needs(out)
        self.counts[done] += 1
        self.last, self.last_level = out, done
        return out

    def _shading(self, depsgraph, camera):
        """Materials, lamps and world around the previous triangles; None when the triangles' material indices
        or the data read from the meshes (UVs, tangents) would change."""
        last = self.last
        stats = last.export_stats
        if slot_signature(depsgraph) != stats["slot_signature"]:
            return None
        warnings = list(stats.get("geometry_warnings", []))
        registry = MaterialRegistry(warnings, camera,
                                    view_layer_places(depsgraph.view_layer_eval, depsgraph.scene_eval))
        for name in stats["material_index"]:  # the previous order gives the previous indices
            mat = bpy.data.materials.get(name)
            if mat is None:
                return None
            registry.material_index(mat.evaluated_get(depsgraph))
        if registry.index != stats["material_index"]:  # a mix gained or lost a component: rows moved
            return None
        out = export_shading(depsgraph, registry, last.geometry, camera, warnings)
        out.export_stats = dict(stats, material_index=dict(registry.index), meshes_read=0,
                                reads_view_layer=getattr(registry.view_layer, "read", False))
        if _needs(out) != stats["material_needs"]:
            return None
        out.export_stats["material_needs"] = stats["material_needs"]
        return out


def _needs(scene) -> tuple:
    """Per material row and mix component: whether it reads a texture or a normal map (what the mesh reads
    depended on: UVs, tangents)."""
    m = scene.materials
    rows = []
    for arr in (m.base_tex, m.emit_tex, getattr(m, "alpha_tex", None), getattr(m, "normal_tex", None),
                getattr(m, "bump_tex", None), getattr(m, "mix_first", None), getattr(m, "mix_tex", None)):
        rows.append(None if arr is None else tuple(int(v) >= 0 for v in arr))
    return tuple(rows)
