"""The Translucent BSDF against closed-form answers (no bpy): Lambertian transmission, Color/π on the far side of
the surface and nothing on the viewer's (as Cycles' Translucent BSDF). Cycles comparisons of lit scenes:
tests/cycles/test_materials_cycles.py::test_translucent_bsdf_matches_cycles."""
import numpy as np
import pytest
from scenes_core import concat, irradiance_square, quad, top_down_camera, tris
from stats import standard_error

from restir_engine.core.renderer import RenderSettings, render_frame
from restir_engine.core.scene import Lamps, MaterialTable, Scene

COLOR = (0.3, 0.6, 0.9)
LE, H, A = 4.0, 1.0, 0.5  # emitter radiance, its distance from the sheet, its half size

METHODS = {"path tracer": dict(integrator="PATH"),
           "ReSTIR DI unbiased": dict(integrator="RESTIR", direct_method="RESTIR", bias_correction="UNBIASED",
                                      light_candidates=4, spatial_neighbors=3),
           "RIS": dict(integrator="RESTIR", direct_method="RIS", light_candidates=4)}


def sheet_with_emitter(behind: bool, kind: str = "translucent", width: int = 64) -> Scene:
    """A large sheet at z = 0 seen from above (top_down_camera at z = 0.5), a 2A x 2A emissive square of radiance LE
    H below it facing up (``behind``) or H above it facing down (above the camera, which does not see it)."""
    sheet = {"base_color": COLOR, "f0": 0.0, "metallic": 0.0}
    if kind == "translucent":
        sheet["translucent"] = True
    mats = MaterialTable.build([sheet, {"base_color": (0, 0, 0), "f0": 0.0, "emission": (LE,) * 3,
                                        "two_sided_emission": False}])
    floor = tris(quad((0, 0, 0), (50, 0, 0), (0, 50, 0)), 0)
    z = -H if behind else H
    light = tris(quad((0, 0, z), (A, 0, 0), (0, A, 0)) if behind else quad((0, 0, z), (0, A, 0), (A, 0, 0)), 1)
    return Scene(concat([floor, light]), mats, Lamps.empty(), top_down_camera(width, width, height_above=0.5))


def centre_means(scene, reps: int, **settings) -> np.ndarray:
    """(reps, 3) means of the central 2 x 2 pixels (within ±1/64 of the point over the emitter's centre, where the
    form factor differs by < 0.05 %) over independent seeds."""
    return np.array([render_frame(scene, RenderSettings(samples=64, max_bounces=0, seed=s, **settings))
                     .passes["Combined"][31:33, 31:33, :3].mean(axis=(0, 1)) for s in range(reps)])


@pytest.mark.slow_case  # statistical: dealt out between the Blenders in CI (tests/conftest.py)
@pytest.mark.parametrize("method", list(METHODS))
def test_translucent_sheet_passes_the_light_behind_it(method):
    """The point over the centre of an emitter behind the sheet: L = Color/π · LE · F (the square's form factor), per
    channel, within 5 standard errors (each able to see a 3 % error). Before, the Translucent BSDF rendered opaque."""
    got = centre_means(sheet_with_emitter(behind=True), 12, **METHODS[method])
    expected = np.array(COLOR) / np.pi * LE * irradiance_square(H, A)
    mean, se = got.mean(axis=0), np.array([standard_error(got[:, c]) for c in range(3)])
    assert (se < 0.006 * expected).all(), se / expected  # power: a 3 % error is at least 5 SE
    assert (np.abs(mean - expected) < 5 * se + 5e-4 * expected).all(), (mean, expected, se)


def test_translucent_sheet_reflects_nothing_and_diffuse_passes_nothing():
    """The other side of the lobe: an emitter on the viewer's side leaves a translucent sheet black, and a diffuse
    sheet with the emitter behind it is black too (with bounces: nothing else in the scene returns light)."""
    for behind, kind in ((False, "translucent"), (True, "diffuse")):
        for st in METHODS.values():
            r = render_frame(sheet_with_emitter(behind, kind, width=32), RenderSettings(samples=4, max_bounces=2,
                                                                                         **st))
            assert r.passes["Combined"][..., :3].max() == 0.0, (behind, kind, st)


def test_translucent_hits_keep_viewer_facing_data_normals():
    """Depth/Normal passes and the denoising normal face the viewer at translucent hits, as at any other."""
    r = render_frame(sheet_with_emitter(True, width=16), RenderSettings(samples=1, max_bounces=0, denoise_data=True))
    assert np.allclose(r.passes["Normal"], [0, 0, 1], atol=1e-4)
    assert np.allclose(r.passes["Denoising Normal"], [0, 0, 1], atol=1e-4)
