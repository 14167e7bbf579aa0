"""The subsurface random walk (core/integrators/subsurface.py) against independent references (5 standard errors):
its walk through Embree's mesh against an analog walk of the same medium through an analytic half-space, the
media's coefficients against their definitions, the entry's refraction against Snell's law. Against Cycles:
tests/cycles/test_materials_cycles.test_subsurface_matches_cycles."""
import numpy as np
import pytest

from restir_engine.core.integrators import subsurface
from restir_engine.core.integrators.subsurface import (WALK_CHIANG, WALK_SKIN, WALK_VAN_DE_HULST, Medium, medium,
                                                      walk)
from restir_engine.core.integrators.trace_context import build_context
from restir_engine.core.scene import Lamps, MaterialTable, Scene
from scenes_core import concat, quad, top_down_camera, tris

Z = 5.0
N = 200_000


def _box_scene(half=1000.0, depth=1000.0) -> Scene:
    """A closed box x, y in [-half, half], z in [-depth, 0] (outward normals), one object."""
    h, d = half, depth / 2
    faces = [quad((0, 0, 0), (h, 0, 0), (0, h, 0)), quad((0, 0, -depth), (0, h, 0), (h, 0, 0)),
             quad((h, 0, -d), (0, h, 0), (0, 0, d)), quad((-h, 0, -d), (0, 0, d), (0, h, 0)),
             quad((0, h, -d), (0, 0, d), (h, 0, 0)), quad((0, -h, -d), (h, 0, 0), (0, 0, d))]
    mats = MaterialTable.build([{"base_color": (0.8, 0.5, 0.2), "f0": 0.0}])
    return Scene(concat([tris(f, 0) for f in faces]), mats, Lamps.empty(), top_down_camera(8, 8))


def _analog_reflectance(sigma_t: float, alpha: float, g: float, n: int, rng) -> np.ndarray:
    """Per walk (n,): 1 where an analog walk (absorption as termination) entering the half-space z < 0 straight down
    leaves it again within the walk's step limit, else 0; the medium changes to its similarity form after
    subsurface.SIMILARITY_AFTER steps, as the walk's."""
    z = np.zeros(n)
    dz = -np.ones(n)
    live = np.ones(n, bool)
    out = np.zeros(n)
    for step in range(subsurface.MAX_STEPS):
        late = step > subsurface.SIMILARITY_AFTER
        ss = sigma_t * alpha * ((1 - g) if late else 1.0)
        st = sigma_t - sigma_t * alpha + ss if late else sigma_t
        gg = 0.0 if late else g
        idx = np.flatnonzero(live)
        if idx.size == 0:
            break
        if step > 0:
            u = rng.random(idx.size)
            cos_t = 1 - 2 * u
            if abs(gg) >= 1e-3:
                k = (1 - gg * gg) / (1 - gg * cos_t)
                cos_t = (1 + gg * gg - k * k) / (2 * gg)
            phi = 2 * np.pi * rng.random(idx.size)
            sin_t = np.sqrt(np.maximum(0, 1 - cos_t ** 2))
            old = dz[idx]
            # the new direction's z: rotate (sin cos φ, sin sin φ, cos) from the old direction's frame
            dz[idx] = cos_t * old + sin_t * np.cos(phi) * np.sqrt(np.maximum(0, 1 - old ** 2))
        t = -np.log1p(-rng.random(idx.size)) / st
        znew = z[idx] + t * dz[idx]
        esc = znew >= 0
        out[idx[esc]] = 1.0
        live[idx[esc]] = False
        z[idx] = znew
        rest = idx[~esc]
        absorbed = rng.random(rest.size) >= ss / st
        live[rest[absorbed]] = False
    return out


@pytest.mark.parametrize("g", [0.0, 0.5])
def test_walk_through_a_mesh_matches_an_analog_walk_of_the_half_space(g):
    """A walk entering a deep box straight down leaves it with weight R per channel, the half-space's reflectance of
    its medium (the box's sides are 1000 mean free paths away, beyond the step limit's reach). An analog walk of each
    channel alone through an analytic half-space estimates the same R; they agree within 5 SE, and a 3 % error is
    outside that bound."""
    scene = _box_scene()
    ctx = build_context(scene, 0)
    albedo = np.tile(np.float32([[0.9], [0.6], [0.4]]), (1, N))
    radius = np.full((3, N), 1.0, np.float32)
    med = medium(albedo, albedo, radius, np.full(N, g), np.full(N, WALK_VAN_DE_HULST), np.full(N, 1.4))
    p = np.zeros((3, N), np.float32)
    ng = np.zeros((3, N), np.float32)
    ng[2] = 1
    d = -ng
    ex = walk(ctx, p, ng, d, np.zeros(N, np.int64), med, np.random.default_rng(3))
    ours = np.zeros((3, N))
    ours[:, ex.rows] = ex.weight
    assert (np.abs(ex.p[2]) < 1e-3).mean() > 0.999  # the walks leave through the top face
    rng = np.random.default_rng(4)
    for c in range(3):
        ref = _analog_reflectance(float(med.sigma_t[c, 0]), float(med.alpha[c, 0]), g, N, rng)
        se = np.sqrt(ours[c].var() / N + ref.var() / N)
        diff = abs(ours[c].mean() - ref.mean())
        assert diff < Z * se, (c, ours[c].mean(), ref.mean(), se)
        assert 0.03 * ref.mean() > Z * se  # power: a 3 % error fails


def test_media_coefficients_follow_their_definitions():
    """Chiang's walk scales the radius by 1/(4π) and σt by 1/(1 - g), van de Hulst's takes it as the mean free path;
    both give α → 1 at albedo 1 and 0 at albedo 0 (raised to 0.2, its weight 0); Skin scales the radius by
    √(3 (1 - α')) of the dipole's albedo inversion."""
    a = np.float32([[1.0, 0.0, 0.5], [1.0, 0.0, 0.5], [1.0, 0.0, 0.5]])
    r = np.full((3, 3), 2.0, np.float32)
    g = np.float32([0.0, 0.0, 0.3])
    ch = medium(a, a, r, g, np.full(3, WALK_CHIANG), np.full(3, 1.4))
    assert np.allclose(ch.sigma_t[:, 0], 4 * np.pi / 2.0, rtol=1e-5)
    assert np.allclose(ch.sigma_t[:, 2], 4 * np.pi / (2.0 * 0.7), rtol=1e-5)
    vh = medium(a, a, r, g, np.full(3, WALK_VAN_DE_HULST), np.full(3, 1.4))
    assert np.allclose(vh.sigma_t, 0.5, rtol=1e-6)
    for m in (ch, vh):
        assert np.all(m.alpha[:, 0] > 0.999) and np.allclose(m.alpha[:, 1], 0.2) and np.all(m.weight[:, 1] == 0)
    # van de Hulst at g: alpha = (1 - s²)/(1 - g s²)
    s2 = (4.20863 * 0.5 - np.sqrt(9.59217 + 41.6808 * 0.5 + 17.7126 * 0.25) + 4.09712) ** 2
    assert np.isclose(vh.alpha[0, 2], (1 - s2) / (1 - 0.3 * s2), rtol=1e-5)
    sk = medium(a, a, r, g, np.full(3, WALK_SKIN), np.full(3, 1.4))
    rd = 0.5
    scale = subsurface.dipole_radius_scale(np.float64([[rd]]), np.float64([1.4]))[0, 0]
    ap = 1 - scale ** 2 / 3
    inv = 1 / 1.4
    f_dr = inv * (-1.44 * inv + 0.71) + 0.668 + 0.0636 * 1.4
    fa = 4 / 3 * (1 + f_dr) / (1 - f_dr)
    s = np.sqrt(3 * (1 - ap))
    assert abs(0.5 * ap * (1 + np.exp(-fa * s)) * np.exp(-s) - rd) < 1e-3  # the inversion's Rd is the albedo
    assert np.isclose(sk.sigma_t[0, 2], 1 / (2.0 * scale * 0.7), rtol=1e-4)


def test_entry_refracts_by_snells_law():
    """A smooth interface (α → 0) refracts the view by Snell's law; Skin's cosine entries go below the surface."""
    n = 4
    theta = np.radians([0.0, 20.0, 45.0, 70.0])
    wo = np.stack([np.sin(theta), np.zeros(n), np.cos(theta)]).astype(np.float32)
    nrm = np.tile(np.float32([[0], [0], [1]]), (1, n))
    ior = np.full(n, 1.4, np.float32)
    u = np.full((2, n), 0.3, np.float32)
    d, ok = subsurface.entry_directions(wo, nrm, nrm, np.full(n, 1e-6, np.float32), ior, np.zeros(n, bool), u)
    assert ok.all()
    sin_t = np.sqrt(d[0] ** 2 + d[1] ** 2)
    assert np.allclose(sin_t, np.sin(theta) / 1.4, atol=1e-3) and (d[2] < 0).all()
    assert np.allclose(d[0], -np.sin(theta) / 1.4, atol=1e-3)  # on the far side of the normal from the view
    u = np.random.default_rng(5).random((2, 1000)).astype(np.float32)
    m = 1000
    wo1 = np.tile(wo[:, 2:3], (1, m))
    nm = np.tile(nrm[:, :1], (1, m))
    d, ok = subsurface.entry_directions(wo1, nm, nm, np.full(m, 0.25, np.float32), np.full(m, 1.3, np.float32),
                                        np.ones(m, bool), u)
    assert ok.mean() > 0.9 and (d[2][ok] < 0).all()


def test_a_channel_of_zero_radius_is_diffuse():
    """As Cycles: where a channel's Radius x Scale is below 1e-8 the walked share of that channel is the diffuse
    lobe's (a camera hit keeps the other channels' share for its walk)."""
    from restir_engine.core.materials.surface import Surface
    scene = _box_scene()
    mats = scene.materials
    mats.subsurface = np.float32([1.0])
    mats.sss_radius = np.float32([[1.0, 0.5, 0.0]])
    mats.sss_method = np.int32([WALK_VAN_DE_HULST])
    ctx = build_context(scene, 0)
    assert ctx.has_subsurface
    n = 4
    o = np.tile(np.float32([[0], [0], [1]]), (1, n))
    d = np.tile(np.float32([[0], [0], [-1]]), (1, n))
    hit = ctx.geom_accel.intersect(o, d)
    s = Surface(ctx, hit.prim, hit.u, hit.v, o, d, hit.t, camera=True)
    base = np.float32([0.8, 0.5, 0.2])
    np.testing.assert_allclose(s.params.sss[:, 0], [0.8, 0.5, 0.0], atol=1e-6)
    np.testing.assert_allclose(s.params.diffuse[:, 0], [0.0, 0.0, 0.2], atol=1e-6)
    folded = Surface(ctx, hit.prim, hit.u, hit.v, o, d, hit.t)  # not a camera hit: all of it diffuse
    np.testing.assert_allclose(folded.params.diffuse[:, 0], base, atol=1e-6)
    assert not folded.params.sss.any()
