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
