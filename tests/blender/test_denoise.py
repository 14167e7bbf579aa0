"""Denoising: the Denoising Albedo / Normal passes, Open Image Denoise in the engine (restir_engine/denoise.py,
core/pipeline/denoiser.py) and files whose compositor an older version set up to denoise.

The end-to-end test renders the built-in demo scene (scripts/make_demo_scene.py) at 4 samples with and without
denoising and compares both with a Cycles reference at 256 samples (its own noise caps the measurable ratio near 60;
rendered once and stored per Blender series, tests/cycles_reference.cycles_image):
the target is a denoised relMSE at least 5x below the raw one. One render each (a deterministic seed), so the ratio
is a measurement of this image, not a statistical claim; the margin between the measured ratio and 5 is in the
assertion message. The denoiser's own tests use synthetic images with a known clean image."""
import os
import sys

import bpy
import numpy as np
from bpy_scenes import configure_cycles, configure_restir
from cycles_reference import cycles_image

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


def test_a_new_scene_denoises_f12_without_touching_the_compositor(addon, tmp_path):
    """Denoise is on in a new scene: Combined is denoised (relMSE against Cycles at least 5x below the raw
    estimate's), Noisy Image is the raw estimate bit for bit (same seed), alpha is kept and no compositor is made."""
    from harness.render import render_scene
    assert bpy.data.scenes.new("fresh").restir.use_denoising  # Cycles' default too
    scene = demo_scene()
    configure_cycles(scene, 256, 4, 0)
    ref = cycles_image("denoise_demo", scene, lambda sc: render_scene(sc)[0]["Combined"][..., :3], 256, 4)
    configure_restir(scene, 4, 4, 0)  # the raw estimate (denoising off)
    raw = render_scene(scene)[0]["Combined"]
    trees_before = len(bpy.data.node_groups)
    scene.restir.use_denoising = True
    scene.view_layers[0].restir.use_pass_denoising_data = True
    passes = render_scene(scene)[0]
    den = passes["Combined"]
    np.testing.assert_array_equal(passes["Noisy Image"], raw)
    np.testing.assert_array_equal(den[..., 3], raw[..., 3])
    e_raw, e_den = rel_mse(raw[..., :3], ref), rel_mse(den[..., :3], ref)
    print(f"DENOISE raw {e_raw:.5f} denoised {e_den:.5f} ratio {e_raw / e_den:.2f}")
    assert e_raw > 5 * e_den, f"raw relMSE {e_raw:.4f}, denoised {e_den:.4f}: ratio {e_raw / e_den:.1f} (target 5)"
    from restir_engine.compat import compositor_tree
    tree = compositor_tree(scene, create=False)
    assert tree is None or not any(n.bl_idname == "CompositorNodeDenoise" for n in tree.nodes)
    assert len(bpy.data.node_groups) == trees_before
    # without the Denoising Data passes the denoiser still has its guides (the same image), and no Noisy Image
    scene.view_layers[0].restir.use_pass_denoising_data = False
    again = render_scene(scene)[0]
    assert "Noisy Image" not in again and "Denoising Albedo" not in again
    np.testing.assert_array_equal(again["Combined"], den)


def test_an_older_compositor_denoise_is_not_doubled_and_can_be_removed(addon, tmp_path):
    """A file whose compositor holds the Denoise node an older version wired in is not denoised again by the engine;
    the panel's operator takes the node out, after which the engine denoises."""
    from harness.render import render_scene
    from restir_engine.compat import compositor_output, compositor_tree
    from restir_engine.denoise import LEGACY_NODE, legacy_compositor_denoise
    scene = demo_scene()
    configure_restir(scene, 2, 2, 0)
    raw = render_scene(scene)[0]["Combined"]
    scene.render.use_compositing = True
    tree = compositor_tree(scene)
    layers = tree.nodes.new("CompositorNodeRLayers")
    layers.name = f"{LEGACY_NODE} Layers"
    layers.scene = scene
    den = tree.nodes.new("CompositorNodeDenoise")
    den.name = LEGACY_NODE
    _out, socket = compositor_output(tree)
    tree.links.new(layers.outputs["Image"], den.inputs["Image"])
    tree.links.new(den.outputs["Image"], socket)
    scene.restir.use_denoising = True
    assert legacy_compositor_denoise(scene)
    from restir_engine.engine import LAST_FRAME_STATS

    def view_layer_combined():  # the EXR holds the composite ("Composite.Combined") before the view layer's
        return render_scene(scene)[0]["Combined"][..., -4:]
    np.testing.assert_array_equal(view_layer_combined(), raw)  # the engine's own output: not denoised
    assert "denoise_seconds" not in LAST_FRAME_STATS
    with bpy.context.temp_override(scene=scene):
        assert bpy.ops.restir.remove_compositor_denoising() == {"FINISHED"}
    assert not legacy_compositor_denoise(scene)
    assert np.abs(view_layer_combined() - raw).max() > 1e-3
    assert LAST_FRAME_STATS["denoise_seconds"] > 0


def _noisy(shape, seed=0):
    """A smooth HDR image and a noisy estimate of it (per-pixel exponential noise of mean 1, as a 1-sample
    estimate of a diffuse surface under a small light)."""
    h, w = shape
    yy, xx = np.mgrid[0:h, 0:w].astype(np.float32)
    clean = np.stack([0.2 + 2.0 * xx / w, 0.2 + yy / h, 0.5 + 0.4 * np.sin(xx / 9.0)], -1).astype(np.float32)
    rng = np.random.default_rng(seed)
    return clean, (clean * rng.exponential(1.0, (h, w, 1))).astype(np.float32)


def test_denoiser_cuts_noise_and_keeps_the_mean(addon):
    from restir_engine.core.pipeline.denoiser import DenoiseSettings
    from restir_engine.denoise import denoiser
    clean, noisy = _noisy((96, 128))
    for prefilter in ("NONE", "FAST", "ACCURATE"):
        for quality in ("HIGH", "BALANCED", "FAST"):
            out = denoiser().denoise(noisy, settings=DenoiseSettings("RGB", prefilter, quality))
            mse_noisy, mse = float(((noisy - clean) ** 2).mean()), float(((out - clean) ** 2).mean())
            assert out.shape == clean.shape and out.dtype == np.float32
            assert mse < mse_noisy / 20, (prefilter, quality, mse_noisy, mse)
            # the noisy mean's standard error is 1/sqrt(96·128) = 0.9 %: a denoiser that kept the energy is within
            # 3 % (z = 3.3); one that lost a tenth of it fails
            assert abs(out.mean() / clean.mean() - 1) < 0.03, (prefilter, quality, out.mean(), clean.mean())


def test_the_albedo_guide_keeps_texture_edges(addon):
    """A checkerboard albedo (4-pixel squares) under smooth light: without the guide the denoiser blurs the squares
    into the noise; with it (and with albedo and normal, any prefilter) the error is at most half as large."""
    from restir_engine.core.pipeline.denoiser import DenoiseSettings
    from restir_engine.denoise import denoiser
    light, _ = _noisy((96, 128))
    yy, xx = np.mgrid[0:96, 0:128]
    albedo = np.where(((yy // 4 + xx // 4) % 2 == 0)[..., None], 0.8, 0.1).astype(np.float32) * np.ones(3, np.float32)
    clean = light * albedo
    noisy = (clean * np.random.default_rng(1).exponential(1.0, (96, 128, 1))).astype(np.float32)
    normal = np.zeros_like(clean)
    normal[..., 2] = 1.0
    alone = float(((denoiser().denoise(noisy, albedo, normal, DenoiseSettings("RGB")) - clean) ** 2).mean())
    for passes in ("RGB_ALBEDO", "RGB_ALBEDO_NORMAL"):
        for prefilter in ("NONE", "FAST", "ACCURATE"):
            out = denoiser().denoise(noisy, albedo, normal, DenoiseSettings(passes, prefilter, "HIGH"))
            guided = float(((out - clean) ** 2).mean())
            assert guided < 0.5 * alone, (passes, prefilter, guided, alone)


def test_non_finite_and_negative_input_is_read_as_black(addon):
    from restir_engine.denoise import denoiser
    clean, noisy = _noisy((32, 48))
    noisy[3, 4] = np.nan
    noisy[5, 6] = np.inf
    noisy[7, 8] = -5.0
    out = denoiser().denoise(noisy)
    assert np.isfinite(out).all() and out.min() >= 0


def test_the_denoiser_leaves_its_inputs_untouched(addon):
    """The passes handed to the denoiser (Combined, Denoising Albedo and Normal, out of range and non-finite) are
    read, never cleaned in place: the frame keeps them as rendered; the alpha of Combined is kept."""
    from restir_engine.core.pipeline.denoiser import DenoiseSettings
    from restir_engine.denoise import denoiser
    _clean, noisy = _noisy((32, 48))
    image = np.concatenate([noisy, np.full((32, 48, 1), 0.5, np.float32)], -1)
    image[1, 2, 0] = np.nan
    albedo = np.full((32, 48, 3), 1.5, np.float32)
    normal = np.full((32, 48, 3), -2.0, np.float32)
    normal[3, 4] = np.nan
    before = [a.copy() for a in (image, albedo, normal)]
    out = denoiser().denoise_rgba(image, albedo, normal, DenoiseSettings("RGB_ALBEDO_NORMAL", "ACCURATE", "HIGH"))
    for a, b in zip((image, albedo, normal), before):
        np.testing.assert_array_equal(a, b)
    assert out.shape == image.shape and np.isfinite(out).all() and (out[..., 3] == 0.5).all()
