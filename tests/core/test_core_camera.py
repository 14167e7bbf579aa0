"""Camera rays: the float32 affine form (used for perspective and orthographic projections) agrees with the
general projective form."""
import numpy as np
import pytest
from scenes_core import perspective_camera, top_down_camera

from restir_engine.core.geometry import camera as camera_mod


@pytest.mark.parametrize("cam", [perspective_camera((0.3, -2.6, 1.3), (0.0, 0.6, 0.5), 640, 360),
                                 top_down_camera(64, 48)], ids=["perspective", "orthographic"])
def test_affine_rays_match_the_projective_form(cam, monkeypatch):
    g = np.random.default_rng(0)
    x = (g.random(2000) * cam.width).astype(np.float32)
    y = (g.random(2000) * cam.height).astype(np.float32)
    assert camera_mod._clip_planes_affine(cam) is not None
    o, d, far = camera_mod.generate_rays(cam, x, y)
    monkeypatch.setattr(camera_mod, "_clip_planes_affine", lambda c: None)
    o2, d2, far2 = camera_mod.generate_rays(cam, x, y)
    np.testing.assert_allclose(o, o2, atol=1e-5)
    np.testing.assert_allclose(d, d2, atol=1e-6)
    np.testing.assert_allclose(far, far2, rtol=1e-5)


def test_box_pixels_hold_every_projected_point_of_the_boxes():
    """Random points inside two boxes project into marked pixels (perspective and orthographic); the marked share is
    small for small boxes, and a box reaching behind the camera marks the whole window."""
    rng = np.random.default_rng(3)
    lo = np.array([[-0.5, -0.2, 0.0], [0.6, 0.1, 0.2]], np.float32)
    hi = np.array([[-0.2, 0.1, 0.3], [0.9, 0.4, 0.4]], np.float32)
    for cam in (perspective_camera((0.0, -3.0, 1.5), (0.0, 0.0, 0.0), 64, 48), top_down_camera(48, 48)):
        mask = camera_mod.box_pixels(cam, lo, hi)
        k = rng.integers(0, 2, 5000)
        pts = lo[k] + rng.random((5000, 3), dtype=np.float32) * (hi[k] - lo[k])
        raster, depth = camera_mod.project(cam, pts.T)
        x0, y0, w, h = cam.window
        px, py = np.floor(raster[:, 0] - x0).astype(int), np.floor(raster[:, 1] - y0).astype(int)
        inside = (px >= 0) & (px < w) & (py >= 0) & (py < h)
        assert inside.sum() > 1000 and mask[py[inside], px[inside]].all()
        assert mask.mean() < 0.5
    cam = perspective_camera((0.0, -3.0, 1.5), (0.0, 0.0, 0.0), 64, 48)
    assert camera_mod.box_pixels(cam, np.array([[-1, -5, 0]], np.float32), np.array([[1, 1, 1]], np.float32)).all()
