"""ReSTIR DI where it tends to fail: lights behind the surface, one very bright tiny light among dim
ones, pixels whose neighbours are all rejected. Every case: finite output, and the unbiased mode agrees
with the path tracer within 5 standard errors."""
import numpy as np

from restir_engine.core.renderer import RenderSettings, render_frame
from scenes_core import concat, floor_with_emitter, quad, tris
from restir_engine.core.scene import MaterialTable

RESTIR = dict(max_bounces=0, integrator="RESTIR", direct_method="RESTIR", light_candidates=4, spatial_radius=6)


def compare(scene, reps=10, **restir):
    a = np.array([render_frame(scene, RenderSettings(samples=2, seed=s, **{**RESTIR, **restir})).passes["Combined"]
                  for s in range(reps)])
    b = np.array([render_frame(scene, RenderSettings(samples=2, max_bounces=0, seed=100 + s)).passes["Combined"]
                  for s in range(reps)])
    assert np.isfinite(a).all()
    ma, mb = a[..., :3].mean(axis=(1, 2, 3)), b[..., :3].mean(axis=(1, 2, 3))
    se = np.sqrt(ma.var(ddof=1) / reps + mb.var(ddof=1) / reps)
    return ma.mean(), mb.mean(), se


def test_lights_behind_the_surface_give_nothing():
    scene = floor_with_emitter(width=24, two_sided=False)
    scene.geometry.verts[2:, :, 2] = -0.5  # the emitter (facing down) now hangs below the floor
    r = render_frame(scene, RenderSettings(samples=2, **RESTIR))
    assert np.isfinite(r.passes["Combined"]).all()
    assert r.passes["Direct"].max() == 0.0


def test_one_bright_tiny_light_among_dim_ones():
    scene = floor_with_emitter(width=32, le=0.5)
    mats = scene.materials
    rows = [{"base_color": tuple(mats.base_color[i]), "f0": float(mats.f0[i]), "emission": tuple(mats.emission[i])}
            for i in range(len(mats.names))]
    rows.append({"base_color": (0, 0, 0), "f0": 0.0, "emission": (20000.0,) * 3})
    scene.materials = MaterialTable.build(rows)
    tiny = tris(quad((0.3, -0.2, 0.6), (0, 0.005, 0), (0.005, 0, 0)), len(rows) - 1)
    scene.geometry = concat([scene.geometry, tiny])
    ours, ref, se = compare(scene)
    assert se < 0.02 * ref
    assert abs(ours - ref) < 5 * se, (ours, ref, se)


def test_pixels_whose_neighbours_are_all_rejected():
    """A radius far beyond the window: every neighbour is dropped, M stays 1, the estimate stays right."""
    scene = floor_with_emitter(width=24)
    r = render_frame(scene, RenderSettings(samples=1, seed=3, **{**RESTIR, "spatial_radius": 5000,
                                                                 "temporal_reuse": False}))
    assert np.allclose(r.passes["Reservoir M"], 1.0)
    ours, ref, se = compare(scene, spatial_radius=5000, temporal_reuse=False)
    assert abs(ours - ref) < 5 * se, (ours, ref, se)
