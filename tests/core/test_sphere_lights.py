"""Point/spot lamps as true spheres: cone sampling, analytic ray hits, and the estimators that use them against
closed forms (no bpy scene; the proxy triangles are the exporter's)."""
import numpy as np
import pytest
from scenes_core import quad, top_down_camera, tris

from restir_engine.core.integrators import trace_context
from restir_engine.core.renderer import RenderSettings, render_frame
from restir_engine.core.scene import Lamps, MaterialTable, Scene
from restir_engine.export.lights import _SPHERE
from stats import standard_error

ALBEDO, LE, HEIGHT, RADIUS = 0.5, 3.0, 1.5, 0.5


def floor_under_sphere(radius=RADIUS, height=HEIGHT, le=LE, width=32) -> Scene:
    """A diffuse floor (z = 0) under a point lamp: a sphere of ``radius`` and radiance ``le`` centred at height
    ``height`` above the origin."""
    mats = MaterialTable.build([{"base_color": (ALBEDO,) * 3, "f0": 0.0},
                                {"base_color": (0, 0, 0), "f0": 0.0, "emission": (le,) * 3,
                                 "two_sided_emission": False}])
    floor = tris(quad((0, 0, 0), (50, 0, 0), (0, 50, 0)), 0)
    center = np.array([0.0, 0.0, height], np.float32)
    proxy = (_SPHERE * radius + center).astype(np.float32)
    n = len(proxy)
    lamps = Lamps.empty()
    lamps.tris = tris(proxy, 1)
    lamps.spot_center = np.repeat(center[None], n, axis=0)
    lamps.spot_axis = np.zeros((n, 3), np.float32)
    lamps.spot_cos = np.full(n, -2.0, np.float32)
    lamps.spot_smooth = np.zeros(n, np.float32)
    lamps.camera_visible = np.ones(n, bool)
    lamps.sphere_radius = np.full(n, radius, np.float32)
    lamps.sphere_first = np.zeros(n, np.int32)
    return Scene(floor, mats, lamps, top_down_camera(width, width, height_above=0.5 * (height - radius)))


def expected_floor_radiance(x=0.0, y=0.0, radius=RADIUS, height=HEIGHT, le=LE):
    """Radiance of the floor at (x, y): albedo/π · E with E = π Le sin²α cos β for a sphere wholly above the
    horizon (sin α = r / D, D the distance to its centre, cos β = h / D)."""
    d2 = x * x + y * y + height * height
    return ALBEDO * le * radius * radius / d2 * height / np.sqrt(d2)


def test_one_light_entry_per_sphere_with_the_true_area():
    ctx = trace_context.build_context(floor_under_sphere(), 0)
    lights = ctx.lights
    assert lights.n_tri == 1 and lights.any_sphere
    assert np.isclose(lights.tri_area[0], 4 * np.pi * RADIUS ** 2, rtol=1e-6)
    assert (lights.lamp_to_light == 0).all()  # every proxy triangle leads to the sphere


def test_ray_sphere_hits_geometry():
    lights = trace_context.build_context(floor_under_sphere(), 0).lights
    o = np.array([[0, 0, 0], [0.49, 0, 0], [0.51, 0, 0], [0, 0, HEIGHT]], np.float32).T  # last: from the centre
    d = np.tile(np.array([[0, 0, 1]], np.float32).T, (1, 4))
    t, b1, b2, cos_l = lights.sphere_hits(np.zeros(4, np.int64), o, d, np.full(4, np.inf, np.float32))
    assert np.isclose(t[0], HEIGHT - RADIUS, rtol=1e-6) and np.isclose(cos_l[0], 1.0, atol=1e-6)
    assert np.isfinite(t[1]) and not np.isfinite(t[2])  # grazes inside / passes outside the radius
    assert np.isclose(t[3], RADIUS, rtol=1e-6) and cos_l[3] < -0.999  # from inside: the far wall, back face
    assert np.isclose(b1[0], 1.0, atol=1e-6)  # the south pole in sphere coordinates (z = 1 - 2 b1 = -1)
    t_short, *_ = lights.sphere_hits(np.zeros(1, np.int64), o[:, :1], d[:, :1], np.array([0.5], np.float32))
    assert not np.isfinite(t_short[0])  # beyond tmax


def test_hit_fraction_of_uniform_directions_is_the_cone_solid_angle():
    """Analytic hits and the cone pdf describe the same sphere: the fraction of uniform directions that hit
    it is Ω / 4π with Ω = 2π (1 - cos θmax) = 1 / pdf (one light, selection probability 1)."""
    lights = trace_context.build_context(floor_under_sphere(), 0).lights
    rng = np.random.default_rng(1)
    n = 400_000
    z = rng.uniform(-1, 1, n)
    phi = rng.uniform(0, 2 * np.pi, n)
    rxy = np.sqrt(1 - z * z)
    d = np.stack([rxy * np.cos(phi), rxy * np.sin(phi), z]).astype(np.float32)
    o = np.zeros((3, n), np.float32)
    t, _b1, _b2, cos_l = lights.sphere_hits(np.zeros(n, np.int64), o, d, np.full(n, np.inf, np.float32))
    hit = np.isfinite(t)
    frac = hit.mean()
    pdf = lights.pdf_solid_angle(np.zeros(1, np.int64), o[:, :1], np.ones(1, np.float32), np.ones(1, np.float32))[0]
    expected = 1.0 / (4 * np.pi * pdf)
    se = np.sqrt(expected * (1 - expected) / n)
    assert abs(frac - expected) < 4 * se, (frac, expected, se)
    assert (cos_l[hit] > 0).all()  # from outside a ray first meets the front


def test_cone_sampling_irradiance_is_exact_up_to_the_cosine_spread():
    """Next-event samples of a sphere above a receiver: E = Le cos θ / p has the mean π Le (r/h)², and as every
    sample lies in the cone, cos θ in [cos θmax, 1] bounds its relative spread by 1 - cos θmax."""
    lights = trace_context.build_context(floor_under_sphere(), 0).lights
    n = 20_000
    p = np.zeros((3, n), np.float32)
    ls = lights.sample(p, np.random.default_rng(2).random((4, n), dtype=np.float32))
    assert (ls.pdf > 0).all()
    e = ls.le[0] * ls.wi[2] / ls.pdf
    expected = np.pi * LE * (RADIUS / HEIGHT) ** 2
    cos_max = np.sqrt(1 - (RADIUS / HEIGHT) ** 2)
    assert e.max() <= expected / (1 + cos_max) * 2 * (1 + 1e-4)  # E ∝ cos θ: at most 2 / (1 + cos θmax) x the mean
    assert e.min() >= expected * cos_max * 2 / (1 + cos_max) * (1 - 1e-4)
    se = e.std(ddof=1) / np.sqrt(n)
    assert abs(e.mean() - expected) < 4 * se + 1e-6 * expected, (e.mean(), expected, se)
    # the sampled points lie on the sphere, on its near side
    q = ls.pos - np.array([[0], [0], [HEIGHT]], np.float32)
    assert np.allclose(np.sqrt((q * q).sum(0)), RADIUS, rtol=1e-4)
    assert (q[2] < 0).all()


@pytest.mark.parametrize("method", ["PATH", "RIS"])
def test_floor_under_sphere_light_matches_closed_form(method):
    """NEE (cone) + BSDF hits on the analytic sphere (MIS), or RIS over area-sampled sphere points with BSDF
    candidates: the floor under the centre has radiance albedo · Le · (r/h)²."""
    width = 64
    scene = floor_under_sphere(width=width)
    settings = dict(samples=16, max_bounces=0)
    if method == "RIS":  # area-sampled sphere points: about 0.7 relative deviation per sample at 8 candidates
        settings.update(integrator="RESTIR", direct_method="RIS", light_candidates=8)
    # the central 16 x 16 pixels (x, y in ±0.25) against the closed form at each pixel centre (the pixel
    # average of this smooth function differs from its centre value by < 1e-5 relative)
    c = -1 + (np.arange(24, 40) + 0.5) * 2 / width
    expected = expected_floor_radiance(c[None, :], c[:, None])
    reps = [(render_frame(scene, RenderSettings(**settings, seed=s)).passes["Combined"][24:40, 24:40, 0] / expected)
            .mean() for s in range(8)]
    mean, se = np.mean(reps), standard_error(reps)
    assert se < 0.01  # the test can see a 3 % error
    assert abs(mean - 1.0) < 5 * se + 5e-4, (mean, se)


def test_light_falloff_scales_a_lamp_by_its_distance_to_the_receiver():
    """A Light Falloff output multiplies a lamp's radiance by d^k (k 1 Linear, 2 Constant) and, with Smooth s,
    by d² / (s + d²), d from the receiver to the light point (the lamp's centre when none is given); spot cones and
    falloffs multiply; a lamp without one reads 1, also when a scene built its Lamps without falloff arrays."""
    from restir_engine.core.lights.receiver import spot_factor
    lamps = floor_under_sphere().lamps
    n = len(lamps.spot_cos)
    tri = np.zeros(4, np.int64)
    p = np.array([[0, 0, 0], [3, 0, 1.5], [0, 0, 5.5], [0, 2, 1.5]], np.float32).T  # distances 1.5, 3, 4, 2
    d = np.float32([1.5, 3, 4, 2])
    np.testing.assert_allclose(spot_factor(lamps, tri, p), 1.0)
    for k, s in ((1, 0.0), (2, 0.0), (0, 2.0), (1, 0.5)):
        lamps.falloff, lamps.falloff_smooth = np.full(n, k, np.float32), np.full(n, s, np.float32)
        want = d ** k * (d * d / (s + d * d) if s > 0 else 1.0)
        np.testing.assert_allclose(spot_factor(lamps, tri, p), want, rtol=1e-5)
        q = np.array([[0, 0, 1.0]] * 4, np.float32).T  # a light point 0.5 below the centre
        dq = np.linalg.norm(p - q, axis=0)
        want_q = dq ** k * (dq * dq / (s + dq * dq) if s > 0 else 1.0)
        np.testing.assert_allclose(spot_factor(lamps, tri, p, q), want_q, rtol=1e-5)
