"""Denoising: the Denoising Albedo / Normal passes and the compositor set-up (restir_engine/denoise.py).

The end-to-end test renders the built-in demo scene (scripts/make_demo_scene.py) at 4 samples with and without
the "Denoise" option and compares both with a Cycles reference at 256 samples (its own noise caps the measurable ratio near 60): the issue's target is a denoised
relMSE at least 5x below the raw one. One render each (a deterministic seed), so the ratio is a measurement of
this image, not a statistical claim; the margin between the measured ratio and 5 is in the assertion message."""
import os
import sys

import bpy
import numpy as np
from bpy_scenes import configure_cycles, configure_restir

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SIZE = (160, 90)


def demo_scene():
    sys.path.insert(0, os.path.join(ROOT, "scripts"))
    from make_demo_scene import build_demo
    scene = build_demo(frames=2, resolution=SIZE)
    scene.render.resolution_percentage = 100
    scene.frame_set(1)
    return scene


def render_exr(scene, path) -> np.ndarray:
    """Render the current frame to a single-layer float EXR (the composited image when compositing is on)."""
    from restir_engine.compat import set_output_format
    set_output_format(scene.render.image_settings, "OPEN_EXR")
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(path, check_existing=False)
    px = np.array(img.pixels[:], np.float32).reshape(img.size[1], img.size[0], -1)[..., :3]
    bpy.data.images.remove(img)
    return px


def rel_mse(x, ref):
    return float(np.mean((x - ref) ** 2 / (ref * ref + 1e-2)))


def test_denoising_passes_are_albedo_and_camera_space_normals(addon, tmp_path):
    from harness.render import render_scene
    scene = demo_scene()
    configure_restir(scene, 2, 2)
    scene.view_layers[0].restir.use_pass_denoising_data = True
    scene.view_layers[0].use_pass_normal = True
    passes = render_scene(scene)[0]
    albedo, normal = passes["Denoising Albedo"][..., :3], passes["Denoising Normal"][..., :3]
    assert np.isfinite(albedo).all() and albedo.min() >= 0 and albedo.max() <= 1
    assert albedo.mean() > 0.2  # the room's walls are light
    length = np.linalg.norm(normal, axis=-1)
    assert np.median(length) > 0.95 and length.max() < 1.001
    # the Normal pass (world space, pixel centres) turned into camera space agrees away from edges
    to_cam = np.array(scene.camera.matrix_world, np.float64)[:3, :3].T
    world = passes["Normal"][..., :3] @ to_cam.T
    assert np.median((world * normal).sum(axis=-1)) > 0.99


def test_denoise_option_sets_up_the_compositor_and_cuts_the_error(addon, tmp_path):
    scene = demo_scene()
    configure_cycles(scene, 256, 4, 0)
    ref = render_exr(scene, str(tmp_path / "ref.exr"))
    configure_restir(scene, 4, 4, 0)
    raw = render_exr(scene, str(tmp_path / "raw.exr"))
    scene.restir.use_denoising = True
    assert scene.view_layers[0].restir.use_pass_denoising_data
    den = render_exr(scene, str(tmp_path / "den.exr"))
    e_raw, e_den = rel_mse(raw, ref), rel_mse(den, ref)
    print(f"DENOISE raw {e_raw:.5f} denoised {e_den:.5f} ratio {e_raw / e_den:.2f}")
    assert e_raw > 5 * e_den, f"raw relMSE {e_raw:.4f}, denoised {e_den:.4f}: ratio {e_raw / e_den:.1f} (target 5)"
    scene.restir.use_denoising = False  # the option also takes the Denoise node out again: the raw image returns
    again = render_exr(scene, str(tmp_path / "again.exr"))
    np.testing.assert_allclose(again, raw, rtol=1e-5, atol=1e-6)
