"""Evaluated depsgraph -> :class:`restir_engine.core.scene.Scene` (flat NumPy arrays).

One module per datablock kind; :func:`export_scene` ties them together.
"""
from __future__ import annotations

import time

from ..core.scene import Scene
from .camera import ExportError, export_camera
from .lights import export_lamps
from .materials import MaterialRegistry
from .meshes import export_geometry
from .world import export_world

__all__ = ["ExportError", "export_scene"]


def export_scene(depsgraph, camera_override=None, camera=None) -> Scene:
    """Export everything visible in ``depsgraph``; raises :class:`ExportError` on unusable input.

    camera: a ready core Camera (the viewport's view) instead of the scene's camera object.
    """
    t0 = time.perf_counter()
    scene = depsgraph.scene
    warnings: list[str] = []
    if camera is None:
        camera = export_camera(depsgraph, camera_override, warnings)
    registry = MaterialRegistry(warnings)
    geometry, stats = export_geometry(depsgraph, registry, warnings)
    lamps = export_lamps(depsgraph, registry, warnings)
    world = export_world(scene, warnings)
    materials = registry.table()
    out = Scene(geometry=geometry, materials=materials, lamps=lamps, camera=camera,
                world_radiance=world, warnings=warnings)
    out.export_stats = dict(stats, seconds=time.perf_counter() - t0)
    return out
