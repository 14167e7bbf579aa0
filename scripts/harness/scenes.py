"""Scene library, built by code with bpy (deterministic; no binary .blend in git).

Each entry says what it stresses. ``ensure_blend(name, variant, size)`` builds the scene into the
cache directory on demand (keyed by a hash of the builder's source and the helpers it calls, so editing a
builder rebuilds that scene only).

  cornell      box + one emissive quad: simple, fast sanity scene; variant subdiv-K adds a
               20·4^K-triangle sphere (cost versus scene size)
  many_lights  floor, walls, Suzanne heads and pillars lit by N small emissive triangles of different
               colours and strengths (a night market); variants: 100, 1k, 10k, 100k, 1M lights
  glossy       the same objects, Principled roughness 0.05 / 0.2 / 0.5 plus metals, lit by two panels
               (where reuse across different BSDFs breaks)
  interior_gi  a room lit mostly indirectly: an emissive panel aimed at a wall
  animated     camera move + moving occluder + a light that switches off at frame 5 + an object sliding
               away to reveal a lit background (8 frames)
  default_cube Blender's factory startup scene (cube, point light, grey world): the first F12 a user tries
  many_lights_pan  many_lights (variant = light count) with a slow camera pan over PAN_FRAMES frames: temporal
               reuse under camera motion
"""
from __future__ import annotations

import hashlib
import math
import os

import bpy
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CACHE = os.environ.get("RESTIR_CACHE", os.path.join(ROOT, ".cache"))
SIZES = {"tiny": (64, 48), "small": (160, 90), "medium": (320, 180), "large": (640, 360)}


# -- building blocks (also used by the tests) ---------------------------------------------------
def enable_nodes(idblock):
    if bpy.app.version < (5, 0, 0):
        idblock.use_nodes = True


def reset():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_percentage = 100
    return scene


def _replace_surface(name, node_type):
    m = bpy.data.materials.new(name)
    enable_nodes(m)
    nodes = m.node_tree.nodes
    nodes.remove(nodes["Principled BSDF"])
    node = nodes.new(node_type)
    m.node_tree.links.new(node.outputs[0], nodes["Material Output"].inputs["Surface"])
    return m, node


def diffuse(name, color):
    m, d = _replace_surface(name, "ShaderNodeBsdfDiffuse")
    d.inputs["Color"].default_value = (*color, 1)
    d.inputs["Roughness"].default_value = 0.0
    return m


def emission(name, color, strength):
    m, e = _replace_surface(name, "ShaderNodeEmission")
    e.inputs["Color"].default_value = (*color, 1)
    e.inputs["Strength"].default_value = strength
    return m


def principled(name, color, roughness=0.5, metallic=0.0):
    m = bpy.data.materials.new(name)
    enable_nodes(m)
    b = m.node_tree.nodes["Principled BSDF"]
    b.inputs["Base Color"].default_value = (*color, 1)
    b.inputs["Roughness"].default_value = roughness
    b.inputs["Metallic"].default_value = metallic
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


def black_world(scene):
    world = bpy.data.worlds.new("World")
    enable_nodes(world)
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0, 0, 0, 1)
    scene.world = world


def mesh_from_arrays(name, verts: np.ndarray, tris: np.ndarray, material_index=None, materials=()):
    """A mesh object from (v, 3) vertices and (t, 3) triangle indices, built with foreach_set."""
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(len(verts))
    mesh.vertices.foreach_set("co", verts.astype(np.float32).ravel())
    mesh.loops.add(tris.size)
    mesh.loops.foreach_set("vertex_index", tris.astype(np.int32).ravel())
    mesh.polygons.add(len(tris))
    mesh.polygons.foreach_set("loop_start", np.arange(0, tris.size, 3, dtype=np.int32))
    mesh.polygons.foreach_set("loop_total", np.full(len(tris), 3, np.int32))
    for m in materials:
        mesh.materials.append(m)
    if material_index is not None:
        mesh.polygons.foreach_set("material_index", material_index.astype(np.int32))
    mesh.update(calc_edges=True)
    mesh.validate()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def set_size(scene, size):
    scene.render.resolution_x, scene.render.resolution_y = SIZES[size] if isinstance(size, str) else size


# -- scenes ---------------------------------------------------------------------------------------
def build_cornell(variant="default", size="tiny"):
    scene = reset()
    white, red, green = diffuse("White", (0.7, 0.7, 0.7)), diffuse("Red", (0.7, 0.1, 0.1)), diffuse("Green", (0.1, 0.6, 0.1))
    plane("Floor", 2, (0, 0, 0), material=white)
    plane("Ceiling", 2, (0, 0, 2), (math.pi, 0, 0), material=white)
    plane("Back", 2, (0, 1, 1), (math.pi / 2, 0, 0), material=white)
    plane("Left", 2, (-1, 0, 1), (0, math.pi / 2, 0), material=red)
    plane("Right", 2, (1, 0, 1), (0, -math.pi / 2, 0), material=green)
    plane("Block", 0.6, (0.3, 0.2, 0.4), (math.pi / 2, 0, 0.3), material=white)
    plane("Lamp", 0.6, (0, 0, 1.98), (math.pi, 0, 0), material=emission("Lamp", (1, 0.9, 0.8), 10.0))
    if variant.startswith("subdiv-"):  # scene-size growth: an icosphere of 20·4^k triangles
        bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=int(variant.split("-")[1]), radius=0.3,
                                              location=(-0.4, 0.3, 0.3))
        bpy.context.active_object.data.materials.append(white)
    camera((0, -3.2, 1.0), (math.pi / 2, 0, 0), lens=30)
    black_world(scene)
    set_size(scene, size)
    return scene


def _street(scene, material_for):
    """Floor, two walls, pillars and Suzanne heads (material_for(kind) gives each its material)."""
    plane("Floor", 30, (0, 0, 0), material=material_for("floor"))
    plane("Wall L", 30, (-6, 0, 4), (0, math.pi / 2, 0), material=material_for("wall"), scale=(0.3, 1, 1))
    plane("Wall R", 30, (6, 0, 4), (0, -math.pi / 2, 0), material=material_for("wall"), scale=(0.3, 1, 1))
    for i, y in enumerate((-2, 3, 8)):
        for x in (-3.5, 3.5):
            bpy.ops.mesh.primitive_cylinder_add(radius=0.35, depth=5, location=(x, y, 2.5), vertices=24)
            bpy.context.active_object.data.materials.append(material_for("pillar"))
        bpy.ops.mesh.primitive_monkey_add(size=1.4, location=(-1.2 + 1.2 * i, y + 1.0, 0.75),
                                          rotation=(0, 0, math.pi + 0.3 * (i - 1)))
        monkey = bpy.context.active_object
        mod = monkey.modifiers.new("Subdivision", "SUBSURF")
        mod.levels = mod.render_levels = 1
        monkey.data.polygons.foreach_set("use_smooth", np.ones(len(monkey.data.polygons), bool))
        monkey.data.materials.append(material_for("head"))


def build_many_lights(variant="10k", size="small"):
    """N small emissive triangles hung between the walls; colours and strengths vary (seeded)."""
    count = {"100": 100, "1k": 1000, "10k": 10000, "100k": 100000, "1m": 1000000}[variant.lower()]
    scene = reset()
    white = diffuse("White", (0.6, 0.6, 0.6))
    _street(scene, lambda kind: white)
    g = np.random.default_rng(1234)
    centers = np.stack([g.uniform(-5.5, 5.5, count), g.uniform(-4, 14, count), g.uniform(2.5, 6.0, count)], axis=1)
    size_m = 0.06 * np.sqrt(1000.0 / max(count, 1000))  # total emitting area roughly constant
    offs = g.normal(size=(count, 3, 3)) * size_m
    verts = (centers[:, None, :] + offs).reshape(-1, 3)
    tris = np.arange(count * 3).reshape(count, 3)
    palette = [((1.0, 0.55, 0.2), 40.0), ((0.3, 0.6, 1.0), 40.0), ((1.0, 0.25, 0.4), 60.0), ((0.4, 1.0, 0.5), 30.0),
               ((1.0, 0.9, 0.7), 80.0), ((0.8, 0.4, 1.0), 50.0), ((1.0, 1.0, 1.0), 300.0)]
    mats = [emission(f"Light {i}", c, s) for i, (c, s) in enumerate(palette)]
    weights = np.array([0.22, 0.22, 0.15, 0.15, 0.15, 0.1, 0.01])
    idx = g.choice(len(palette), size=count, p=weights / weights.sum())
    mesh_from_arrays("Lights", verts, tris, idx, mats)
    camera((0, -9, 2.2), (math.radians(84), 0, 0), lens=28)
    black_world(scene)
    set_size(scene, size)
    return scene


def build_glossy(variant="0.2", size="small"):
    rough = float(variant)
    scene = reset()
    mats = {"floor": principled("Floor", (0.5, 0.5, 0.5), roughness=rough),
            "wall": principled("Wall", (0.6, 0.55, 0.5), roughness=min(1.0, rough * 2)),
            "pillar": principled("Pillar", (0.9, 0.6, 0.3), roughness=rough, metallic=1.0),
            "head": principled("Head", (0.95, 0.95, 0.95), roughness=rough, metallic=1.0)}
    _street(scene, lambda kind: mats[kind])
    plane("Panel A", 3.0, (-3, 4, 6.5), (math.pi, 0, 0), material=emission("Panel A", (1, 0.85, 0.7), 6.0))
    plane("Panel B", 1.5, (3, 10, 3), (math.pi / 2, 0, 0), material=emission("Panel B", (0.6, 0.8, 1), 10.0))
    camera((0, -9, 2.2), (math.radians(84), 0, 0), lens=28)
    black_world(scene)
    set_size(scene, size)
    return scene


def build_interior_gi(variant="default", size="small"):
    scene = reset()
    white = diffuse("White", (0.75, 0.75, 0.75))
    orange = diffuse("Orange", (0.8, 0.4, 0.1))
    blue = diffuse("Blue", (0.15, 0.3, 0.8))
    plane("Floor", 8, (0, 0, 0), material=white)
    plane("Ceiling", 8, (0, 0, 3), (math.pi, 0, 0), material=white)
    plane("Back", 8, (0, 4, 1.5), (math.pi / 2, 0, 0), material=orange, scale=(1, 0.375, 1))
    plane("Front", 8, (0, -4, 1.5), (-math.pi / 2, 0, 0), material=white, scale=(1, 0.375, 1))
    plane("Left", 8, (-4, 0, 1.5), (0, math.pi / 2, 0), material=white, scale=(0.375, 1, 1))
    plane("Right", 8, (4, 0, 1.5), (0, -math.pi / 2, 0), material=blue, scale=(0.375, 1, 1))
    # the panel faces the back wall: the camera sees mostly light bounced off that wall
    plane("Panel", 1.2, (0, 3.4, 2.4), (-math.pi / 2, 0, 0), material=emission("Panel", (1, 0.95, 0.9), 40.0))
    blocker = plane("Baffle", 1.6, (0, 3.2, 2.4), (-math.pi / 2, 0, 0), material=white)
    blocker.location.y = 3.3
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.6, location=(-1.2, 0.5, 0.6), segments=32, ring_count=16)
    bpy.context.active_object.data.materials.append(white)
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(1.3, 0.0, 0.5), rotation=(0, 0, 0.4))
    bpy.context.active_object.data.materials.append(white)
    camera((0, -3.7, 1.5), (math.radians(88), 0, 0), lens=20)
    black_world(scene)
    set_size(scene, size)
    return scene


def build_default_cube(variant="default", size="medium"):
    """The factory startup file as a new user sees it (Principled cube, 1000 W point light of radius 0.1 m,
    grey world), at the library's sizes."""
    bpy.ops.wm.read_factory_settings(use_empty=False)
    scene = bpy.context.scene
    scene.render.resolution_percentage = 100
    set_size(scene, size)
    return scene


PAN_FRAMES = 8


def build_many_lights_pan(variant="10k", size="medium"):
    """many_lights with the camera panning 1° and dollying 0.1 m per frame (frames 1..PAN_FRAMES)."""
    scene = build_many_lights(variant, size)
    scene.frame_start, scene.frame_end = 1, PAN_FRAMES
    cam = scene.camera
    cam.rotation_euler.z = math.radians(-3.5)
    cam.keyframe_insert("rotation_euler", frame=1)
    cam.keyframe_insert("location", frame=1)
    cam.rotation_euler.z = math.radians(3.5)
    cam.location.y += 0.7
    cam.keyframe_insert("rotation_euler", frame=PAN_FRAMES)
    cam.keyframe_insert("location", frame=PAN_FRAMES)
    for fc in _fcurves(cam):
        for k in fc.keyframe_points:
            k.interpolation = "LINEAR"
    return scene


def build_interior_gi_pan(variant="default", size="medium"):
    """interior_gi (a room lit almost only by light bounced off its back wall) with the camera panning 1° and
    moving 0.05 m sideways per frame (frames 1..PAN_FRAMES)."""
    scene = build_interior_gi(variant, size)
    scene.frame_start, scene.frame_end = 1, PAN_FRAMES
    cam = scene.camera
    cam.rotation_euler.z = math.radians(-3.5)
    cam.keyframe_insert("rotation_euler", frame=1)
    cam.keyframe_insert("location", frame=1)
    cam.rotation_euler.z = math.radians(3.5)
    cam.location.x += 0.35
    cam.keyframe_insert("rotation_euler", frame=PAN_FRAMES)
    cam.keyframe_insert("location", frame=PAN_FRAMES)
    for fc in _fcurves(cam):
        for k in fc.keyframe_points:
            k.interpolation = "LINEAR"
    return scene


def _fcurves(obj):
    """F-curves of an object's action (Blender 4.x: action.fcurves; 5.x: layered actions)."""
    action = obj.animation_data.action
    if hasattr(action, "fcurves") and len(action.fcurves):
        return list(action.fcurves)
    out = []
    for layer in getattr(action, "layers", []):
        for strip in layer.strips:
            for bag in strip.channelbags:
                out.extend(bag.fcurves)
    return out


ANIM_FRAMES = 8
LIGHT_OFF_FRAME = 5


def build_animated(variant="default", size="small"):
    """Frames 1-8: the camera dollies, a pillar crosses the view, the red lamp switches off at frame 5,
    a panel slides away to reveal a lit back wall."""
    scene = build_cornell(size=size)
    scene.frame_start, scene.frame_end = 1, ANIM_FRAMES
    cam = scene.camera
    cam.keyframe_insert("location", frame=1)
    cam.location = (0.25, -3.0, 1.05)
    cam.keyframe_insert("location", frame=ANIM_FRAMES)
    bpy.ops.mesh.primitive_cylinder_add(radius=0.12, depth=1.6, location=(-0.7, -0.3, 0.8), vertices=16)
    pillar = bpy.context.active_object
    pillar.data.materials.append(bpy.data.materials["White"])
    pillar.keyframe_insert("location", frame=1)
    pillar.location.x = 0.7
    pillar.keyframe_insert("location", frame=ANIM_FRAMES)
    red = emission("Red lamp", (1, 0.2, 0.1), 15.0)
    plane("Red lamp", 0.3, (-0.98, 0.3, 1.4), (0, math.pi / 2, 0), material=red)
    strength = red.node_tree.nodes["Emission"].inputs["Strength"]
    strength.keyframe_insert("default_value", frame=LIGHT_OFF_FRAME - 1)
    strength.default_value = 0.0
    strength.keyframe_insert("default_value", frame=LIGHT_OFF_FRAME)
    slider = plane("Slider", 0.8, (0.2, 0.9, 1.2), (math.pi / 2, 0, 0), material=bpy.data.materials["Red"])
    slider.keyframe_insert("location", frame=1)
    slider.location.x = 1.5
    slider.keyframe_insert("location", frame=ANIM_FRAMES)
    return scene


BUILDERS = {"cornell": build_cornell, "many_lights": build_many_lights, "glossy": build_glossy,
            "interior_gi": build_interior_gi, "animated": build_animated, "default_cube": build_default_cube,
            "many_lights_pan": build_many_lights_pan, "interior_gi_pan": build_interior_gi_pan}


def _source_hash(name: str) -> str:
    """Hash of the source of scene ``name``'s builder and of every function of this module it calls (directly
    or not), and of the Blender version: editing one builder (or adding one) rebuilds only what it changes, and
    the Cycles references keyed by the file name stay valid for the others."""
    import inspect
    seen, todo, parts = set(), [BUILDERS[name]], []
    while todo:
        fn = todo.pop()
        if fn.__name__ in seen:
            continue
        seen.add(fn.__name__)
        parts.append(inspect.getsource(fn))
        for ref in fn.__code__.co_names:
            obj = globals().get(ref)
            if inspect.isfunction(obj) and obj.__module__ == __name__:
                todo.append(obj)
    text = "".join(sorted(parts)) + bpy.app.version_string
    return hashlib.sha256(text.encode()).hexdigest()[:12]


def ensure_blend(name: str, variant: str = "default", size="small") -> str:
    """Path of the cached .blend for (scene, variant, size), building it when missing or outdated."""
    size_key = size if isinstance(size, str) else f"{size[0]}x{size[1]}"
    path = os.path.join(CACHE, "scenes", f"{name}-{variant}-{size_key}-{_source_hash(name)}.blend")
    if not os.path.exists(path):
        os.makedirs(os.path.dirname(path), exist_ok=True)
        BUILDERS[name](variant=variant, size=size)
        bpy.ops.wm.save_as_mainfile(filepath=path, copy=True)
    return path
