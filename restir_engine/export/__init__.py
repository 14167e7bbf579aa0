"""Evaluated depsgraph -> :class:`restir_engine.core.scene.Scene` (flat NumPy arrays).

One module per datablock kind; :func:`export_scene` ties them together.
"""
from __future__ import annotations

import time

import numpy as np

from ..core.scene import Motion, Scene
from .camera import ExportError, export_camera
from .limits import clamped_radiance
from .light_groups import export_light_groups, group_index
from .lights import export_lamps
from .materials import MaterialRegistry
from .meshes import export_geometry, instance_matrices
from .object_properties import view_layer_places
from .world import export_world

__all__ = ["ExportError", "export_scene", "export_shading", "neighbour_frames"]


def neighbour_frames(engine, depsgraph, scene_out: Scene, camera_override=None, need_next=True):
    """Fill ``scene_out.motion`` by evaluating the frames before and after (``engine.frame_set``) and
    restoring the current one. Instances missing in a neighbouring frame keep their current matrix."""
    scene = depsgraph.scene
    frame = scene.frame_current
    keys = scene_out.export_stats["instance_keys"]
    current = scene_out.export_stats["instance_matrices"]
    found = {}
    for which, f in (("prev", frame - 1), ("next", frame + 1)):
        if which == "next" and not need_next:
            continue
        engine.frame_set(f, subframe=0.0)
        mats = instance_matrices(depsgraph)
        arr = np.array([mats.get(k, current[i]) for i, k in enumerate(keys)]).reshape(-1, 4, 4)
        try:
            cam = export_camera(depsgraph, camera_override, [])
        except ExportError:
            cam = None
        if cam is not None and cam.blind:  # no orientation then: no motion to measure against it
            cam = None
        found[which] = (arr, cam)
    engine.frame_set(frame, subframe=0.0)
    prev, cam_prev = found["prev"]
    nxt, cam_next = found.get("next", (current.copy(), None))
    scene_out.motion = Motion(current=current, prev=prev, next=nxt, camera_prev=cam_prev, camera_next=cam_next)


def export_scene(depsgraph, camera_override=None, camera=None, mesh_cache: dict | None = None,
                 last: Scene | None = None) -> Scene:
    """Export everything visible in ``depsgraph``; raises :class:`ExportError` on unusable input.

    camera: a ready core Camera (the viewport's view) instead of the scene's camera object.
    mesh_cache: meshes read by earlier exports (export.meshes.export_geometry), for the viewport.
    last: an earlier export with the same mesh_cache, whose triangles are reused where objects only moved.
    ``export_stats["material_index"]`` maps each material's name to its table index (incremental.py).
    """
    t0 = time.perf_counter()
    warnings: list[str] = []
    if camera is None:
        camera = export_camera(depsgraph, camera_override, warnings)
    registry = MaterialRegistry(warnings, camera, view_layer_places(depsgraph.view_layer_eval, depsgraph.scene_eval))
    geometry, stats = export_geometry(depsgraph, registry, warnings, mesh_cache,
                                      None if last is None else (last.geometry, last.export_stats))
    geometry_warnings = list(warnings)
    out = export_shading(depsgraph, registry, geometry, camera, warnings)
    out.export_stats = dict(stats, seconds=time.perf_counter() - t0, material_index=dict(registry.index),
                            geometry_warnings=geometry_warnings,
                            reads_view_layer=getattr(registry.view_layer, "read", False))
    return out


def export_shading(depsgraph, registry: MaterialRegistry, geometry, camera, warnings: list) -> Scene:
    """The lamps, the world and the material table (after the geometry registered its materials in
    ``registry``) around ``geometry``."""
    groups = group_index(depsgraph)
    lamps = export_lamps(depsgraph, registry, warnings, groups)
    world, world_image, world_rotation, camera_view, world_graph = export_world(depsgraph.scene, warnings,
                                                                                registry.view_layer)
    world = clamped_radiance(world, "World", warnings).astype(np.float32)
    if world_image is not None:
        world_image = clamped_radiance(world_image, "World texture", warnings).astype(np.float32)
    materials = registry.table()
    if lamps.textured is not None:  # the lamps' programs read the table's images
        lamps.textured.textures = materials.textures
    return Scene(geometry=geometry, materials=materials, lamps=lamps, camera=camera,
                 world_radiance=world, world_image=world_image, world_rotation=world_rotation, warnings=warnings,
                 world_camera_view=camera_view, world_graph=world_graph,
                 light_groups=export_light_groups(depsgraph, geometry, groups))
