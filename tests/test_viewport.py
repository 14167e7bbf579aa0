"""Viewport session (no GPU needed): view camera, progressive worker thread, restarts, clean stop."""
import time

import bpy
import numpy as np

from bpy_scenes import cornell_box
from restir_engine.core.renderer import RenderSettings, render_frame
from restir_engine.export import export_scene
from restir_engine.viewport import ViewportSession, view_camera


class FakeRegionData:
    def __init__(self, view, window, perspective=True):
        self.view_matrix, self.window_matrix, self.is_perspective = view, window, perspective


def camera_view(scene, w, h):
    cam = scene.camera
    dg = bpy.context.evaluated_depsgraph_get()
    return FakeRegionData(cam.matrix_world.inverted(), cam.calc_matrix_camera(dg, x=w, y=h))


def test_view_camera_reproduces_the_scene_camera(addon):
    scene = cornell_box("EMISSIVE", (24, 24))
    dg = bpy.context.evaluated_depsgraph_get()
    final = export_scene(dg)
    view = export_scene(dg, camera=view_camera(camera_view(scene, 24, 24), 24, 24, 0.1, 100.0))
    a = render_frame(final, RenderSettings(samples=2, max_bounces=0, seed=3)).passes["Combined"]
    b = render_frame(view, RenderSettings(samples=2, max_bounces=0, seed=3)).passes["Combined"]
    assert np.allclose(a, b, atol=1e-4)


def test_session_accumulates_restarts_and_stops(addon):
    scene = cornell_box("EMISSIVE", (24, 24))
    redraws = []
    session = ViewportSession(lambda: redraws.append(1))
    dg = bpy.context.evaluated_depsgraph_get()
    cam = view_camera(camera_view(scene, 32, 24), 32, 24, 0.1, 100.0)
    session.set_scene(export_scene(dg, camera=cam), RenderSettings(samples=1, max_bounces=1, tile_pixels=256))
    session.set_view(cam, "view-1")
    deadline = time.time() + 20
    while session.latest()[1] < 3 and time.time() < deadline:
        time.sleep(0.05)
    image, n = session.latest()
    assert n >= 3 and image.shape == (24, 32, 4) and np.isfinite(image).all() and image[..., :3].max() > 0
    assert redraws
    session.set_view(cam, "view-1")  # same view: keeps accumulating
    assert session.latest()[1] >= n
    session.set_view(cam, "view-2")  # moved: restarts from zero
    assert session.renderer.samples_done <= 1
    session.halt()
    assert session.thread is None
