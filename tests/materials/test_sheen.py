"""The sheen lobe (core/materials/sheen.py) against its definition by Monte Carlo integration (5 standard errors):
toward every view it reflects Color x R(μo) of uniform light, it is reciprocal, and the BSDF sampler's estimate
agrees. Against Cycles: tests/cycles/test_materials_cycles.test_principled_sheen_matches_cycles_within_its_approximation;
the table's measurement: scripts/make_sheen_table.py."""
import numpy as np
import pytest

from restir_engine.core.materials import bsdf, sheen
from restir_engine.core.materials.params import SurfaceParams
from restir_engine.core.materials.sheen import SheenRows

N = 400_000
Z = 5.0
COLOUR = (0.9, 0.6, 0.3)


def _view(n, mu_o, rough):
    p = SurfaceParams.from_material(np.tile(np.float32([COLOUR]), (n, 1)), np.zeros(n, np.float32),
                                    np.full(n, 0.5, np.float32), np.zeros(n, np.float32))
    wo = np.zeros((3, n), np.float32)
    wo[0], wo[2] = np.sqrt(1 - mu_o * mu_o), mu_o
    v = bsdf.ViewTerms.of(p, wo)
    v.with_sheen(SheenRows(np.arange(n), np.full(n, rough, np.float32)), wo)
    return p, wo, v


def _uniform(g, n):
    z = g.random(n, dtype=np.float32)
    r = np.sqrt(np.maximum(0, 1 - z * z))
    ph = np.float32(2 * np.pi) * g.random(n, dtype=np.float32)
    return np.stack([r * np.cos(ph), r * np.sin(ph), z]).astype(np.float32)


@pytest.mark.parametrize("rough,mu_o", [(0.5, 0.9), (0.5, 0.2), (1.0, 0.5), (0.3, 0.15)])
def test_lobe_reflects_its_albedo_toward_the_view(rough, mu_o):
    """∫ f cos dωi = Color R(μo) (uniform estimate), and the sampler's own estimate agrees; with the light factor
    R(μi) left out the first check fails (power)."""
    g = np.random.default_rng(1)
    p, wo, v = _view(N, mu_o, rough)
    wi = _uniform(g, N)
    f, _pdf = bsdf.eval_view(v, wo, wi)
    x = f * wi[2] * np.float32(2 * np.pi)
    want = np.float32(COLOUR) * sheen.albedo(rough, mu_o)
    se = x.std(axis=1) / np.sqrt(N)
    assert (np.abs(x.mean(axis=1) - want) < Z * se + 1e-4 * want).all(), (x.mean(axis=1), want)
    u = g.random((3, N), dtype=np.float32)
    ws, fs, ps = bsdf.sample_bsdf(p, wo, u[0], u[1], u[2], view=v)
    ok = ps > 0
    est = np.where(ok, fs * np.maximum(ws[2], 0) / np.where(ok, ps, 1), 0)
    se = np.sqrt(est.var(axis=1) / N + x.var(axis=1) / N)
    assert (np.abs(est.mean(axis=1) - x.mean(axis=1)) < Z * se).all()
    flat = x / np.maximum(sheen.albedo(rough, np.maximum(wi[2], 0)), 1e-6)  # the light factor left out
    assert (np.abs(flat.mean(axis=1) - want) > Z * flat.std(axis=1) / np.sqrt(N)).any()


def test_lobe_is_reciprocal():
    g = np.random.default_rng(2)
    n = 5000
    a, b = _uniform(g, n), _uniform(g, n)
    _p, _wo, va = _view(n, 0.5, 0.6)
    fab = []
    for wo, wi in ((a, b), (b, a)):
        p = SurfaceParams.from_material(np.tile(np.float32([COLOUR]), (n, 1)), np.zeros(n, np.float32),
                                        np.full(n, 0.5, np.float32), np.zeros(n, np.float32))
        v = bsdf.ViewTerms.of(p, wo)
        v.with_sheen(SheenRows(np.arange(n), np.full(n, 0.6, np.float32)), wo)
        fab.append(bsdf.eval_view(v, wo, wi)[0])
    np.testing.assert_allclose(fab[0], fab[1], rtol=1e-4, atol=1e-7)


def test_mean_albedo_is_the_tables_cosine_weighted_mean():
    mu = np.linspace(0, 1, 4001, dtype=np.float32)
    for r in (0.2, 0.5, 0.8, 1.0):
        y = 2 * sheen.albedo(r, mu) * mu
        want = float(((y[1:] + y[:-1]) * 0.5 * np.diff(mu)).sum())
        assert abs(float(sheen.mean_albedo(r)) - want) < 2e-3 * want + 1e-5


@pytest.mark.parametrize("glossy", [False, True], ids=["diffuse block", "with a glossy surface"])
def test_restir_target_is_the_sheen_lobe(glossy):
    """ShadingTerms (with the extension rows a scene with sheen gets) evaluates p̂ = |luminance(f Le)| G with the
    sheen's R(μi): the same as the BSDF model (shading_value) at sheen surfaces, in a block of diffuse surfaces and
    in one with a glossy surface too; without the rows (the isotropic block) it differs there."""
    from restir_engine.core.lights import tiles as light_tiles
    from restir_engine.core.restir.di import shading_value
    from restir_engine.core.restir.target import ANISO_WIDTH, WIDTH, ShadingTerms
    from restir_engine.core.sampling import orthonormal_basis, to_local

    g = np.random.default_rng(5)
    n = 2000

    class Surf:
        pass
    s = Surf()
    ng = g.normal(size=(3, n))
    s.ng = (ng / np.linalg.norm(ng, axis=0)).astype(np.float32)
    s.ns = s.ng.copy()
    s.p = g.uniform(-1, 1, (3, n)).astype(np.float32)
    s.t, s.bt = orthonormal_basis(s.ns)
    wo = s.ng + 0.7 * g.normal(size=(3, n)).astype(np.float32)
    wo_l = to_local((wo / np.linalg.norm(wo, axis=0)).astype(np.float32), s.ns, s.t, s.bt)
    wo_l[2] = np.maximum(wo_l[2], 0.05)
    s.wo_l = (wo_l / np.linalg.norm(wo_l, axis=0)).astype(np.float32)
    metal = np.zeros(n, np.float32)
    if glossy:
        metal[::7] = 1.0
    s.params = SurfaceParams.from_material(g.uniform(0.1, 0.9, (n, 3)).astype(np.float32), metal,
                                           np.full(n, 0.4, np.float32), np.zeros(n, np.float32))
    rows = np.flatnonzero(metal == 0)[::2]
    s.view = bsdf.ViewTerms.of(s.params, s.wo_l)
    s.view.with_sheen(SheenRows(rows, g.uniform(0.2, 1.0, rows.size).astype(np.float32)), s.wo_l)
    pos = g.uniform(-2, 2, (3, n)).astype(np.float32)
    nl = g.normal(size=(3, n))
    pts = light_tiles.LightPoints(np.zeros(n, np.int32), np.zeros(n, np.float32), np.zeros(n, np.float32), pos,
                                  (nl / np.linalg.norm(nl, axis=0)).astype(np.float32), np.ones((3, n), np.float32),
                                  np.ones(n, np.float32), np.ones(n, bool), np.full(n, -1, np.int32))
    d = pos - s.p
    dist = np.linalg.norm(d, axis=0)
    wi = (d / dist).astype(np.float32)
    cos_l = -(wi * pts.normal).sum(axis=0)
    ref, _f, _g, _pdf = shading_value(s, wi, pts.le, dist.astype(np.float32), cos_l.astype(np.float32))
    live = np.intersect1d(rows, np.flatnonzero(ref > 0))
    assert live.size > 100
    for width in (ANISO_WIDTH, WIDTH):
        terms = ShadingTerms.of_surfaces(s, np.empty((width, n), np.float32))
        assert terms.glossy == glossy and terms.sheeny == (width == ANISO_WIDTH)
        p_hat, _ = terms.evaluate(light_tiles.PackedPoints.of(pts.packed()), want_pdf=False)
        if width == ANISO_WIDTH:
            np.testing.assert_allclose(p_hat[live], ref[live], rtol=2e-3, atol=1e-6 * ref.max())
            again, _ = ShadingTerms(terms.packed).take(live).evaluate(
                light_tiles.PackedPoints.of(pts.packed()[:, live]), want_pdf=False)
            np.testing.assert_allclose(again, ref[live], rtol=2e-3, atol=1e-6 * ref.max())
        else:
            assert (p_hat[live] >= ref[live] * (1 - 2e-3)).all()  # the Lambert bound
            assert np.abs(p_hat[live] / ref[live] - 1).max() > 0.2
