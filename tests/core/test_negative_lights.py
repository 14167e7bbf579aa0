"""Lights of negative power subtract their light, as in Cycles: sampled by the magnitude of their power, ReSTIR's
targets by |f · Le|, every estimate keeping its sign (no bpy here; the Cycles comparison is
tests/cycles/test_cycles_accuracy.py::test_negative_lamp_matches_cycles)."""
import numpy as np
import pytest
from scenes_core import floor_with_emitter, irradiance_square
from stats import standard_error

from restir_engine.core.renderer import RenderSettings, render_frame

ALBEDO, LE, H, A = 0.5, -4.0, 1.0, 0.5

METHODS = {"path tracer": dict(integrator="PATH"),
           "RIS": dict(integrator="RESTIR", direct_method="RIS", light_candidates=4),
           "ReSTIR DI unbiased": dict(integrator="RESTIR", direct_method="RESTIR", bias_correction="UNBIASED",
                                      light_candidates=4, spatial_neighbors=3)}


@pytest.mark.slow_case  # long: dealt out between the Blenders in CI (tests/conftest.py)
@pytest.mark.parametrize("method", list(METHODS))
def test_negative_emitter_subtracts_its_direct_light(method):
    """The floor point under the centre of an emissive square of radiance LE < 0: L = albedo/π · LE · F, negative,
    within 5 standard errors (the bound can see a 3 % error). Before, the negative light was left out (L = 0)."""
    scene = floor_with_emitter(ALBEDO, LE, H, A, width=64)
    reps = np.array([render_frame(scene, RenderSettings(samples=64, max_bounces=0, seed=s, **METHODS[method]))
                     .passes["Combined"][31:33, 31:33, 0].mean() for s in range(8)])
    expected = ALBEDO / np.pi * LE * irradiance_square(H, A)
    mean, se = reps.mean(), standard_error(reps)
    assert se < 0.006 * abs(expected)
    assert abs(mean - expected) < 5 * se + 5e-4 * abs(expected), (mean, expected, se)


def test_positive_and_negative_emitters_of_equal_power_cancel():
    """A negative emitter beside a positive one of the same size and magnitude, mirrored about the floor's middle
    line: the floor's light is odd about that line, so the image mean over the symmetric view is zero within its
    standard error, while each half is far from zero (ReSTIR DI with reuse, one bounce of the floor's light)."""
    from scenes_core import add_emitters, concat, quad, tris
    scene = floor_with_emitter(ALBEDO, 4.0, H, A, width=32)
    scene.geometry = concat([tris(quad((0, 0, 0), (50, 0, 0), (0, 50, 0)), 0)])
    pos, neg = add_emitters(scene, [(4.0,) * 3, (-4.0,) * 3])
    scene.geometry = concat([scene.geometry, tris(quad((-0.6, 0, 0.6), (0, 0.3, 0), (0.3, 0, 0)), pos),
                             tris(quad((0.6, 0, 0.6), (0, 0.3, 0), (0.3, 0, 0)), neg)])
    st = dict(samples=16, max_bounces=1, integrator="RESTIR", direct_method="RESTIR", bias_correction="UNBIASED")
    imgs = np.array([render_frame(scene, RenderSettings(seed=s, **st)).passes["Combined"][..., 0] for s in range(6)])
    total = imgs.mean(axis=(1, 2))
    left, right = imgs[:, :, :16].mean(axis=(1, 2)), imgs[:, :, 16:].mean(axis=(1, 2))
    assert left.mean() > 10 * standard_error(left) and right.mean() < -10 * standard_error(right)
    assert abs(total.mean()) < 5 * standard_error(total) + 1e-4 * left.mean(), (total.mean(), left.mean())
