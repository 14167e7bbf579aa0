"""Build the built-in demo scene with bpy and save it as a .blend.

A closed room (diffuse walls, one red and one green) lit by three emissive ceiling/wall panels,
with a Suzanne (glossy Principled) and a sphere (metallic), and a short camera move.

Usage: python scripts/make_demo_scene.py [--output out/demo.blend] [--frames 8]
"""
from __future__ import annotations

import argparse
import math
import os

import bpy


def _material(name, color, roughness=0.8, metallic=0.0, emission=None, strength=0.0):
    m = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Metallic"].default_value = metallic
    if emission:
        bsdf.inputs["Emission Color"].default_value = (*emission, 1.0)
        bsdf.inputs["Emission Strength"].default_value = strength
    return m


def _plane(name, size, location, rotation, material, scale=(1, 1, 1)):
    bpy.ops.mesh.primitive_plane_add(size=size, location=location, rotation=rotation)
    obj = bpy.context.active_object
    obj.name = name
    obj.scale = scale
    obj.data.materials.append(material)
    return obj


def build_demo(frames: int = 8, resolution=(640, 360)):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    white = _material("Wall", (0.75, 0.75, 0.72))
    red = _material("Red wall", (0.7, 0.12, 0.1))
    green = _material("Green wall", (0.15, 0.6, 0.15))
    # room 8 x 8 x 4, floor at z = 0
    _plane("Floor", 8, (0, 0, 0), (0, 0, 0), white)
    _plane("Ceiling", 8, (0, 0, 4), (math.pi, 0, 0), white)
    _plane("Back", 8, (0, 4, 2), (math.pi / 2, 0, 0), white, scale=(1, 0.5, 1))
    _plane("Front", 8, (0, -4, 2), (-math.pi / 2, 0, 0), white, scale=(1, 0.5, 1))
    _plane("Left", 8, (-4, 0, 2), (0, math.pi / 2, 0), red, scale=(0.5, 1, 1))
    _plane("Right", 8, (4, 0, 2), (0, -math.pi / 2, 0), green, scale=(0.5, 1, 1))
    panels = [((-1.8, 1.0, 3.98), (1.0, 0.9, 0.8), 12.0), ((1.8, 1.0, 3.98), (0.8, 0.9, 1.0), 12.0),
              ((0.0, 3.98, 2.8), (1.0, 0.7, 0.4), 8.0)]
    for i, (loc, col, strength) in enumerate(panels):
        rot = (math.pi, 0, 0) if loc[2] > 3.9 else (math.pi / 2, 0, 0)
        _plane(f"Panel {i}", 1.0, loc, rot, _material(f"Panel {i}", (0, 0, 0), emission=col, strength=strength))
    bpy.ops.mesh.primitive_monkey_add(size=1.6, location=(-1.0, 0.8, 0.9), rotation=(0, 0, math.radians(-20)))
    monkey = bpy.context.active_object
    monkey.name = "Suzanne"
    mod = monkey.modifiers.new("Subdivision", "SUBSURF")
    mod.levels = mod.render_levels = 2
    bpy.ops.object.shade_smooth()
    monkey.data.materials.append(_material("Suzanne", (0.8, 0.55, 0.2), roughness=0.35))
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.8, location=(1.5, 0.5, 0.8), segments=48, ring_count=24)
    bpy.ops.object.shade_smooth()
    sphere = bpy.context.active_object
    sphere.name = "Sphere"
    sphere.data.materials.append(_material("Metal", (0.9, 0.9, 0.9), roughness=0.25, metallic=1.0))
    # camera move from the left to the right of the front wall
    bpy.ops.object.camera_add(location=(-1.5, -3.6, 2.0), rotation=(math.radians(78), 0, math.radians(-12)))
    cam = bpy.context.active_object
    cam.data.lens = 24
    scene.camera = cam
    scene.frame_start, scene.frame_end = 1, frames
    cam.keyframe_insert("location", frame=1)
    cam.keyframe_insert("rotation_euler", frame=1)
    cam.location = (1.5, -3.6, 2.2)
    cam.rotation_euler = (math.radians(76), 0, math.radians(12))
    cam.keyframe_insert("location", frame=frames)
    cam.keyframe_insert("rotation_euler", frame=frames)
    world = bpy.data.worlds.new("World")
    if bpy.app.version < (5, 0, 0):
        world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    scene.world = world
    scene.render.resolution_x, scene.render.resolution_y = resolution
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.render.filepath = "//demo_####"
    return scene


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--output", default="out/demo.blend")
    ap.add_argument("--frames", type=int, default=8)
    args = ap.parse_args()
    build_demo(args.frames)
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(args.output))
    print("Saved", os.path.abspath(args.output))


if __name__ == "__main__":
    main()
