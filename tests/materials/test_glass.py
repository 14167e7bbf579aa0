"""Glass sampling (core/materials/glass.py) against closed forms: Fresnel, Snell's law, total internal reflection; rough glass
conserves energy (Cycles' multiscatter compensation) and tends to the smooth interface."""
import numpy as np
import pytest

from restir_engine.core.materials.glass import sample_glass


def _incident(theta_deg, k):
    t = np.radians(theta_deg)
    wo = np.tile(np.array([[np.sin(t)], [0.0], [np.cos(t)]], np.float32), (1, k))
    n = np.tile(np.array([[0.0], [0.0], [1.0]], np.float32), (1, k))
    return wo, n


def test_normal_incidence_reflects_f0_and_refracts_straight_through():
    k = 200000
    wo, n = _incident(0.0, k)
    u = np.random.default_rng(1).random(k, dtype=np.float32)
    white = np.ones((3, k), np.float32)
    wi, w, valid = sample_glass(wo, n, n, np.ones(k, bool), np.full(k, 1.5, np.float32), white, 0.5 * white, u)
    reflected = wi[2] > 0
    f0 = ((1.5 - 1) / (1.5 + 1)) ** 2
    se = np.sqrt(f0 * (1 - f0) / k)
    assert abs(reflected.mean() - f0) < 5 * se and valid.all()
    assert np.allclose(wi[:, ~reflected], [[0], [0], [-1]], atol=1e-6)
    assert np.allclose(w[:, reflected], 1.0) and np.allclose(w[:, ~reflected], 0.5)


def test_snell_fresnel_and_total_internal_reflection():
    k = 4000
    for theta, front in ((40.0, True), (30.0, False), (45.0, False)):
        wo, n = _incident(theta, k)
        u = np.linspace(0, 1, k, endpoint=False, dtype=np.float32)
        white = np.ones((3, k), np.float32)
        wi, _w, valid = sample_glass(wo, n, n, np.full(k, front), np.full(k, 1.5, np.float32), white, white, u)
        eta = 1.5 if front else 1 / 1.5
        ci = np.cos(np.radians(theta))
        s2 = (1 - ci * ci) / eta ** 2
        refracted = wi[2] < 0
        if s2 >= 1:  # beyond the critical angle (41.8° from inside): everything reflects
            assert not refracted.any() and valid.all()
            continue
        ct = np.sqrt(1 - s2)
        rs = (ci - eta * ct) / (ci + eta * ct)
        rp = (eta * ci - ct) / (eta * ci + ct)
        fresnel = 0.5 * (rs * rs + rp * rp)
        assert abs((~refracted).mean() - fresnel) <= 1.0 / k + 1e-6  # u is a uniform grid: exact up to one step
        t = wi[:, refracted]
        assert np.allclose(np.sqrt(t[0] ** 2 + t[1] ** 2), np.sqrt(s2), atol=1e-5)  # Snell: sin θt = sin θi / η
        assert np.allclose(-t[2], ct, atol=1e-5) and (t[0] < 0).all()  # continues forward, bent toward -n


def test_glass_and_principled_transmission_are_exported(addon):
    import pytest

    from bpy_scenes import glass_material
    from restir_engine.export.materials import MaterialRegistry
    warnings = []
    reg = MaterialRegistry(warnings)
    glass = reg.rows[reg.material_index(glass_material("G", "GLASS", 1.33, (0.9, 0.8, 0.7)))]
    assert glass["transmission"] == 1.0 and glass["glass_ior"] == pytest.approx(1.33)
    assert glass["glass_reflect"] == glass["glass_refract"] == pytest.approx((0.9, 0.8, 0.7))
    mat = glass_material("P", "PRINCIPLED", 1.5, (0.25, 1.0, 0.64), transmission=0.5)
    mat.node_tree.nodes["Principled BSDF"].inputs["Metallic"].default_value = 0.2
    row = reg.rows[reg.material_index(mat)]
    assert row["transmission"] == pytest.approx(0.4)               # (1 - 0.2) x 0.5
    assert row["metallic"] == pytest.approx(0.2 / 0.6)             # the rest: 0.2 metal + 0.4 dielectric
    assert row["glass_refract"] == pytest.approx((0.5, 1.0, 0.8))  # sqrt(Base Color)
    assert not warnings
    rough = glass_material("R", "GLASS")
    rough.node_tree.nodes["Glass BSDF"].inputs["Roughness"].default_value = 0.3
    row = reg.rows[reg.material_index(rough)]
    assert row["glass_alpha"] == pytest.approx(0.09) and row["glass_multiscatter"] == 1.0 and not warnings


def _rough(theta, alpha, ior, front, k, seed=0, multiscatter=True):
    wo, n = _incident(theta, k)
    u = np.random.default_rng(seed).random((3, k), dtype=np.float32)
    white = np.ones((3, k), np.float32)
    return sample_glass(wo, n, n, np.full(k, front), np.full(k, ior, np.float32), white, white, u[0],
                        np.full(k, alpha, np.float32), u[1], u[2], np.full(k, multiscatter))


def test_rough_glass_conserves_energy():
    """Multiscatter GGX glass (Cycles' default): the single-scattering interface scaled by 1/E reflects and transmits
    all the light on average, entered from either side, at any roughness and angle (mean weight 1 within 5 SE and
    1 % for the tables' interpolation); single-scattering GGX loses what the table says it does."""
    from restir_engine.core.materials.microfacet_tables import glass_albedo_at
    k = 400000
    for theta, alpha, ior, front in ((0.0, 0.25, 1.45, True), (60.0, 0.5, 1.5, True), (30.0, 0.8, 1.5, False),
                                     (75.0, 0.1, 2.0, True), (50.0, 0.3, 1.33, False)):
        wi, w, valid = _rough(theta, alpha, ior, front, k)
        x = np.where(valid, w[0], 0.0)
        se = x.std() / np.sqrt(k)
        assert abs(x.mean() - 1.0) < 5 * se + 0.01, (theta, alpha, ior, front, x.mean(), se)
        wi, w, valid = _rough(theta, alpha, ior, front, k, multiscatter=False)
        x = np.where(valid, w[0], 0.0)
        eta = ior if front else 1 / ior
        e = float(glass_albedo_at(np.float32(alpha), np.float32(np.cos(np.radians(theta))), np.float32(eta)))
        assert e < 0.999 and abs(x.mean() - e) < 5 * x.std() / np.sqrt(k) + 0.01 * e, (theta, alpha, x.mean(), e)


def test_rough_glass_tends_to_the_smooth_interface():
    """At α = 0.01 the reflected share is the smooth Fresnel and the refracted rays lie within a few degrees of
    Snell's direction; at α below Cycles' delta threshold the sample is exactly the smooth one."""
    k = 200000
    wi, _w, valid = _rough(40.0, 0.01, 1.5, True, k)
    wo, n = _incident(40.0, k)
    ws, _ws, _v = sample_glass(wo, n, n, np.ones(k, bool), np.full(k, 1.5, np.float32), np.ones((3, k), np.float32),
                               np.ones((3, k), np.float32), np.random.default_rng(0).random((3, k), dtype=np.float32)[0])
    assert abs((wi[2] > 0).mean() - (ws[2] > 0).mean()) < 0.01 and valid.mean() > 0.99
    t = ws[:, ws[2] < 0][:, 0]
    assert np.degrees(np.arccos(np.clip(wi[:, wi[2] < 0].T @ t, -1, 1))).mean() < 3.0
    wi0, _w0, _v0 = _rough(40.0, 1e-4, 1.5, True, 1000)
    wo, n = _incident(40.0, 1000)
    u = np.random.default_rng(0).random((3, 1000), dtype=np.float32)
    ws0, _x, _y = sample_glass(wo, n, n, np.ones(1000, bool), np.full(1000, 1.5, np.float32),
                               np.ones((3, 1000), np.float32), np.ones((3, 1000), np.float32), u[0])
    assert np.array_equal(wi0, ws0)


@pytest.mark.parametrize("mu,alpha,ior,front,ms,fresnel,beck", [
    (0.7, 0.3, 1.5, True, True, True, False), (0.3, 0.5, 1.5, False, True, True, False),
    (0.9, 0.2, 1.45, True, False, False, False), (0.6, 0.4, 1.5, True, False, True, True)])
def test_rough_glass_evaluation_is_its_sampler(mu, alpha, ior, front, ms, fresnel, beck):
    """glass.eval_glass (next-event estimation at rough glass) is the lobe sample_glass draws from: at every sample
    f |cos θi| / pdf is the sample's weight; over the sphere (uniform Monte Carlo) the pdf integrates to the share of
    valid samples and f |cos θi| to the samples' mean weight, within 5 standard errors."""
    from restir_engine.core.materials.glass import eval_glass
    n_rays = 200_000
    g = np.random.default_rng(11)
    wo = np.zeros((3, n_rays), np.float32)
    wo[0], wo[2] = np.sqrt(1 - mu * mu), mu
    nrm = np.zeros((3, n_rays), np.float32)
    nrm[2] = 1
    ones = np.ones((3, n_rays), np.float32)
    per = dict(front=np.full(n_rays, front), ior=np.full(n_rays, ior, np.float32))
    a = np.full(n_rays, alpha, np.float32)
    flags = (np.full(n_rays, ms), np.full(n_rays, fresnel), np.full(n_rays, beck))
    u = g.random((3, n_rays), dtype=np.float32)
    wi, w, valid = sample_glass(wo, nrm, nrm, per["front"], per["ior"], ones, ones, u[0], a, u[1], u[2], *flags)
    f, pdf = eval_glass(wo, wi, nrm, nrm, per["front"], per["ior"], ones, ones, a, *flags)
    v = valid & (pdf > 0)
    assert v.mean() > 0.99 * valid.mean()
    np.testing.assert_allclose(f[0, v] * np.abs(wi[2, v]) / pdf[v], w[0, v], rtol=2e-3)
    z = g.random(n_rays) * 2 - 1
    ph = g.random(n_rays) * 2 * np.pi
    r = np.sqrt(1 - z * z)
    wu = np.stack([r * np.cos(ph), r * np.sin(ph), z]).astype(np.float32)
    fu, pu = eval_glass(wo, wu, nrm, nrm, per["front"], per["ior"], ones, ones, a, *flags)
    x = 4 * np.pi * pu
    assert abs(x.mean() - valid.mean()) < 5 * x.std() / np.sqrt(n_rays)
    y = 4 * np.pi * fu[0] * np.abs(wu[2])
    sampled = np.where(valid, w[0], 0.0)
    se = np.sqrt(y.var() / n_rays + sampled.var() / n_rays)
    assert abs(y.mean() - sampled.mean()) < 5 * se
