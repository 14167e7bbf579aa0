"""BSDF checks against numerical integration (tolerances are 5 standard errors)."""
import numpy as np
import pytest

from restir_engine.core import bsdf
from restir_engine.core.bsdf import SurfaceParams

N = 400_000


# the core keeps vectors as (3, n) rows; these tests read (n, 3) rows
def eval_bsdf(p, wo, wi):
    f, pdf = bsdf.eval_bsdf(p, np.ascontiguousarray(wo.T), np.ascontiguousarray(wi.T))
    return f.T, pdf


def sample_bsdf(p, wo, u_lobe, u1, u2):
    wi, f, pdf = bsdf.sample_bsdf(p, np.ascontiguousarray(wo.T), u_lobe, u1, u2)
    return wi.T, f.T, pdf


def params(n, base, metallic, roughness, f0):
    return SurfaceParams.from_material(np.tile(np.array(base, np.float32), (n, 1)), np.full(n, metallic, np.float32),
                                       np.full(n, roughness, np.float32), np.full(n, f0, np.float32))


def wo_at(theta, n):
    return np.tile(np.array([np.sin(theta), 0, np.cos(theta)], np.float32), (n, 1))


def uniform_hemisphere(g, n):
    u1, u2 = g.random(n), g.random(n)
    z = u1
    r = np.sqrt(np.maximum(0, 1 - z * z))
    return np.stack([r * np.cos(2 * np.pi * u2), r * np.sin(2 * np.pi * u2), z], axis=1).astype(np.float32)


CASES = [((0.8, 0.8, 0.8), 0.0, 0.5, 0.0), ((0.8, 0.5, 0.2), 0.0, 0.3, 0.04), ((0.9, 0.9, 0.9), 1.0, 0.2, 0.04),
         ((0.5, 0.5, 0.5), 0.5, 0.6, 0.04)]


@pytest.mark.parametrize("base,metallic,roughness,f0", CASES)
@pytest.mark.parametrize("theta", [0.2, 1.0])
def test_sampling_estimate_matches_quadrature(base, metallic, roughness, f0, theta):
    """E[f cos / pdf] under the sampler equals ∫ f cos dω estimated by uniform hemisphere sampling."""
    g = np.random.default_rng(1)
    p = params(N, base, metallic, roughness, f0)
    wo = wo_at(theta, N)
    wi, f, pdf = sample_bsdf(p, wo, g.random(N, dtype=np.float32), g.random(N, dtype=np.float32),
                             g.random(N, dtype=np.float32))
    est = np.where(pdf[:, None] > 0, f * wi[:, 2:3] / np.maximum(pdf, 1e-30)[:, None], 0.0)
    wu = uniform_hemisphere(g, N)
    fu, _ = eval_bsdf(p, wo, wu)
    quad = fu * wu[:, 2:3] * 2 * np.pi
    for c in range(3):
        se = np.sqrt(est[:, c].var() / N + quad[:, c].var() / N)
        assert abs(est[:, c].mean() - quad[:, c].mean()) < 5 * se + 1e-6, (c, est[:, c].mean(), quad[:, c].mean())
    # energy: a white surface reflects no more than it receives
    assert quad.mean(axis=0).max() < 1.0 + 5 * np.sqrt(quad.var(axis=0).max() / N)


@pytest.mark.parametrize("base,metallic,roughness,f0", CASES)
def test_pdf_integrates_to_the_sampled_fraction(base, metallic, roughness, f0):
    """∫ pdf dω over the hemisphere equals the fraction of samples the sampler keeps."""
    g = np.random.default_rng(2)
    p = params(N, base, metallic, roughness, f0)
    wo = wo_at(0.7, N)
    wu = uniform_hemisphere(g, N)
    _, pdf = eval_bsdf(p, wo, wu)
    integral = pdf * 2 * np.pi
    _, _, spdf = sample_bsdf(p, wo, g.random(N, dtype=np.float32), g.random(N, dtype=np.float32),
                             g.random(N, dtype=np.float32))
    kept = (spdf > 0).mean()
    se = np.sqrt(integral.var() / N + kept * (1 - kept) / N)
    assert abs(integral.mean() - kept) < 5 * se


def test_lambert_is_exact():
    p = params(4, (0.5, 0.5, 0.5), 0.0, 0.5, 0.0)
    wo = wo_at(0.3, 4)
    wi = np.array([[0, 0, 1], [0.6, 0, 0.8], [0, 0.6, 0.8], [0, 0, -1]], np.float32)
    f, pdf = eval_bsdf(p, wo, wi)
    assert np.allclose(f[:3], 0.5 / np.pi) and np.allclose(f[3], 0)
    assert np.allclose(pdf[:3], wi[:3, 2] / np.pi) and pdf[3] == 0


@pytest.mark.parametrize("roughness", [0.3, 0.6, 1.0])
@pytest.mark.parametrize("theta", [0.0, 0.8, 1.3])
def test_white_metal_reflects_all_energy(roughness, theta):
    """Energy compensation: a white (f0 = 1) GGX metal has albedo 1 at every roughness and angle
    (single scattering alone loses up to ~40% at roughness 1)."""
    g = np.random.default_rng(9)
    p = params(N, (1.0, 1.0, 1.0), 1.0, roughness, 0.04)
    wo = wo_at(theta, N)
    wi, f, pdf = sample_bsdf(p, wo, g.random(N, dtype=np.float32), g.random(N, dtype=np.float32),
                             g.random(N, dtype=np.float32))
    est = np.where(pdf > 0, f[:, 0] * wi[:, 2] / np.maximum(pdf, 1e-30), 0.0)
    se = est.std() / np.sqrt(N)
    # 1% allowance for the 32x32 albedo table's interpolation, plus 5 standard errors
    assert abs(est.mean() - 1.0) < 0.01 + 5 * se, (est.mean(), se)


def test_stored_ggx_albedo_table_is_the_computed_one():
    """core/data/ggx_albedo.npy (read at start-up instead of a second of computation) is what
    scripts/make_ggx_table.py computes."""
    from restir_engine.core.bsdf import TABLE_FILE, compute_ggx_albedo_table
    np.testing.assert_allclose(np.load(TABLE_FILE), compute_ggx_albedo_table(), rtol=0, atol=1e-7)
