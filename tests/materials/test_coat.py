"""The Principled Coat's layering (core/materials/nodes/ops_layers.py) and the Mix pick it goes through
(core/materials/mix.py), without bpy: the layer and tint factors against their closed forms, a white furnace of
coat + base over view angles and coat roughnesses (Monte Carlo, 5 standard errors), and the pick's expectation.
The match with Cycles' images is tests/cycles/test_materials_cycles.py::test_principled_coat_matches_cycles."""
from types import SimpleNamespace

import numpy as np
import pytest

from restir_engine.core.materials.bsdf import sample_bsdf
from restir_engine.core.materials.mix import pick_components
from restir_engine.core.materials.nodes.ops_layers import coat_layer
from restir_engine.core.materials.params import SurfaceParams

N = 400_000
Z = 5.0


class _View:
    """The hit attributes coat_layer reads: the view ("incoming") of k hits."""

    def __init__(self, incoming):
        self.incoming = incoming

    def get(self, name):
        assert name == "incoming"
        return self.incoming

    def __len__(self):
        return self.incoming.shape[1]


def _view(mu):
    mu = np.atleast_1d(np.asarray(mu, np.float32))
    return np.stack([np.sqrt(1 - mu * mu), np.zeros_like(mu), mu]).astype(np.float32)


def _fresnel(cos, eta):
    """The unpolarized dielectric Fresnel reflectance (float64, from the two polarizations)."""
    sin_t = np.sqrt(1 - cos * cos) / eta
    cos_t = np.sqrt(1 - sin_t * sin_t)
    rs = (cos - eta * cos_t) / (cos + eta * cos_t)
    rp = (eta * cos - cos_t) / (eta * cos + cos_t)
    return 0.5 * (rs * rs + rp * rp), cos_t


def test_coat_layer_factors_follow_their_closed_forms():
    """Smooth coat: layer = 1 - w F(θ, η) with the exact Fresnel; tint factor = mix(1, tint^(1/cos θ_t), w) with θ_t
    the view refracted into the coat; normal incidence: F = ((η - 1)/(η + 1))² and the factor is the tint itself."""
    mu = np.array([1.0, 0.8, 0.5, 0.2, 0.05])
    normal = np.array([[0.0], [0.0], [1.0]], np.float32)
    tint = np.array([[0.9], [0.4], [0.2]], np.float32)
    smooth = np.float32(0.0)
    for weight, eta in ((1.0, 1.5), (0.5, 1.3), (1.0, 2.0)):
        layer, factor, albedo = coat_layer(_View(_view(mu)), {}, np.float32(weight), np.float32(eta), tint, normal,
                                           smooth)
        f, cos_t = _fresnel(mu, eta)
        assert np.allclose(albedo, f, rtol=0.01, atol=1e-3)  # the layer tables' interpolation
        assert np.allclose(layer, 1 - weight * albedo, atol=1e-6)
        assert np.allclose(factor, (1 - weight) + weight * tint.astype(np.float64) ** (1 / cos_t), rtol=1e-5)
    layer, factor, _ = coat_layer(_View(_view([1.0])), {}, np.float32(1), np.float32(1.5), tint, normal, smooth)
    assert abs(float(layer[0]) - 0.96) < 1e-4 and np.allclose(factor[:, 0], tint[:, 0])
    # a white tint changes nothing; a weight above 1 saturates the layer at 0, not below
    _, white, _ = coat_layer(_View(_view(mu)), {}, np.float32(1), np.float32(1.5), np.ones((3, 1), np.float32), normal,
                             smooth)
    assert np.allclose(white, 1)
    layer, _, _ = coat_layer(_View(_view([0.05])), {}, np.float32(3), np.float32(1.5), tint, normal, smooth)
    assert float(layer[0]) == 0.0


@pytest.mark.parametrize("roughness", [0.3, 0.6, 0.9])
def test_coat_albedo_is_the_coat_lobes_albedo(roughness):
    """A rough coat's albedo toward the viewer, as the layering weighs it ((E + Fms (1 - E)) mix(F0, 1, S), Cycles'
    estimate), is the directional albedo of the coat lobe itself (Monte Carlo of the BSDF, 5 SE + 1 %), so coat +
    base never reflect more than arrives; the smooth Fresnel (what a smooth coat reflects) is far off it at grazing
    views and, at roughness 0.9, dims a white base under the coat by 2 % too much even at normal incidence."""
    rng = np.random.default_rng(3)
    for eta in (1.5, 2.0):
        f0 = ((eta - 1) / (eta + 1)) ** 2
        lobe = _rows((0, 0, 0), roughness, f0)
        for mu in (1.0, 0.5, 0.1):
            _, _, albedo = coat_layer(_View(_view([mu])), {}, np.float32(1), np.float32(eta),
                                      np.ones((3, 1), np.float32), np.array([[0.0], [0.0], [1.0]], np.float32),
                                      np.float32(roughness))
            mc, se = _albedo(lobe, mu, rng)
            assert abs(float(albedo[0]) - mc) < Z * se + 0.01 * mc, (eta, mu, float(albedo[0]), mc)
            if mu == 0.1:  # power: the smooth estimate is caught (at a grazing view at every roughness here)
                smooth, _ = _fresnel(np.array([mu]), eta)
                assert abs(float(smooth[0]) - mc) > Z * se + 0.01 * mc


def _albedo(p, mu, rng):
    """Directional albedo (mean, SE) of SurfaceParams ``p`` (N entries) at view cosine ``mu`` (Monte Carlo)."""
    wo = np.repeat(_view([mu]), N, axis=1)
    wi, f, pdf = sample_bsdf(p, wo, rng.random(N, dtype=np.float32), rng.random(N, dtype=np.float32),
                             rng.random(N, dtype=np.float32))
    x = np.where(pdf > 0, f * np.maximum(wi[2], 0) / np.maximum(pdf, 1e-30), 0).mean(axis=0)
    return float(x.mean()), float(x.std() / np.sqrt(N))


def _rows(base, roughness, f0):
    return SurfaceParams.from_material(np.tile(np.asarray(base, np.float32), (N, 1)), np.zeros(N, np.float32),
                                       np.full(N, roughness, np.float32), np.full(N, f0, np.float32))


@pytest.mark.parametrize("coat_roughness", [0.0, 0.3, 1.0])
def test_coat_over_a_white_base_creates_no_energy(coat_roughness):
    """White furnace: a coat of weight 1 (IOR 1.5) over a white Principled base (roughness 0.5) reflects at most
    what arrives, at normal, oblique and grazing views: albedo(coat) + layer · albedo(base) ≤ 1 + 5 SE. The same sum
    without the layering (layer = 1) exceeds 1 by many SE at a grazing view, so a coat added on top of the base
    without attenuating it fails here."""
    rng = np.random.default_rng(7)
    normal = np.array([[0.0], [0.0], [1.0]], np.float32)
    coat, base = _rows((0, 0, 0), coat_roughness, 0.04), _rows((1, 1, 1), 0.5, 0.04)
    for mu in (1.0, 0.5, 0.1):
        layer, _, _ = coat_layer(_View(_view([mu])), {}, np.float32(1), np.float32(1.5), np.ones((3, 1), np.float32),
                                 normal, np.float32(coat_roughness))
        (ac, sc), (ab, sb) = _albedo(coat, mu, rng), _albedo(base, mu, rng)
        se = float(np.hypot(sc, sb))
        assert ac + float(layer[0]) * ab <= 1 + Z * se, (mu, ac, ab, float(layer[0]))
        if mu == 0.1:
            assert ac + ab > 1 + Z * se  # power: the unlayered sum is caught


def _mix_table(weights, pick):
    """A material table of one mixed material (index 1) whose components (materials 10, 11, ...) have constant
    ``weights`` and whose node program gives them the reflectance estimates ``pick`` ("mix_pick:<k>")."""
    k = len(weights)
    outputs = {f"mix_pick:{j}": v for j, v in enumerate(pick)}

    class _Program:
        def has(self, name):
            return name in outputs

        def run(self, attrs, fields=None):
            return {f: np.full(len(attrs), v, np.float32) for f, v in outputs.items()}
    return SimpleNamespace(mix_first=np.array([-1, 0], np.int32), mix_count=np.array([0, k], np.int32),
                           mix_comp=np.arange(10, 10 + k, dtype=np.int32),
                           mix_weight=np.asarray(weights, np.float32), mix_tex=np.full(k, -1, np.int32),
                           mix_sign=np.zeros(k, np.float32), textures=[], program=np.array([-1, 0], np.int32),
                           programs=[_Program()])


def test_mix_pick_by_estimates_keeps_the_expectation():
    """With reflectance estimates a_k the pick probability is p_k = ½ w_k/W + ½ w_k a_k/Σ w_j a_j and the picked
    component is scaled by w_k/p_k: over a uniform grid of ξ, E[scale · 1{k picked}] = w_k for every component
    (the sum stays Σ w_k f_k); a faint coat (a = 0.04) over a bright base (a = 0.7) gets fewer picks than by
    weight alone."""
    n = 200_000
    xi = (np.arange(n, dtype=np.float32) + 0.5) / n
    weights, est = [1.0, 0.96], [0.04, 0.7]
    mats = _mix_table(weights, est)
    comp, scale, tint = pick_components(mats, np.full(n, 1), np.arange(n), xi, None, attrs_of=lambda rows: rows)
    assert tint is None
    w, a = np.array(weights), np.array(est)
    p = 0.5 * w / w.sum() + 0.5 * w * a / (w * a).sum()
    for j in range(2):
        chosen = comp == 10 + j
        assert abs(chosen.mean() - p[j]) < 1e-4
        assert abs((scale * chosen).mean() - w[j]) < 1e-3 * w[j]
    assert (comp == 10).mean() < w[0] / w.sum() - 0.1
