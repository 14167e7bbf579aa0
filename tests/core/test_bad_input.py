"""Bad input gives a clear message and a valid (finite) image, never a crash."""
import math
import time

import bpy
import numpy as np
import pytest
from bpy_scenes import camera, configure_restir, cornell_box, render_passes, reset

from restir_engine.core.renderer import RenderSettings, render_frame
from restir_engine.engine import scene_problems
from restir_engine.export import export_scene


def export():
    return export_scene(bpy.context.evaluated_depsgraph_get())


def small_scene():
    scene = reset()
    scene.render.resolution_x = scene.render.resolution_y = 16
    camera((0, -5, 1), (math.pi / 2, 0, 0))
    configure_restir(scene, 1, 1)
    return scene


def test_no_camera_render_fails_with_a_message(addon):
    scene = reset()
    scene.render.engine = "RESTIR"
    bpy.ops.mesh.primitive_cube_add()
    with pytest.raises(RuntimeError, match="(?i)camera"):
        bpy.ops.render.render()


def test_no_lights_gives_black_image_and_warning(addon):
    scene = small_scene()
    bpy.ops.mesh.primitive_cube_add()
    p = render_passes(scene)
    assert np.isfinite(p["Combined"]).all() and p["Combined"][..., :3].max() == 0
    s = export()
    assert any("no lights" in m for m in scene_problems(s, 0))


def test_empty_scene_renders_the_world(addon):
    scene = small_scene()
    scene.world = bpy.data.worlds.new("W")
    scene.world.color = (0.25, 0.5, 1.0)
    if bpy.app.version >= (5, 0, 0):
        scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.25, 0.5, 1.0, 1)
    p = render_passes(scene)
    assert np.allclose(p["Combined"][..., :3], (0.25, 0.5, 1.0), atol=1e-5)
    assert any("nothing to render" in m for m in scene_problems(export(), 0))


def _mesh(verts, faces, name="bad"):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def test_zero_area_nan_and_huge_triangles_are_skipped_with_warnings(addon):
    cornell = cornell_box("EMISSIVE", (16, 16))
    configure_restir(cornell, 1, 1)
    _mesh([(0, 0, 0), (1, 0, 0), (2, 0, 0)], [(0, 1, 2)], "degenerate")
    nan = _mesh([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)], "nan")
    nan.data.vertices[0].co = (float("nan"), 0, 0)
    _mesh([(1e9, 0, 0), (1e9 + 1, 0, 0), (1e9, 1, 0)], [(0, 1, 2)], "huge")
    s = export()
    assert any("zero-area" in w for w in s.warnings)
    assert any("NaN" in w and "nan" in w for w in s.warnings)
    assert np.isfinite(s.geometry.verts).all() and np.abs(s.geometry.verts).max() < 1e7
    p = render_passes(cornell)
    for img in p.values():
        assert np.isfinite(img).all()
    assert p["Combined"][..., :3].mean() > 0


def test_cancel_stops_within_a_second(addon):
    """Esc (test_break) during the second sample pass: the render returns within a second with the
    first pass kept."""
    cornell_box("EMISSIVE", (320, 240))
    s = export()
    samples = 64
    asked = {}

    def progress(fraction, _msg):
        if fraction > 1.5 / samples and "t" not in asked:
            asked["t"] = time.perf_counter()

    r = render_frame(s, RenderSettings(samples=samples, max_bounces=4), progress=progress,
                     should_stop=lambda: "t" in asked)
    latency = time.perf_counter() - asked["t"]
    assert r.cancelled and r.samples_done == 1
    assert latency < 1.0, f"stopped {latency:.2f}s after the request"
    assert np.isfinite(r.passes["Combined"]).all()


def test_camera_inside_geometry_and_zero_size_light(addon):
    scene = cornell_box("AREA", (16, 16))
    configure_restir(scene, 1, 1)
    bpy.data.lights[0].size = 0.0
    scene.camera.location = (0, 0, 0.0)  # on the floor plane
    s = export()
    assert any("zero area" in w for w in s.warnings)
    p = render_passes(scene)
    assert np.isfinite(p["Combined"]).all()
