"""The world as a light (core/world.py): importance sampling of an environment image and of a constant colour, used
by next-event estimation with MIS. Tolerances: 5 standard errors of the per-seed means (each side a z-test with the
stated bound; the seeds are independent)."""
import numpy as np
import pytest
from scenes_core import plane_under_world

from restir_engine.core.renderer import RenderSettings, render_frame
from restir_engine.core.world import World


def sun_sky(h=32, w=64):
    """A dim blue sky with a small bright sun-like spot 40° above the horizon (and black below the horizon)."""
    img = np.zeros((h, w, 3), np.float32)
    img[h // 2:] = (0.2, 0.3, 0.5)
    img[int(h * (0.5 + 40 / 180)), 10:12] = (800.0, 700.0, 600.0)
    return img


def irradiance_up(world: World, n=2_000_000, seed=0) -> np.ndarray:
    """∫ L(ω) cos⁺θ dω over the upper hemisphere by uniform sphere sampling (a reference independent of the
    sampler under test), and its standard error."""
    g = np.random.default_rng(seed)
    z = 1 - 2 * g.random(n)
    r = np.sqrt(1 - z * z)
    phi = 2 * np.pi * g.random(n)
    d = np.stack([r * np.cos(phi), r * np.sin(phi), z]).astype(np.float32)
    est = world.radiance(d) * np.maximum(z, 0) * 4 * np.pi
    return est.mean(axis=1), est.std(axis=1) / np.sqrt(n)


@pytest.mark.parametrize("rotated", [False, True])
def test_environment_sampling_pdf_and_estimate(rotated):
    """sample() returns the density pdf() reports, and E[L cos / pdf] over the hemisphere equals the reference
    irradiance (5 SE of both estimates)."""
    rot = None
    if rotated:
        a = 0.7
        rot = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]], np.float32)
    world = World((0, 0, 0), sun_sky(), rot)
    g = np.random.default_rng(3)
    n = 1_000_000
    d, pdf, le = world.sample(g.random(n), g.random(n))
    # the same texel's density, except for the few directions that round onto a texel edge
    assert (np.abs(world.pdf(d) / pdf - 1) > 1e-3).mean() < 1e-4
    est = le * np.maximum(d[2], 0) / pdf
    ref, ref_se = irradiance_up(world, seed=5)
    se = np.sqrt(est.var(axis=1) / n + ref_se ** 2)
    assert (np.abs(est.mean(axis=1) - ref) < 5 * se).all(), (est.mean(axis=1), ref, se)


def render_mean(scene, spp, seed):
    r = render_frame(scene, RenderSettings(integrator="PATH", max_bounces=0, samples=spp, seed=seed))
    return r.passes["Combined"][..., :3].reshape(-1, 3).mean(axis=0)


@pytest.mark.parametrize("kind", ["constant", "image"])
def test_floor_under_the_world_matches_the_irradiance(kind):
    """A diffuse floor (albedo 0.5) under the world, seen from above: its radiance is albedo/π times the world's
    irradiance, computed independently (constant world: exactly 0.5). 12 seeds; bound 5 SE + 0.5 % (the
    irradiance reference's own error is below 0.2 %)."""
    scene = plane_under_world(albedo=0.5, world=1.0, width=16)
    if kind == "image":
        scene.world_image = sun_sky()
        ref = 0.5 / np.pi * irradiance_up(World((0, 0, 0), scene.world_image))[0]
    else:
        ref = np.full(3, 0.5, np.float32)
    means = np.array([render_mean(scene, 8, seed) for seed in range(12)])
    se = means.std(axis=0, ddof=1) / np.sqrt(len(means))
    assert (np.abs(means.mean(axis=0) - ref) < 5 * se + 0.005 * ref).all(), (means.mean(axis=0), ref, se)


def test_importance_sampling_beats_bsdf_sampling_on_a_sun():
    """With the sun-like spot, the environment's light sample makes the floor's per-pixel variance at least 10x
    lower than BSDF sampling alone would (measured by turning the world's sampling off)."""
    scene = plane_under_world(albedo=0.5, world=1.0, width=16)
    scene.world_image = sun_sky()
    on = render_frame(scene, RenderSettings(integrator="PATH", max_bounces=0, samples=1, seed=1))
    img_on = on.passes["Combined"][..., 0]
    from restir_engine.core import pathtracer
    orig = pathtracer.World.__init__

    def unsampled(self, *a, **k):
        orig(self, *a, **k)
        self.sampled = False
    pathtracer.World.__init__ = unsampled
    try:
        from restir_engine.core import context_cache
        context_cache.clear()
        off = render_frame(scene, RenderSettings(integrator="PATH", max_bounces=0, samples=1, seed=1))
    finally:
        pathtracer.World.__init__ = orig
        context_cache.clear()
    img_off = off.passes["Combined"][..., 0]
    assert abs(img_off.mean() / img_on.mean() - 1) < 0.5  # the same light, both noisy estimates of it
    assert img_off.var() > 10 * img_on.var(), (img_off.var(), img_on.var())
