"""Rendered viewport shading: progressive sample passes on a background thread, drawn as a texture.

The core is pure NumPy, so a worker thread renders while Blender's UI thread only copies the
running mean into a GPU texture in ``view_draw``. Geometry is exported in ``view_update`` (Blender's
thread, as the API requires); camera moves only restart accumulation.
"""
from __future__ import annotations

import threading

import numpy as np

from .core.renderer import FrameRenderer, RenderSettings
from .core.scene import Camera

MAX_VIEWPORT_SAMPLES = 1024
HALF_FLOAT_MAX = 65504.0  # RGBA16F textures turn larger values into inf (black viewport)


def view_camera(region_data, width: int, height: int, clip_start: float, clip_end: float) -> Camera:
    """Core camera of a 3D view: view_matrix is world->view, window_matrix the projection."""
    view = np.array(region_data.view_matrix, np.float64)
    proj = np.array(region_data.window_matrix, np.float64)
    return Camera(cam_to_world=np.linalg.inv(view), ndc_to_cam=np.linalg.inv(proj), width=width, height=height,
                  window=(0, 0, width, height), ortho=not region_data.is_perspective,
                  clip_start=clip_start, clip_end=clip_end)


class ViewportSession:
    """Owns the FrameRenderer and the worker thread of one viewport engine instance."""

    def __init__(self, redraw):
        self.redraw = redraw
        self.renderer: FrameRenderer | None = None
        self.lock = threading.Lock()
        self.stop = threading.Event()
        self.thread: threading.Thread | None = None
        self.key = None
        self.image = None  # latest Combined (h, w, 4), float32, clamped for half floats
        self.samples = 0

    def set_scene(self, scene, settings: RenderSettings):
        self.halt()
        self.renderer = FrameRenderer(scene, settings)
        self.key = None

    def set_view(self, camera: Camera, key):
        """Restart accumulation when the view (matrices, size) changed."""
        if self.renderer is None or key == self.key:
            return
        self.halt()
        self.key = key
        self.renderer.set_camera(camera)
        self.stop.clear()
        self.thread = threading.Thread(target=self._work, name="restir-viewport", daemon=True)
        self.thread.start()

    def _work(self):
        r = self.renderer
        while not self.stop.is_set() and r.samples_done < MAX_VIEWPORT_SAMPLES:
            if not r.sample_pass(should_stop=self.stop.is_set):
                return
            img = np.minimum(r.combined(), HALF_FLOAT_MAX)
            with self.lock:
                self.image, self.samples = img, r.samples_done
            self.redraw()

    def halt(self):
        self.stop.set()
        if self.thread is not None:
            self.thread.join()
        self.thread = None

    def latest(self):
        with self.lock:
            return self.image, self.samples
