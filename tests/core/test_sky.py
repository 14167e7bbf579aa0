"""The Sky Texture's models (core/lights/sky.py) and a world lit by one (core/lights/world.py): where the sun is,
its disc, and the world's sampling of the disc apart from its image (unbiased: the estimate of the sky's total
power matches a fine quadrature within 5 standard errors, and a 3 % error of the pdf would not)."""
import math

import numpy as np
from stats import POWER_ERROR, Z_MAX

from restir_engine.core.lights import sky
from restir_engine.core.lights.world import LUM, World, WorldGraph
from restir_engine.core.materials.nodes.attributes import DirectionAttributes
from restir_engine.core.materials.nodes.program import Program


def test_a_sun_past_the_zenith_comes_down_on_the_other_side():
    e, az = sky.wrap_sun(2.2, 0.3)
    assert math.isclose(e, math.pi - 2.2, abs_tol=1e-12)
    assert math.isclose(az, 2 * math.pi - (0.3 + math.pi), abs_tol=1e-12)
    e, az = sky.wrap_sun(0.4 + 2 * math.pi, -1.0)  # whole turns of the elevation and a negative rotation
    assert math.isclose(e, 0.4, abs_tol=1e-9) and math.isclose(az, 1.0, abs_tol=1e-12)


def _sky(model="MULTIPLE_SCATTERING", elevation=0.4, rotation=1.1, size=0.05):
    return sky.atmosphere_sky(model, True, size, 1.0, elevation, rotation, 100.0, 1.0, 1.0, 1.0)


def test_the_sun_disc_is_where_the_sun_points_with_its_limb_darker():
    for model in ("MULTIPLE_SCATTERING", "SINGLE_SCATTERING"):
        s = _sky(model)
        sun = s.sun_direction().astype(np.float64)
        assert math.isclose(math.asin(sun[2]), 0.4, abs_tol=1e-6)
        helper = np.cross(sun, [0.0, 0.0, 1.0])
        helper /= np.linalg.norm(helper)

        def towards(angle):  # beside the sun's centre, horizontally
            d = sun * math.cos(angle) + helper * math.sin(angle)
            return s.radiance(d[:, None].astype(np.float32))[:, 0]
        centre, limb, outside = towards(0.0), towards(0.024), towards(0.026)
        assert centre.sum() > 1000 * outside.sum() > 0  # the disc outshines the sky beside it
        assert limb.sum() < 0.8 * centre.sum()           # limb darkening
        assert np.allclose(s.radiance(sun[:, None].astype(np.float32), sun=False)[:, 0], outside, rtol=0.05)


def _world_of(model) -> World:
    program = Program(ops=[("attribute", (0,), (), {"name": "generated"}),
                           ("sky_texture", (1,), (0,), {"sky": model, "plain": True})],
                      outputs={"color": (1, "rgb")}, reads=("generated",), vectors=(0, 1))
    h, w = 128, 256
    rows, cols = np.meshgrid(np.arange(h), np.arange(w), indexing="ij")
    phi, theta = (0.5 - (cols.ravel() + 0.5) / w) * 2 * np.pi, (1.0 - (rows.ravel() + 0.5) / h) * np.pi
    dirs = np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)]).astype(np.float32)
    image = program.run(DirectionAttributes(dirs, [], without_sun=True))["color"].T.reshape(h, w, 3)
    graph = WorldGraph(program, [], False, None, 1.0, (model.sun_cone(),))
    return World(np.zeros(3, np.float32), image, graph=graph)


def _power_by_quadrature(model) -> float:
    """∫ luminance dω: the sky without its disc on a fine equal-area grid, plus the disc over a fine cone grid."""
    n = 1024
    z = 1 - 2 * (np.arange(n) + 0.5) / n
    phi = 2 * np.pi * (np.arange(2 * n) + 0.5) / (2 * n)
    zz, pp = np.meshgrid(z, phi, indexing="ij")
    r = np.sqrt(1 - zz * zz)
    d = np.stack([r * np.cos(pp), r * np.sin(pp), zz]).reshape(3, -1).astype(np.float32)
    sky_part = float((model.radiance(d, sun=False).T @ LUM).mean() * 4 * np.pi)
    axis, half = model.sun_cone()
    from restir_engine.core.lights.world import _cone_directions
    k = 200
    g = (np.arange(k) + 0.5) / k
    u, v = (x.ravel() for x in np.meshgrid(g, g))
    cone = _cone_directions(axis, math.cos(half), u, v)
    solid = 2 * np.pi * (1 - math.cos(half))
    disc = float(((model.radiance(cone) - model.radiance(cone, sun=False)).T @ LUM).mean() * solid)
    return sky_part + disc


def test_a_world_sky_samples_its_sun_disc_apart_and_stays_unbiased():
    model = _sky()
    world = _world_of(model)
    assert 0.3 < world._suns[0][3] < 0.99  # the disc takes its share of the samples
    rng = np.random.default_rng(7)
    u1, u2 = rng.random(400_000), rng.random(400_000)
    d, pdf, le = world.sample(u1, u2)
    np.testing.assert_allclose(world.pdf(d), pdf, rtol=1e-6)
    f = (le.T @ LUM) / pdf
    mean, se = f.mean(), f.std(ddof=1) / np.sqrt(len(f))
    ref = _power_by_quadrature(model)
    assert abs(mean - ref) <= Z_MAX * se + 1e-3 * ref, (mean, se, ref)
    assert abs(mean * (1 + POWER_ERROR) - ref) > Z_MAX * se + 1e-3 * ref  # power: a 3 % error shows
