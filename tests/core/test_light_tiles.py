"""Light tiles (presampled candidates) and the packed target function: same estimates, cheaper."""
from __future__ import annotations

import numpy as np
import pytest

from restir_engine.core.lights import tiles as light_tiles
from restir_engine.core.materials.params import SurfaceParams
from restir_engine.core.lights.tiles import TileSettings
from restir_engine.core.renderer import RenderSettings, render_frame
from restir_engine.core.restir.di import shading_value
from restir_engine.core.sampling import orthonormal_basis, to_local
from restir_engine.core.restir.target import ShadingTerms
from stats import welch_se


class _Surf:
    """Random surfaces: positions in a box, tilted shading normals, mixed diffuse / glossy / metal (vectors
    as (3, n) rows, like the core's)."""

    def __init__(self, n, g, diffuse_only=False):
        p = g.uniform(-1, 1, (n, 3))
        ng = g.normal(size=(n, 3))
        ng /= np.linalg.norm(ng, axis=1)[:, None]
        ns = ng + 0.2 * g.normal(size=(n, 3))
        ns /= np.linalg.norm(ns, axis=1)[:, None]
        self.p, self.ng, self.ns = (np.ascontiguousarray(a.T, dtype=np.float32) for a in (p, ng, ns))
        self.t, self.bt = orthonormal_basis(self.ns)
        wo = ns + 0.8 * g.normal(size=(n, 3))
        wo /= np.linalg.norm(wo, axis=1)[:, None]
        wo_l = to_local(np.ascontiguousarray(wo.T, dtype=np.float32), self.ns, self.t, self.bt)
        wo_l[2] = np.maximum(wo_l[2], 1e-4)
        self.wo_l = (wo_l / np.linalg.norm(wo_l, axis=0)).astype(np.float32)
        kind = g.integers(0, 1 if diffuse_only else 3, n)
        base = g.uniform(0.05, 0.95, (n, 3)).astype(np.float32)
        self.params = SurfaceParams.from_material(base, (kind == 2).astype(np.float32),
                                                  g.uniform(0.05, 1.0, n).astype(np.float32),
                                                  np.where(kind == 0, 0.0, 0.04).astype(np.float32))


@pytest.mark.parametrize("diffuse_only", [False, True], ids=["mixed", "diffuse-only"])
def test_packed_target_matches_the_bsdf_model(diffuse_only):
    """ShadingTerms.evaluate (per-surface terms folded) agrees with bsdf.eval_bsdf for p̂ (including
    points below the horizon and back faces of one-sided lights) and for the BSDF pdf where p̂ > 0; with
    diffuse surfaces only it takes its square-root-free path."""
    g = np.random.default_rng(3)
    n = 4000
    surf = _Surf(n, g, diffuse_only)
    nl = g.normal(size=(3, n))
    pts = light_tiles.LightPoints(np.zeros(n, np.int32), np.zeros(n, np.float32), np.zeros(n, np.float32),
                                  g.uniform(-2, 2, (3, n)).astype(np.float32),
                                  (nl / np.linalg.norm(nl, axis=0)).astype(np.float32),
                                  g.uniform(0, 5, (3, n)).astype(np.float32), np.ones(n, np.float32),
                                  g.random(n) < 0.5, np.full(n, -1, np.int32))
    terms = ShadingTerms.of_surfaces(surf)
    assert terms.glossy != diffuse_only
    p_hat, pdf = terms.evaluate(light_tiles.PackedPoints.of(pts.packed()))
    d = pts.pos - surf.p
    dist = np.linalg.norm(d, axis=0)
    wi = (d / dist).astype(np.float32)
    cos_l = -(wi * pts.normal).sum(axis=0)
    le = np.where((cos_l > 0) | pts.two_sided, pts.le, 0.0).astype(np.float32)
    ref_p, _f, _g, ref_pdf = shading_value(surf, wi, le, dist.astype(np.float32), cos_l.astype(np.float32))
    assert (ref_p > 0).mean() > 0.2 and (ref_p == 0).mean() > 0.2  # both cases exercised
    np.testing.assert_allclose(p_hat, ref_p, rtol=2e-3, atol=1e-6 * ref_p.max())
    live = ref_p > 0  # where p̂ = 0 the pdf never matters (the candidate's weight is 0 either way)
    np.testing.assert_allclose(pdf[live], ref_pdf[live], rtol=2e-3, atol=1e-6 * ref_pdf.max())


def test_auto_turns_tiles_on_only_when_candidates_outnumber_the_tile_points():
    auto = TileSettings("AUTO", 128, 1024)
    points = 128 * 1024
    assert not auto.wanted(64 * 48, 32)
    assert auto.wanted(int(light_tiles.AUTO_FACTOR * points / 32) + 1, 32)
    assert not auto.wanted(10 ** 7, 0)
    assert TileSettings("ON").wanted(16, 1) and not TileSettings("OFF").wanted(10 ** 7, 32)


def _many_coloured_lights(width=40):
    """A floor under 60 small emitters of three colours and strengths (one-sided and two-sided)."""
    from scenes_core import concat, quad, tris, top_down_camera
    from restir_engine.core.scene import Lamps, MaterialTable, Scene
    g = np.random.default_rng(5)
    mats = MaterialTable.build([{"base_color": (0.6, 0.5, 0.4), "f0": 0.04, "roughness": 0.4},
                                {"emission": (6.0, 2.0, 1.0), "base_color": (0, 0, 0), "f0": 0.0},
                                {"emission": (1.0, 3.0, 8.0), "base_color": (0, 0, 0), "f0": 0.0,
                                 "two_sided_emission": False},
                                {"emission": (30.0, 30.0, 30.0), "base_color": (0, 0, 0), "f0": 0.0}])
    sets = [tris(quad((0, 0, 0), (50, 0, 0), (0, 50, 0)), 0)]
    for i in range(60):
        c = (g.uniform(-1.5, 1.5), g.uniform(-1.5, 1.5), g.uniform(0.4, 1.2))
        sets.append(tris(quad(c, (0, 0.04, 0), (0.04, 0, 0)), 1 + i % 3))  # normal -z
    return Scene(concat(sets), mats, Lamps.empty(), top_down_camera(width, width, height_above=0.3, half_extent=1.2))


@pytest.mark.slow_case  # long: dealt out between the Blenders in CI (tests/conftest.py)
@pytest.mark.parametrize("sampler", ["POWER", "SPATIAL"])
@pytest.mark.parametrize("method", ["RIS", "RESTIR"])
def test_tile_candidates_converge_to_the_path_tracer(method, sampler):
    """Candidates from a few small tiles (strongly correlated within a 16 x 16 block, and between
    spatial neighbours) still give the path tracer's image mean within 5 standard errors (24 independent
    seeds each: measured over 40 seeds, every renderer's image mean has a standard deviation of 0.0032 per
    seed, so se ≈ 0.0009, half the 0.8 % the check needs; the test can see a 4 % error). Temporal reuse is off: it makes the passes of one seed
    correlated, which needs many more seeds for the same power (it is tested without tiles). SPATIAL: one tile
    per block from its own light distribution (light_blocks.py), with the BSDF candidates' MIS at that pdf."""
    scene = _many_coloured_lights()
    st = dict(samples=16, max_bounces=0, integrator="RESTIR", direct_method=method, light_candidates=8,
              light_tiles="ON", light_tile_count=4, light_tile_size=64, spatial_radius=8, temporal_reuse=False,
              light_sampler=sampler)
    a = [render_frame(scene, RenderSettings(**st, seed=s)) for s in range(24)]
    assert all(r.stats["light_tiles"] for r in a)
    ma = np.array([r.passes["Combined"][..., :3].mean() for r in a])
    mb = np.array([render_frame(scene, RenderSettings(samples=8, max_bounces=0, seed=100 + s)).passes["Combined"][..., :3]
                   .mean() for s in range(24)])
    se = welch_se(ma, mb)
    assert se < 0.008 * mb.mean()
    assert abs(ma.mean() - mb.mean()) < 5 * se, (ma.mean(), mb.mean(), se)


def _block_tiles(scene, width, height_above=0.0):
    """Block tiles for a top-down view of the z = 0 floor of ``scene`` (positions of the pixel centres)."""
    from restir_engine.core.lights import blocks as light_blocks
    from restir_engine.core.integrators import trace_context
    ctx = trace_context.build_context(scene, 0)
    half = 1.2
    c = -half + (np.arange(width) + 0.5) * 2 * half / width
    pos = np.stack([np.broadcast_to(c[None, :], (width, width)), np.broadcast_to(c[:, None], (width, width)),
                    np.full((width, width), height_above)]).astype(np.float32)
    return ctx.lights, light_blocks.BlockLightTiles(ctx.lights, pos, width, width, np.random.default_rng(7), size=4096)


def test_block_tiles_store_their_blocks_pdf_and_draw_clusters_by_it():
    """Each tile point carries the area pdf of its block's distribution (the one the BSDF candidates' MIS
    evaluates), every block's cluster probabilities sum to 1, and 4096 draws per block follow them
    (chi-square over the clusters, 1e-4 false-alarm level)."""
    from restir_engine.core.lights.blocks import clusters_of
    lights, bt = _block_tiles(_many_coloured_lights(), 40)
    assert np.allclose(bt.q.sum(axis=1), 1.0)
    assert (bt.q > 0).all()  # every cluster keeps a positive probability: unbiased whatever the bound
    block = np.repeat(np.arange(bt.q.shape[0]), bt.size)
    bx, by = block % bt.blocks_x, block // bt.blocks_x
    pdf = bt.pdf_area(bt.points.light.astype(np.int64), bx * 16, by * 16)
    assert np.allclose(bt.points.pdf, pdf, rtol=1e-6)
    cl = clusters_of(lights)
    chosen = cl.cluster_of[bt.points.light].reshape(-1, bt.size)
    for b in range(bt.q.shape[0]):
        counts = np.bincount(chosen[b], minlength=cl.count)
        expected = bt.q[b] * bt.size
        keep = expected > 5
        chi2 = ((counts[keep] - expected[keep]) ** 2 / expected[keep]).sum()
        dof = max(1, keep.sum() - 1)
        assert chi2 < dof + 4.0 * np.sqrt(2 * dof) + 10, (b, chi2, dof)  # ~1e-4 tail of chi-square


def test_block_tiles_favour_the_lights_above_the_block():
    """A block right under a light gives it more probability than the power table does (the point of the
    spatial sampler), a far block less."""
    from restir_engine.core.lights.blocks import clusters_of
    scene = _many_coloured_lights()
    lights, bt = _block_tiles(scene, 40)
    cl = clusters_of(lights)
    # the light nearest to the floor point under block 0's centre, and the farthest one
    centre = np.array([-1.2 + 8 * 2.4 / 40, -1.2 + 8 * 2.4 / 40, 0.0])
    light_c = lights.tri_verts.mean(axis=1)
    d = np.linalg.norm(light_c - centre, axis=1)
    near, far = int(np.argmin(d)), int(np.argmax(d))
    power_pdf = lights.tri_pdf_area
    block_pdf = bt.pdf_area(np.array([near, far]), np.array([0, 0]), np.array([0, 0]))
    assert block_pdf[0] > 2 * power_pdf[near], (block_pdf[0], power_pdf[near])
    assert block_pdf[1] < power_pdf[far]
    from restir_engine.core.lights.blocks import CLUSTERS
    assert cl.count == min(lights.n_tri, CLUSTERS)
