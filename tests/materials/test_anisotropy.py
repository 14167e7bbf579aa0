"""Anisotropic GGX (core/materials/anisotropy.py): the lobe against its own definitions by Monte Carlo integration
(tolerances 5 standard errors), the sampler against the pdf, and the ReSTIR DI target's BSDF pdf against the BSDF's.
Cycles' images of the same lobes: tests/cycles/test_materials_cycles.test_anisotropic_ggx_matches_cycles."""
import numpy as np
import pytest

from restir_engine.core.lights import tiles as light_tiles
from restir_engine.core.materials import anisotropy, bsdf
from restir_engine.core.materials.anisotropy import AnisoFrame, glossy_aspect, principled_aspect
from restir_engine.core.materials.params import SurfaceParams
from restir_engine.core.restir.di import shading_value
from restir_engine.core.restir.target import ANISO_WIDTH, ShadingTerms
from restir_engine.core.sampling import orthonormal_basis, to_local

N = 400_000
Z = 5.0


def _view(n, theta_o, phi_o, metallic=1.0, rough=0.4):
    p = SurfaceParams.from_material(np.tile(np.float32([[0.9, 0.6, 0.3]]), (n, 1)), np.full(n, metallic, np.float32),
                                    np.full(n, rough, np.float32), np.full(n, 0.04, np.float32))
    wo = np.zeros((3, n), np.float32)
    wo[0], wo[1], wo[2] = np.sin(theta_o) * np.cos(phi_o), np.sin(theta_o) * np.sin(phi_o), np.cos(theta_o)
    return p, wo


def _frame(p, n, aspect, rot=0.0, normal=(0.0, 0.0, 1.0)):
    t = np.zeros((3, n), np.float32)
    t[0], t[1] = np.cos(rot), np.sin(rot)
    nl = np.tile(np.float32(normal)[:, None] / np.linalg.norm(normal), (1, n))
    return AnisoFrame.of(np.arange(n), p.alpha, np.full(n, aspect, np.float32), t, nl)


def _aniso_view(p, wo, frame):
    v = bsdf.ViewTerms.of(p, wo)
    v.with_anisotropy(frame, wo)
    return v


def _uniform(g, n):
    z = g.random(n, dtype=np.float32)
    r = np.sqrt(np.maximum(0, 1 - z * z))
    ph = np.float32(2 * np.pi) * g.random(n, dtype=np.float32)
    return np.stack([r * np.cos(ph), r * np.sin(ph), z]).astype(np.float32)


def test_aspects_are_cycles_mappings():
    """Principled: √(1 - 0.9 a), isotropic at a ≤ 0; Glossy: 1/(1 - a) and 1 + a, clamped to ±0.99; √(αx αy) = α."""
    np.testing.assert_allclose(principled_aspect([0.0, 0.5, 1.0, -0.5, 2.0]),
                               [1.0, np.sqrt(0.55), np.sqrt(0.1), 1.0, np.sqrt(0.1)], rtol=1e-6)
    np.testing.assert_allclose(glossy_aspect([0.0, 0.8, -0.6, 1.0, -1.0]), [1.0, 5.0, 0.4, 100.0, 0.01], rtol=1e-5)
    f = AnisoFrame.of(np.arange(1), np.float32([0.09]), np.float32([0.3]), np.float32([[1], [0], [0]]),
                      np.float32([[0], [0], [1]]))
    assert f.ax[0] == pytest.approx(0.3) and f.ay[0] == pytest.approx(0.027)
    assert np.sqrt(f.ax * f.ay)[0] == pytest.approx(0.09)


def test_aspect_one_is_the_isotropic_lobe():
    """A frame of aspect 1 (any tangent, about the shading normal) evaluates the isotropic f (its pdf is the
    visible-normal sampler's, not the isotropic lobe's D cos θh sampler's)."""
    g = np.random.default_rng(1)
    n = 20000
    p, wo = _view(n, 0.7, 0.4, metallic=0.5)
    wi = _uniform(g, n)
    f0, _pdf0 = bsdf.eval_view(bsdf.ViewTerms.of(p, wo), wo, wi)
    f1, _pdf1 = bsdf.eval_view(_aniso_view(p, wo, _frame(p, n, 1.0, rot=1.3)), wo, wi)
    np.testing.assert_allclose(f1, f0, rtol=2e-4, atol=1e-7)


def test_distribution_is_normalized():
    """∫ D(h) cos θh dω = 1 (uniform hemisphere estimate) for stretched and squeezed lobes."""
    g = np.random.default_rng(2)
    for ax, ay in ((0.5, 0.05), (0.1, 0.4), (0.3, 0.3)):
        h = _uniform(g, N)
        x = anisotropy.ggx_d(np.float32(ax), np.float32(ay), h[0], h[1], h[2]) * h[2] * np.float32(2 * np.pi)
        assert abs(x.mean() - 1.0) < Z * x.std() / np.sqrt(N) + 1e-3, (ax, ay, x.mean())


@pytest.mark.parametrize("aspect,rot,metallic", [(0.3, 0.0, 1.0), (2.5, 0.7, 1.0), (0.5, 2.0, 0.0)])
def test_sampler_draws_the_pdf(aspect, rot, metallic):
    """The BSDF sampler's directions have the density eval_view reports: the mass of the pdf over the hemisphere
    (a uniform estimate) is the share of samples above it, and ∫ f cos dω estimated with the sampler's own
    samples equals the uniform estimate. Weighed by another pdf (the isotropic lobe's) the same samples fail the
    second check."""
    g = np.random.default_rng(3)
    p, wo = _view(N, 0.8, 0.3, metallic=metallic)
    frame = _frame(p, N, aspect, rot)
    v = _aniso_view(p, wo, frame)
    u = g.random((3, N), dtype=np.float32)
    wi, f, pdf = bsdf.sample_bsdf(p, wo, u[0], u[1], u[2], view=v)
    live = pdf > 0
    est = np.where(live, f * np.maximum(wi[2], 0) / np.where(live, pdf, 1), 0)
    wu = _uniform(g, N)
    fu, pu = bsdf.eval_view(v, wo, wu)
    ref = fu * wu[2] * np.float32(2 * np.pi)
    mass = pu * np.float32(2 * np.pi)
    se = np.sqrt(mass.var() / N + live.mean() * (1 - live.mean()) / N)
    assert abs(mass.mean() - live.mean()) < Z * se
    se = np.sqrt(est.var(axis=1) / N + ref.var(axis=1) / N)
    assert (np.abs(est.mean(axis=1) - ref.mean(axis=1)) < Z * se).all(), (est.mean(axis=1), ref.mean(axis=1))
    # power: the same samples weighed by the isotropic lobe's pdf (a sampler and pdf that disagree) fail
    _f, pdf_iso = bsdf.eval_view(bsdf.ViewTerms.of(p, wo), wo, wi)
    ok = pdf_iso > 0
    wrong = np.where(ok, f * np.maximum(wi[2], 0) / np.where(ok, pdf_iso, 1), 0)
    se = np.sqrt(wrong.var(axis=1) / N + ref.var(axis=1) / N)
    assert (np.abs(wrong.mean(axis=1) - ref.mean(axis=1)) > Z * se).any()


def test_stretch_follows_the_tangent():
    """At normal incidence a lobe of aspect < 1 reflects more toward directions along its tangent than across it
    (αx = α/aspect > αy), and the tangent turned by 90° swaps the two."""
    n = 2
    p, wo = _view(n, 0.0, 0.0, rough=0.3)
    s = np.float32(np.sin(0.5))
    wi = np.float32([[s, 0], [0, s], [np.cos(0.5), np.cos(0.5)]])
    f, _ = bsdf.eval_view(_aniso_view(p, wo, _frame(p, n, 0.4)), wo, wi)
    assert f[0, 0] > 3 * f[0, 1]
    f, _ = bsdf.eval_view(_aniso_view(p, wo, _frame(p, n, 0.4, rot=np.pi / 2)), wo, wi)
    assert f[0, 1] > 3 * f[0, 0]


class _Surf:
    """Random glossy surfaces with an anisotropic frame about a tilted lobe normal (as Surface gives them)."""

    def __init__(self, n, g):
        p = g.uniform(-1, 1, (n, 3))
        ng = g.normal(size=(n, 3))
        ng /= np.linalg.norm(ng, axis=1)[:, None]
        self.p, self.ng = (np.ascontiguousarray(a.T, dtype=np.float32) for a in (p, ng))
        self.ns = self.ng.copy()
        self.t, self.bt = orthonormal_basis(self.ns)
        wo = ng + 0.8 * g.normal(size=(n, 3))
        wo /= np.linalg.norm(wo, axis=1)[:, None]
        wo_l = to_local(np.ascontiguousarray(wo.T, dtype=np.float32), self.ns, self.t, self.bt)
        wo_l[2] = np.maximum(wo_l[2], 0.05)  # (at grazing views the world-space round trip costs float32 digits)
        self.wo_l = (wo_l / np.linalg.norm(wo_l, axis=0)).astype(np.float32)
        self.params = SurfaceParams.from_material(g.uniform(0.05, 0.95, (n, 3)).astype(np.float32),
                                                  (g.random(n) < 0.5).astype(np.float32),
                                                  g.uniform(0.1, 0.8, n).astype(np.float32), np.full(n, 0.04))
        rows = np.flatnonzero(g.random(n) < 0.7)
        tl = g.normal(size=(3, rows.size)).astype(np.float32)
        nl = np.zeros((3, rows.size), np.float32)
        nl[2] = 1.0
        self.view = bsdf.ViewTerms.of(self.params, self.wo_l)
        self.view.with_anisotropy(AnisoFrame.of(rows, self.params.alpha[rows], g.uniform(0.2, 3.0, rows.size)
                                                .astype(np.float32), tl, nl), self.wo_l)


@pytest.mark.parametrize("rows", [32, ANISO_WIDTH], ids=["isotropic target", "anisotropic target"])
def test_target_pdf_is_the_anisotropic_bsdf_pdf(rows):
    """ShadingTerms.evaluate's BSDF pdf (what weighs the BSDF candidates against the light candidates in the
    initial resampling) equals eval_view's at anisotropic surfaces, for one point per surface and for a block of
    candidates (broadcast), and after take(); p̂ stays positive wherever the BSDF reflects, and with the anisotropic
    rows (a scene with anisotropic materials) it is the BSDF's own luminance, also read back from the frame's
    block alone (as spatial and temporal reuse read it)."""
    g = np.random.default_rng(4)
    n = 3000
    surf = _Surf(n, g)
    block = np.empty((rows, n), np.float32)
    terms = ShadingTerms.of_surfaces(surf, block)
    assert terms.aniso is not None and terms.stretched == (rows == ANISO_WIDTH)
    pos = g.uniform(-2, 2, (3, n)).astype(np.float32)
    nl = g.normal(size=(3, n))
    pts = light_tiles.LightPoints(np.zeros(n, np.int32), np.zeros(n, np.float32), np.zeros(n, np.float32), pos,
                                  (nl / np.linalg.norm(nl, axis=0)).astype(np.float32), np.ones((3, n), np.float32),
                                  np.ones(n, np.float32), np.ones(n, bool), np.full(n, -1, np.int32))
    p_hat, pdf = terms.evaluate(light_tiles.PackedPoints.of(pts.packed()))
    d = pos - surf.p
    dist = np.linalg.norm(d, axis=0)
    wi = (d / dist).astype(np.float32)
    cos_l = -(wi * pts.normal).sum(axis=0)
    ref_p, _f, _g, ref_pdf = shading_value(surf, wi, pts.le, dist.astype(np.float32), cos_l.astype(np.float32))
    live = ref_p > 0
    assert live.mean() > 0.2
    np.testing.assert_allclose(pdf[live], ref_pdf[live], rtol=2e-3, atol=1e-6 * ref_pdf.max())
    assert (p_hat[live] > 0).all()
    if rows == ANISO_WIDTH:
        np.testing.assert_allclose(p_hat, ref_p, rtol=2e-3, atol=1e-6 * ref_p.max())
        again, _ = ShadingTerms(block).evaluate(light_tiles.PackedPoints.of(pts.packed()), want_pdf=False)
        np.testing.assert_allclose(again, ref_p, rtol=2e-3, atol=1e-6 * ref_p.max())
    else:
        assert np.abs(p_hat[live] / ref_p[live] - 1).max() > 0.1  # the isotropic stand-in differs
    # a block of 3 candidates per surface, and the terms of some surfaces taken
    block = light_tiles.PackedPoints.of(np.repeat(pts.packed()[:, None, :], 3, axis=1))
    _p3, pdf3 = terms.evaluate(block)
    np.testing.assert_allclose(pdf3[1][live], ref_pdf[live], rtol=2e-3, atol=1e-6 * ref_pdf.max())
    idx = np.flatnonzero(live)[::3]
    sub = terms.take(idx)
    _ps, pdfs = sub.evaluate(light_tiles.PackedPoints.of(pts.packed()[:, idx]))
    np.testing.assert_allclose(pdfs, ref_pdf[idx], rtol=2e-3, atol=1e-6 * ref_pdf.max())
