"""Small Blender scenes for the integration tests, and helpers to render and read them back."""
from __future__ import annotations

import math
import os
import tempfile

import bpy
import numpy as np


def enable_nodes(idblock):
    if bpy.app.version < (5, 0, 0):
        idblock.use_nodes = True


def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_percentage = 100
    return scene


def diffuse(name, color):
    m = bpy.data.materials.new(name)
    enable_nodes(m)
    nodes = m.node_tree.nodes
    nodes.remove(nodes["Principled BSDF"])
    d = nodes.new("ShaderNodeBsdfDiffuse")
    d.inputs["Color"].default_value = (*color, 1)
    d.inputs["Roughness"].default_value = 0.0
    m.node_tree.links.new(d.outputs[0], nodes["Material Output"].inputs["Surface"])
    return m


def emission(name, color, strength):
    m = bpy.data.materials.new(name)
    enable_nodes(m)
    nodes = m.node_tree.nodes
    nodes.remove(nodes["Principled BSDF"])
    e = nodes.new("ShaderNodeEmission")
    e.inputs["Color"].default_value = (*color, 1)
    e.inputs["Strength"].default_value = strength
    m.node_tree.links.new(e.outputs[0], nodes["Material Output"].inputs["Surface"])
    return m


def plane(name, size, location, rotation=(0, 0, 0), material=None, scale=(1, 1, 1)):
    mesh = bpy.data.meshes.new(name)
    s = size / 2
    mesh.from_pydata([(-s, -s, 0), (s, -s, 0), (s, s, 0), (-s, s, 0)], [], [(0, 1, 2, 3)])
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    obj.location, obj.rotation_euler, obj.scale = location, rotation, scale
    if material is not None:
        mesh.materials.append(material)
    return obj


def camera(location, rotation, lens=35.0, ortho_scale=None):
    data = bpy.data.cameras.new("Camera")
    data.lens = lens
    if ortho_scale:
        data.type = "ORTHO"
        data.ortho_scale = ortho_scale
    obj = bpy.data.objects.new("Camera", data)
    bpy.context.scene.collection.objects.link(obj)
    obj.location, obj.rotation_euler = location, rotation
    bpy.context.scene.camera = obj
    return obj


def light(kind, location, rotation=(0, 0, 0), energy=100.0, color=(1, 1, 1), **attrs):
    data = bpy.data.lights.new(f"{kind} light", kind)
    data.energy = energy
    data.color = color
    for k, v in attrs.items():
        setattr(data, k, v)
    obj = bpy.data.objects.new(f"{kind} light", data)
    bpy.context.scene.collection.objects.link(obj)
    obj.location, obj.rotation_euler = location, rotation
    return obj


def cornell_box(light_kind="EMISSIVE", size=(48, 48)):
    """A 2 m Cornell-style box (floor z=0, open towards -Y where the camera is), lit from below the
    ceiling by an emissive quad facing down, an area light, a point light, a spot or a sun."""
    scene = reset()
    white, red, green = diffuse("White", (0.7, 0.7, 0.7)), diffuse("Red", (0.7, 0.1, 0.1)), diffuse("Green", (0.1, 0.6, 0.1))
    plane("Floor", 2, (0, 0, 0), material=white)
    plane("Ceiling", 2, (0, 0, 2), (math.pi, 0, 0), material=white)
    plane("Back", 2, (0, 1, 1), (math.pi / 2, 0, 0), material=white)
    plane("Left", 2, (-1, 0, 1), (0, math.pi / 2, 0), material=red)
    plane("Right", 2, (1, 0, 1), (0, -math.pi / 2, 0), material=green)
    box = plane("Block", 0.6, (0.3, 0.2, 0.4), (math.pi / 2, 0, 0.3), material=white)
    box.name = "Block"
    if light_kind == "EMISSIVE":
        plane("Lamp", 0.6, (0, 0, 1.98), (math.pi, 0, 0), material=emission("Lamp", (1, 0.9, 0.8), 10.0))
    elif light_kind == "AREA":
        light("AREA", (0, 0, 1.98), energy=30.0, color=(1, 0.9, 0.8), size=0.6)
    elif light_kind == "POINT":
        light("POINT", (0, 0, 1.5), energy=40.0, color=(1, 0.9, 0.8), shadow_soft_size=0.1)
    elif light_kind == "SPOT":
        light("SPOT", (0, 0, 1.9), energy=80.0, spot_size=math.radians(70), spot_blend=0.3, shadow_soft_size=0.05)
    elif light_kind == "SUN":
        plane("Ceiling hole", 0.001, (0, 0, 3))  # keep geometry bounds sane
        bpy.data.objects.remove(bpy.data.objects["Ceiling"])
        light("SUN", (0, 0, 5), (math.radians(20), 0, 0), energy=3.0, angle=math.radians(2))
    camera((0, -3.2, 1.0), (math.pi / 2, 0, 0), lens=30)
    scene.render.resolution_x, scene.render.resolution_y = size
    world = bpy.data.worlds.new("World")
    enable_nodes(world)
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    scene.world = world
    return scene


def configure_cycles(scene, samples: int, bounces: int, seed: int = 0):
    """Cycles as ground truth: CPU, no clamping, light threshold 0, box filter of one pixel (the same
    pixel filter as ours), no denoising, no adaptive sampling, no glossy blur."""
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = samples
    c.seed = seed
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.light_sampling_threshold = 0.0
    c.blur_glossy = 0.0
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = bounces
    c.transmission_bounces = c.volume_bounces = c.transparent_max_bounces = bounces
    c.min_light_bounces = 0
    c.caustics_reflective = c.caustics_refractive = True
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    for lamp in bpy.data.lights:  # a true sphere light (our model); soft falloff is measured in docs
        if hasattr(lamp, "use_soft_falloff"):
            lamp.use_soft_falloff = False


def configure_restir(scene, samples: int, bounces: int, seed: int = 0):
    scene.render.engine = "RESTIR"
    scene.restir.samples = samples
    scene.restir.max_bounces = bounces
    scene.restir.seed = seed
    scene.view_settings.view_transform = "Standard"


def render_passes(scene) -> dict:
    """Render the current frame and return {pass name: (h, w, c) float32, row 0 at the bottom}."""
    import OpenEXR
    settings = scene.render.image_settings
    if hasattr(settings, "media_type"):
        settings.media_type = "MULTI_LAYER_IMAGE"
    else:
        settings.file_format = "OPEN_EXR_MULTILAYER"
    settings.color_depth = "32"
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "render.exr")
        scene.render.filepath = path
        bpy.ops.render.render(write_still=True)
        f = OpenEXR.File(path)
        out = {}
        for part in f.parts:
            for name, ch in part.channels.items():
                px = np.asarray(ch.pixels, np.float32)
                if px.ndim == 2:
                    px = px[..., None]
                key = name.split(".")[1] if "." in name else name
                out.setdefault(key, []).append((name, px[::-1].copy()))  # EXR rows are top-down
        return {k: np.concatenate([p for _n, p in sorted(v)], axis=2) if len(v) > 1 else v[0][1]
                for k, v in out.items()}
