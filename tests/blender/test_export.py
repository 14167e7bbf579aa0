"""Depsgraph export: geometry, instances, normals, materials, textures, lights, camera."""
import math

import bpy
import numpy as np
import pytest
from bpy_scenes import camera, emission, light, plane, reset

from restir_engine.export import ExportError, export_scene


def export():
    dg = bpy.context.evaluated_depsgraph_get()
    return export_scene(dg)


@pytest.fixture
def scene(addon):
    s = reset()
    s.render.resolution_x, s.render.resolution_y = 64, 48
    camera((0, -6, 1), (math.pi / 2, 0, 0))
    return s


def test_cube_triangles_and_world_transform(scene):
    bpy.ops.mesh.primitive_cube_add(size=2, location=(1, 2, 3))
    s = export()
    assert len(s.geometry) == 12
    v = s.geometry.verts.reshape(-1, 3)
    assert np.allclose(v.min(0), [0, 1, 2]) and np.allclose(v.max(0), [2, 3, 4])
    assert (s.geometry.material == 0).all()  # no material: Blender's default grey
    assert np.allclose(s.materials.base_color[0], 0.8)


def test_modifiers_and_linked_instances(scene):
    bpy.ops.mesh.primitive_cube_add(size=1)
    cube = bpy.context.active_object
    mod = cube.modifiers.new("Array", "ARRAY")
    mod.count = 3
    dup = cube.copy()  # linked duplicate: same mesh, other transform
    bpy.context.scene.collection.objects.link(dup)
    dup.location = (0, 10, 0)
    dup.scale = (2, 2, 2)
    s = export()
    assert len(s.geometry) == 2 * 3 * 12
    v = s.geometry.verts.reshape(-1, 3)
    far = v[v[:, 1] > 5]
    assert np.isclose(far[:, 1].min(), 10 - 1) and np.isclose(far[:, 1].max(), 10 + 1)  # scaled by 2


def test_collection_instances_via_depsgraph(scene):
    coll = bpy.data.collections.new("Src")
    mesh = bpy.data.meshes.new("tri")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [(0, 1, 2)])
    obj = bpy.data.objects.new("tri", mesh)
    coll.objects.link(obj)
    for i in range(5):
        inst = bpy.data.objects.new(f"inst{i}", None)
        inst.instance_type = "COLLECTION"
        inst.instance_collection = coll
        inst.location = (i * 3, 0, 0)
        bpy.context.scene.collection.objects.link(inst)
    s = export()
    assert len(s.geometry) == 5
    assert sorted(np.round(s.geometry.verts[:, 0, 0]).tolist()) == [0, 3, 6, 9, 12]


def test_smooth_and_flat_normals(scene):
    bpy.ops.mesh.primitive_uv_sphere_add(radius=1, segments=16, ring_count=8)
    flat = export()
    v = flat.geometry.verts
    ng = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    ng /= np.linalg.norm(ng, axis=1)[:, None]
    assert np.allclose(flat.geometry.normals, ng[:, None, :], atol=1e-4)
    bpy.ops.object.shade_smooth()
    smooth = export()
    v = smooth.geometry.verts
    radial = v / np.linalg.norm(v, axis=2, keepdims=True)
    # Blender averages face normals: within ~2° of radial on this 16-segment sphere, far from flat
    cos_radial = (smooth.geometry.normals * radial).sum(axis=2)
    assert cos_radial.min() > np.cos(np.radians(3))
    assert (smooth.geometry.normals * ng[:, None, :]).sum(axis=2).min() < np.cos(np.radians(8))


def test_principled_parameters_and_emission(scene):
    bpy.ops.mesh.primitive_plane_add()
    m = bpy.data.materials.new("P")
    if bpy.app.version < (5, 0, 0):
        m.use_nodes = True
    b = m.node_tree.nodes["Principled BSDF"]
    b.inputs["Base Color"].default_value = (0.2, 0.4, 0.6, 1)
    b.inputs["Metallic"].default_value = 0.3
    b.inputs["Roughness"].default_value = 0.7
    b.inputs["Emission Color"].default_value = (1, 0.5, 0.25, 1)
    b.inputs["Emission Strength"].default_value = 4.0
    bpy.context.active_object.data.materials.append(m)
    s = export()
    i = s.geometry.material[0]
    assert np.allclose(s.materials.base_color[i], (0.2, 0.4, 0.6))
    assert np.isclose(s.materials.metallic[i], 0.3) and np.isclose(s.materials.roughness[i], 0.7)
    assert np.isclose(s.materials.f0[i], 0.04, atol=1e-4)
    assert np.allclose(s.materials.emission[i], (4.0, 2.0, 1.0))
    assert not s.warnings


def shader_plane(name: str, node_type: str):
    """A plane whose material ``name`` is one shader node of ``node_type`` on the output; returns the node."""
    bpy.ops.mesh.primitive_plane_add()
    m = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        m.use_nodes = True
    nodes = m.node_tree.nodes
    g = nodes.new(node_type)
    m.node_tree.links.new(g.outputs[0], nodes["Material Output"].inputs["Surface"])
    bpy.context.active_object.data.materials.append(m)
    return g


def test_unsupported_node_is_approximated_and_reported(scene):
    shader_plane("Cartoon", "ShaderNodeBsdfToon")
    s = export()
    assert any("Cartoon" in w and "BSDF_TOON" in w and "not supported" in w for w in s.warnings)


def test_translucent_bsdf_is_exported_as_translucent(scene):
    """A Translucent BSDF becomes a translucent row of its colour, without a warning (the lobe:
    tests/materials/test_translucent.py)."""
    shader_plane("Leaf", "ShaderNodeBsdfTranslucent").inputs["Color"].default_value = (0.2, 0.7, 0.1, 1)
    s = export()
    i = s.geometry.material[0]
    assert s.materials.translucent[i] and np.allclose(s.materials.base_color[i], (0.2, 0.7, 0.1))
    assert not s.warnings


def textured_plane(img, socket: str, name="Tex"):
    """A plane whose Principled BSDF input ``socket`` is driven by an Image Texture of ``img``."""
    bpy.ops.mesh.primitive_plane_add()
    m = bpy.data.materials.new(name)
    if bpy.app.version < (5, 0, 0):
        m.use_nodes = True
    t = m.node_tree.nodes.new("ShaderNodeTexImage")
    t.image = img
    m.node_tree.links.new(t.outputs["Color"], m.node_tree.nodes["Principled BSDF"].inputs[socket])
    bpy.context.active_object.data.materials.append(m)
    return m


def test_image_texture_feeds_base_color(scene):
    img = bpy.data.images.new("checker", 4, 2, alpha=False, float_buffer=True)
    img.colorspace_settings.name = "Linear Rec.709"
    px = np.zeros((2, 4, 4), np.float32)
    px[..., 3] = 1
    px[:, :2, 0] = 1.0  # left half red, right half blue
    px[:, 2:, 2] = 1.0
    img.pixels.foreach_set(px.ravel())
    textured_plane(img, "Base Color")
    s = export()
    i = s.geometry.material[0]
    assert s.materials.base_tex[i] == 0 and s.geometry.uvs is not None
    tex = s.materials.textures[0]
    assert tex.shape == (2, 4, 3)
    assert np.allclose(tex[:, :2], [1, 0, 0]) and np.allclose(tex[:, 2:], [0, 0, 1])
    from restir_engine.core.materials.textures import sample_bilinear
    assert np.allclose(sample_bilinear(tex, np.array([[0.25, 0.5], [0.75, 0.5]], np.float32)), [[1, 0, 0], [0, 0, 1]])
    assert s.geometry.uvs.min() >= 0 and s.geometry.uvs.max() <= 1


def test_srgb_byte_image_is_kept_encoded_and_decoded_by_its_lookups(scene):
    """An 8-bit sRGB image keeps its bytes (as Cycles keeps them) and reads scene-linear through every lookup."""
    from restir_engine.core.materials.textures import SrgbImage, linear_texels, sample
    img = bpy.data.images.new("grey", 1, 1)
    img.pixels.foreach_set(np.array([0.5, 0.5, 0.5, 1], np.float32))
    textured_plane(img, "Base Color")
    s = export()
    tex = s.materials.textures[0]
    assert isinstance(tex, SrgbImage) and np.allclose(np.asarray(tex), 128 / 255, atol=1e-7)
    want = ((128 / 255 + 0.055) / 1.055) ** 2.4
    assert np.allclose(linear_texels(tex), want, rtol=1e-5)
    assert np.allclose(sample(tex, np.array([[0.3, 0.7]], np.float32)), want, rtol=1e-5)


def test_light_table_power_conventions(scene):
    plane("Emitter", 2.0, (0, 0, 3), material=emission("E", (1, 1, 1), 5.0))  # 4 m², two-sided
    light("AREA", (5, 0, 3), energy=100.0, size=2.0)
    light("POINT", (-5, 0, 3), energy=50.0, shadow_soft_size=0.2)
    light("SUN", (0, 0, 10), energy=3.0)
    s = export()
    from restir_engine.core.lights.table import LightTable
    table = LightTable(s, scene_radius=10.0)
    assert table.n_geom == 2 and table.n_sun == 1
    # emissive mesh: power = π · L · A · 2 sides; area light: P; point light: P (luminance of white = 1)
    mesh_power = table.power[:2].sum()
    assert np.isclose(mesh_power, np.pi * 5.0 * 4.0 * 2, rtol=1e-4)
    lamp_power = table.power[2:table.n_tri]
    area_part = lamp_power[:2].sum()
    point_part = lamp_power[2:].sum()
    assert np.isclose(area_part, 100.0, rtol=1e-4) and np.isclose(point_part, 50.0, rtol=1e-4)
    assert np.allclose(s.lamps.sun_irradiance[0], 3.0) and np.allclose(s.lamps.sun_dir[0], [0, 0, 1], atol=1e-6)
    # area light faces down (local -Z)
    from restir_engine.core.lights.table import triangle_geometry
    ng, _ = triangle_geometry(s.lamps.tris.verts[:2])
    assert np.allclose(ng, [0, 0, -1], atol=1e-6)


def test_curve_and_text_export_through_their_mesh(scene):
    bpy.ops.curve.primitive_bezier_circle_add()
    bpy.context.active_object.data.extrude = 0.1
    bpy.ops.object.text_add(location=(3, 0, 0))
    s = export()
    assert len(s.geometry) > 50


def test_camera_override_and_border(scene):
    r = bpy.context.scene.render
    r.use_border = True
    r.border_min_x, r.border_max_x, r.border_min_y, r.border_max_y = 0.25, 0.75, 0.5, 1.0
    s = export()
    assert s.camera.window == (16, 24, 32, 24)
    assert (s.camera.width, s.camera.height) == (64, 48)


def test_no_camera_is_a_clear_error(addon):
    reset()
    bpy.ops.mesh.primitive_cube_add()
    with pytest.raises(ExportError, match="camera"):
        export()


def test_export_of_a_million_triangles_takes_seconds(scene):
    import time
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=708, y_subdivisions=708, size=10)  # ~1M triangles
    t0 = time.perf_counter()
    s = export()
    dt = time.perf_counter() - t0
    assert len(s.geometry) > 990_000
    assert dt < 30.0  # behaviour guard only (a per-triangle Python loop takes minutes); speed is in the benchmark


def test_metaball_and_emission_texture(scene):
    bpy.ops.object.metaball_add(type="BALL", location=(0, 0, 0))
    img = bpy.data.images.new("glow", 2, 2, float_buffer=True)
    img.colorspace_settings.name = "Linear Rec.709"
    img.pixels.foreach_set(np.tile(np.array([0.5, 0.25, 1.0, 1.0], np.float32), 4))
    m = textured_plane(img, "Emission Color", "Glow")
    bpy.context.active_object.location = (3, 0, 0)
    m.node_tree.nodes["Principled BSDF"].inputs["Emission Strength"].default_value = 2.0
    s = export()
    assert len(s.geometry) > 100  # the metaball's evaluated mesh plus the plane
    i = s.materials.names.index("Glow")
    assert s.materials.emit_tex[i] >= 0 and np.allclose(s.materials.emission[i], 2.0)
    from restir_engine.core.lights.table import LightTable
    table = LightTable(s, 10.0)
    assert table.n_geom == 2  # the plane's two triangles are lights, with the texture's mean in their power
    lum = 0.2126 * 0.5 + 0.7152 * 0.25 + 0.0722 * 1.0
    assert np.isclose(table.power[:2].sum(), np.pi * 2 * 2.0 * lum * 4.0, rtol=1e-4)


class _Frames:
    """The part of a RenderEngine export_shutter calls: frame_set on the scene."""

    def __init__(self, scene):
        self.scene = scene

    def frame_set(self, frame, subframe=0.0):
        self.scene.frame_set(frame, subframe=subframe)


def _shutter(scene):
    from restir_engine.export.motion_blur import export_shutter
    dg = bpy.context.evaluated_depsgraph_get()
    out = export_scene(dg)
    warnings = export_shutter(_Frames(scene), dg, out)
    return out, warnings


def test_motion_blur_steps_follow_the_shutter(addon):
    """Render > Motion Blur as Cycles evaluates it: 3 steps over the shutter around the frame (Center) or after it
    (Start), the camera's steps where it moves, the deforming sheet's corners per step, nothing for an object whose
    Object > Motion Blur is off; the frame is restored afterwards."""
    from bpy_scenes import motion_blur_scene
    scene = motion_blur_scene(shutter=1.0, camera_pans=True, deform=True)
    out, warnings = _shutter(scene)
    assert scene.frame_current == 2 and not warnings
    blur = out.blur
    keys = [k[0] for k in out.export_stats["instance_keys"]]
    cube = keys.index("Cube")
    # the cube moves 1 m per frame: x at frames 1.5, 2, 2.5
    np.testing.assert_allclose(blur.instance_steps[:, cube, 0, 3], [-1.0, -0.5, 0.0], atol=1e-5)
    assert blur.moving[cube] and not blur.moving[keys.index("Floor")]
    assert blur.camera_steps is not None and len(blur.camera_steps) == 3
    assert blur.deform_rows is not None and len(blur.deform_rows) == 2 * 8 * 2  # the 8 x 2 grid's triangles
    np.testing.assert_allclose(blur.deform_steps[2, :, :, 0] - blur.deform_steps[0, :, :, 0], 0.6, atol=1e-5)
    scene.render.motion_blur_position = "START"
    np.testing.assert_allclose(_shutter(scene)[0].blur.instance_steps[:, cube, 0, 3], [-0.5, 0.0, 0.5],
                               atol=1e-5)
    scene.render.motion_blur_position = "CENTER"
    bpy.data.objects["Cube"].cycles.use_motion_blur = False
    assert not _shutter(scene)[0].blur.moving[cube]
    scene.cycles.rolling_shutter_type = "TOP"
    assert any("rolling shutter" in w for w in _shutter(scene)[1])


def test_a_still_shutter_has_no_blur(scene):
    plane("Floor", 2.0, (0, 0, 0))
    scene.render.use_motion_blur = True
    out, warnings = _shutter(scene)
    assert out.blur is None and not warnings


def test_flat_faces_of_an_armature_deformed_mesh_shade_with_their_own_normals(addon):
    """A flat-shaded cube bent by an armature (a posed bone): every triangle's shading normals are its own face
    normal, as Cycles shades flat faces. Blender's corner normals of such an evaluated mesh can lag behind its
    deformed positions (the glTF add-on's shape-key test file: up to 19°, its cube 6 % too dark)."""
    import math

    import bpy
    import numpy as np
    from harness.scenes import camera, reset

    from restir_engine.export import export_scene
    reset()
    camera((0, -8, 2), (math.radians(80), 0, 0))
    bpy.ops.mesh.primitive_cube_add(size=2, location=(0, 0, 1))
    cube = bpy.context.object
    arm_data = bpy.data.armatures.new("Rig")
    rig = bpy.data.objects.new("Rig", arm_data)
    bpy.context.scene.collection.objects.link(rig)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode="EDIT")
    bone = arm_data.edit_bones.new("Bone")
    bone.head, bone.tail = (0, 0, 0), (0, 0, 2)
    bpy.ops.object.mode_set(mode="OBJECT")
    group = cube.vertex_groups.new(name="Bone")
    group.add([v.index for v in cube.data.vertices if v.co.z > 0], 1.0, "REPLACE")
    mod = cube.modifiers.new("Armature", "ARMATURE")
    mod.object = rig
    rig.pose.bones["Bone"].rotation_mode = "XYZ"
    rig.pose.bones["Bone"].rotation_euler = (0.5, 0.3, 0.0)
    bpy.context.view_layer.update()
    sc = export_scene(bpy.context.evaluated_depsgraph_get())
    v = sc.geometry.verts.astype(np.float64)
    ng = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    ng /= np.linalg.norm(ng, axis=1, keepdims=True)
    ns = sc.geometry.normals / np.linalg.norm(sc.geometry.normals, axis=2, keepdims=True)
    assert np.einsum("tij,tj->ti", ns, ng).min() > 0.9999
