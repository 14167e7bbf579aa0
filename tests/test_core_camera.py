"""Camera rays: the float32 affine form (used for perspective and orthographic projections) agrees with the
general projective form."""
import numpy as np
import pytest
from scenes_core import perspective_camera, top_down_camera

from restir_engine.core import camera as camera_mod


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
