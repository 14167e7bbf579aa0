"""Pixel coverage: the emission seen directly averaged over one camera ray per stratum is an unbiased estimate
of the box-filtered pixel, with less variance at emitter edges than one ray (no bpy)."""
import numpy as np
import pytest
from scenes_core import quad, top_down_camera, tris

from restir_engine.core.renderer import RenderSettings, coverage_samples, render_frame
from restir_engine.core.scene import Lamps, MaterialTable, Scene

WIDTH = 32
X0, X1, Y0, Y1 = -0.3037, 0.4121, -0.5555, 0.2718  # emitter edges inside pixels (pixel size 1/16)
LE = 2.0


def emitter_on_floor() -> Scene:
    """An emissive rectangle lying on a black floor under the top-down camera (it faces the camera)."""
    mats = MaterialTable.build([{"base_color": (0, 0, 0), "f0": 0.0},
                                {"base_color": (0, 0, 0), "f0": 0.0, "emission": (LE,) * 3}])
    floor = tris(quad((0, 0, 0), (5, 0, 0), (0, 5, 0)), 0)
    c = ((X0 + X1) / 2, (Y0 + Y1) / 2, 1e-3)
    panel = tris(quad(c, ((X1 - X0) / 2, 0, 0), (0, (Y1 - Y0) / 2, 0)), 1)
    geometry = floor
    geometry.verts = np.concatenate([floor.verts, panel.verts])
    geometry.normals = np.concatenate([floor.normals, panel.normals])
    geometry.material = np.concatenate([floor.material, panel.material])
    return Scene(geometry, mats, Lamps.empty(), top_down_camera(WIDTH, WIDTH))


def exact_emission() -> np.ndarray:
    """(h, w) emission of each box-filtered pixel: Le times the pixel area the rectangle covers."""
    edges = -1 + np.arange(WIDTH + 1) * 2 / WIDTH
    ox = np.clip(np.minimum(edges[1:], X1) - np.maximum(edges[:-1], X0), 0, None)
    oy = np.clip(np.minimum(edges[1:], Y1) - np.maximum(edges[:-1], Y0), 0, None)
    return LE * np.outer(oy, ox) / (2 / WIDTH) ** 2  # rows bottom-up, as the passes


def emission_reps(strata: int, reps: int) -> np.ndarray:
    scene = emitter_on_floor()
    return np.stack([render_frame(scene, RenderSettings(samples=1, seed=s, max_bounces=0, coverage_samples=strata))
                     .passes["Emission"][..., 0] for s in range(reps)])


def test_automatic_coverage_follows_visible_emitters():
    from restir_engine.core.integrators import trace_context
    ctx = trace_context.build_context(emitter_on_floor(), 0)
    assert coverage_samples(0, ctx.lights, ctx.scene.lamps)[0] > 1
    assert coverage_samples(5, ctx.lights, ctx.scene.lamps)[0] == 4  # rounded down to a square
    dark = emitter_on_floor()
    dark.materials.emission[:] = 0.0
    ctx = trace_context.build_context(dark, 0)
    assert coverage_samples(0, ctx.lights, ctx.scene.lamps)[0] == 1


@pytest.mark.parametrize("strata", [1, 4, 9])
def test_stratified_emission_is_unbiased(strata):
    reps = 64
    e = emission_reps(strata, reps)
    exact = exact_emission()
    edge = (exact > 0) & (exact < LE)
    interior = exact == LE
    assert np.allclose(e[:, interior], LE) and np.allclose(e[:, exact == 0], 0.0)
    # the mean over the edge pixels, per repetition: z-test of its average against the exact value
    per_rep = (e[:, edge] - exact[edge]).mean(axis=1)
    se = per_rep.std(ddof=1) / np.sqrt(reps)
    assert se < 0.01 * LE
    assert abs(per_rep.mean()) < 4 * se, (per_rep.mean(), se)


def test_strata_cut_the_variance_at_edges():
    """One ray: Var = Le² c (1 - c) for a pixel a fraction c covered; 4 strata along a straight edge leave at
    most the 2 strata the edge crosses uncertain: Var <= Le² c (1 - c) / 2 on average (measured ~1/8)."""
    reps = 48
    exact = exact_emission()
    edge = (exact > 0) & (exact < LE)
    one = emission_reps(1, reps)[:, edge].var(axis=0, ddof=1).mean()
    four = emission_reps(4, reps)[:, edge].var(axis=0, ddof=1).mean()
    c = exact[edge] / LE
    # ~90 edge pixels x 48 repetitions: the averaged variance estimate has a relative standard error of ~3 %
    assert np.isclose(one, (LE * LE * c * (1 - c)).mean(), rtol=0.12)
    assert four < 0.5 * one, (four, one)
    print(f"edge pixel variance: 1 ray {one:.4f}, 4 strata {four:.4f} ({four / one:.3f}x)")


def test_passes_spread_over_the_pixel():
    """The passes of a pixel follow a per-pixel shifted Sobol sequence: each pass uniform over the pixel (the
    16-pass mean is unbiased), and together they cover it evenly, so at an emitter's edge the variance of the
    16-pass mean is well below the Le² c (1 - c) / 16 of independent jitter (measured about 0.1x)."""
    scene = emitter_on_floor()
    reps = 32
    e = np.stack([render_frame(scene, RenderSettings(samples=16, seed=s, max_bounces=0, coverage_samples=1))
                  .passes["Emission"][..., 0] for s in range(reps)])
    exact = exact_emission()
    edge = (exact > 0) & (exact < LE)
    per_rep = (e[:, edge] - exact[edge]).mean(axis=1)
    se = per_rep.std(ddof=1) / np.sqrt(reps)
    assert abs(per_rep.mean()) < 4 * se + 1e-6, (per_rep.mean(), se)
    c = exact[edge] / LE
    independent = (LE * LE * c * (1 - c)).mean() / 16
    measured = e[:, edge].var(axis=0, ddof=1).mean()
    print(f"16-pass edge variance: {measured:.5f} against {independent:.5f} with independent jitter")
    assert measured < 0.5 * independent


def test_coverage_rays_go_where_an_emitter_can_be_seen():
    """Automatic coverage: the extra rays are cast only in the pixels an emitter's projection may touch (every
    pixel the rectangle covers is among them, pixels far from it are not), and not at all when the emitters are
    out of view; the image stays an unbiased estimate (tests above)."""
    from restir_engine.core.integrators import trace_context
    from restir_engine.core.renderer import FrameRenderer
    scene = emitter_on_floor()
    r = FrameRenderer(scene, RenderSettings(samples=1, max_bounces=0))
    assert r.coverage > 1 and r.coverage_mask is not None
    mask = r.coverage_mask.reshape(WIDTH, WIDTH)
    assert mask[exact_emission() > 0].all()
    assert 0 < mask.mean() < 0.8 and not mask[0, 0] and not mask[-1, -1]
    away = emitter_on_floor()
    away.geometry.verts[2:, :, 0] += 50.0  # the rectangle far outside the view
    ctx = trace_context.build_context(away, 0)
    assert coverage_samples(0, ctx.lights, ctx.scene.lamps, away.camera) == (1, "no emitter in view")
    assert coverage_samples(0, ctx.lights, ctx.scene.lamps)[0] > 1  # without a camera: as before
