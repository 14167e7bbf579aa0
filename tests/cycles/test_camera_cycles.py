"""Panoramic cameras against Cycles (same bpy, CPU): every Blender 5 panorama type in a room whose walls each
have their own colour, over a diffuse floor they light (1 bounce), 8 x 8 image cells with the materials tests'
bound (tests/stats.py); ReSTIR DI in its unbiased mode with temporal reuse (which reprojects through the
panorama) for two of them. Power: the camera turned by 3° must fail in 3 cells or more."""
import math

import numpy as np
import pytest
from bpy_scenes import panorama_scene
from cycles_compare import cycles_reference, ours_cells
from stats import MARGIN, Z_MAX, assert_cells_match, cell_means, image_cells

SIZE = (64, 32)
KINDS = ["EQUIRECTANGULAR", "FISHEYE_EQUIDISTANT", "FISHEYE_EQUISOLID", "FISHEYE_LENS_POLYNOMIAL", "MIRRORBALL",
         "CENTRAL_CYLINDRICAL"]
CASES = [(k, "PATH") for k in KINDS] + [("EQUIRECTANGULAR", "RESTIR_DI"), ("FISHEYE_EQUISOLID", "RESTIR_DI")]


@pytest.mark.parametrize("kind,method", CASES)
def test_panoramic_camera_matches_cycles(addon, kind, method):
    masks = image_cells(SIZE, 8)
    reduce = lambda im: cell_means(im, masks)  # noqa: E731
    settings = {"integrator": "PATH"} if method == "PATH" else {
        "integrator": "RESTIR", "direct_method": "RESTIR", "bias_correction": "UNBIASED", "temporal_reuse": True,
        "spatial_neighbors": 3}
    ours = ours_cells(lambda: panorama_scene(kind, SIZE), 1, 16, reduce, reps=8, **settings)
    ref = cycles_reference(f"pano_{kind.lower()}_b1", lambda: panorama_scene(kind, SIZE), 1, 64, reduce, reps=8)
    seen = [i for i in range(len(masks)) if ref.mean(0)[i] > 0.02]
    assert_cells_match(ours[:, seen], ref[:, seen], [f"cell {i}" for i in seen])
    if method == "PATH":
        def turned():
            scene = panorama_scene(kind, SIZE)
            scene.camera.rotation_euler[2] += math.radians(3)
            return scene
        off = ours_cells(turned, 1, 16, reduce, reps=4, **settings)
        se = np.sqrt(off.var(0, ddof=1) / len(off) + ref.var(0, ddof=1) / len(ref))
        bad = np.abs(off.mean(0) - ref.mean(0)) > Z_MAX * se + MARGIN * np.abs(ref.mean(0))
        assert bad[seen].sum() >= 3, "a camera turned by 3° is not told apart"


def test_panorama_directions_and_frame_points_invert(addon):
    from restir_engine.core.geometry.panorama import Panorama
    rng = np.random.default_rng(1)
    u, v = rng.random(4000), rng.random(4000)
    for kind in KINDS:
        pano = Panorama(kind, fov=math.radians(200) if kind == "FISHEYE_EQUIDISTANT" else math.pi,
                        latitude=(-1.2, 1.4), longitude=(-2.6, 3.0),
                        polynomial=(-1.17e-05, -0.01999, -3.35e-06, 3.1e-06, -2.6e-08))
        d, ok = pano.directions(u, v)
        uu, vv, back = pano.frame_points(d)
        ok &= back
        assert ok.mean() > 0.5, kind
        np.testing.assert_allclose(uu[ok], u[ok], atol=2e-4, err_msg=kind)
        np.testing.assert_allclose(vv[ok], v[ok], atol=2e-4, err_msg=kind)


@pytest.mark.parametrize("kind", ["EQUIRECTANGULAR", "DOF"])
def test_cameras_render_the_same_in_worker_processes(addon, kind):
    """A panorama, and depth of field under a Blackman-Harris filter, travel to the workers with the scene: the
    same image from 1 and 2 processes, bit for bit (ReSTIR DI with reuse, 2 samples)."""
    import bpy
    from process_runs import one_and_two_processes

    from restir_engine.core.renderer import RenderSettings
    from restir_engine.export import export_scene
    scene = panorama_scene(kind if kind != "DOF" else "EQUIRECTANGULAR", SIZE)
    if kind == "DOF":
        cam = scene.camera.data
        cam.type = "PERSP"
        cam.dof.use_dof, cam.dof.focus_distance, cam.dof.aperture_fstop = True, 2.0, 0.2
        scene.restir.pixel_filter = "BLACKMAN_HARRIS"
    sc = export_scene(bpy.context.evaluated_depsgraph_get())
    assert (sc.camera.panorama is not None) == (kind != "DOF") and (sc.camera.lens is not None) == (kind == "DOF")
    settings = RenderSettings(integrator="RESTIR", direct_method="RESTIR", samples=2, max_bounces=1, tile_pixels=512)
    one, two = one_and_two_processes(sc, settings)
    assert two.stats["processes"] == 2 and one.passes["Combined"][..., :3].mean() > 0.02
    assert np.array_equal(one.passes["Combined"], two.passes["Combined"])
