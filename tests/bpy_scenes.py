"""Small Blender scenes for the integration tests (building blocks shared with the harness)."""
from __future__ import annotations

import math

import bpy

from harness.render import configure_cycles, configure_restir, render_scene
from harness.scenes import build_cornell, camera, diffuse, emission, enable_nodes, light, plane, reset

__all__ = ["camera", "configure_cycles", "configure_restir", "cornell_box", "diffuse", "emission", "enable_nodes",
           "light", "plane", "render_passes", "reset"]


def cornell_box(light_kind="EMISSIVE", size=(48, 48)):
    """The harness's Cornell box (floor z=0, open towards -Y where the camera is), lit by its emissive quad
    facing down, or instead by an area light, a point light, a spot or a sun."""
    scene = build_cornell(size=size)
    if light_kind != "EMISSIVE":
        bpy.data.objects.remove(bpy.data.objects["Lamp"])
    if light_kind == "AREA":
        light("AREA", (0, 0, 1.98), energy=30.0, color=(1, 0.9, 0.8), size=0.6)
    elif light_kind == "POINT":
        light("POINT", (0, 0, 1.5), energy=40.0, color=(1, 0.9, 0.8), shadow_soft_size=0.1)
    elif light_kind == "SPOT":
        light("SPOT", (0, 0, 1.9), energy=80.0, spot_size=math.radians(70), spot_blend=0.3, shadow_soft_size=0.05)
    elif light_kind == "SUN":
        bpy.data.objects.remove(bpy.data.objects["Ceiling"])
        light("SUN", (0, 0, 5), (math.radians(20), 0, 0), energy=3.0, angle=math.radians(2))
    return scene


def render_passes(scene) -> dict:
    """Render the current frame and return {pass name: (h, w, c) float32, row 0 at the bottom}."""
    return render_scene(scene)[0]
