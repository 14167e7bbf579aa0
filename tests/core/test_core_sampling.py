import numpy as np
import pytest

from restir_engine.core.sampling import AliasTable, rng, uniform_triangle


@pytest.mark.parametrize("n", [1, 2, 7, 1000, 100000])
def test_alias_table_realizes_the_weights(n):
    g = np.random.default_rng(n)
    w = g.random(n) ** 6
    w[g.random(n) < 0.2] = 0
    if w.sum() == 0:
        w[0] = 1
    table = AliasTable(w)
    assert np.allclose(table.implied_pdf(), w / w.sum(), rtol=0, atol=1e-12)
    assert ((table.prob >= 0) & (table.prob <= 1)).all()


def test_alias_table_sampling_frequencies_chi_square():
    w = np.array([5.0, 1.0, 0.0, 3.0, 0.5, 0.5])
    table = AliasTable(w)
    g = np.random.default_rng(3)
    n = 400_000
    idx = table.sample(g.random(n), g.random(n))
    counts = np.bincount(idx, minlength=len(w))
    assert counts[2] == 0  # zero weight is never chosen
    expected = n * w / w.sum()
    nz = expected > 0
    chi2 = ((counts[nz] - expected[nz]) ** 2 / expected[nz]).sum()
    # 4 degrees of freedom: P(chi2 > 23.5) = 1e-4
    assert chi2 < 23.5


def test_alias_table_rejects_all_zero():
    with pytest.raises(ValueError):
        AliasTable(np.zeros(4))


def test_rng_streams_are_deterministic_and_independent():
    a = rng(1, 2, 3, 4, 5).random(1000)
    assert np.array_equal(a, rng(1, 2, 3, 4, 5).random(1000))
    for other in [(2, 2, 3, 4, 5), (1, 3, 3, 4, 5), (1, 2, 4, 4, 5), (1, 2, 3, 5, 5), (1, 2, 3, 4, 6)]:
        b = rng(*other).random(1000)
        # correlation of independent uniforms: sd 1/sqrt(1000) ~ 0.032; 5 sd bound
        assert abs(np.corrcoef(a, b)[0, 1]) < 0.16


def test_uniform_triangle_is_uniform():
    g = np.random.default_rng(0)
    b1, b2 = uniform_triangle(g.random(200_000), g.random(200_000))
    assert (b1 >= 0).all() and (b2 >= 0).all() and (b1 + b2 <= 1 + 1e-6).all()
    # mean barycentric of a uniform point is 1/3 each; sd of each is sqrt(1/18)
    se = np.sqrt(1 / 18 / 200_000)
    assert abs(b1.mean() - 1 / 3) < 5 * se and abs(b2.mean() - 1 / 3) < 5 * se


def test_uniform_ints_cover_the_range_uniformly():
    """Multiply-shift integers: inside [0, high), every value about equally often (chi-square, 1e-4 level),
    same for the same stream."""
    from restir_engine.core.sampling import uniform_ints
    for high in (7, 1024):
        k = uniform_ints(rng(1, 2, 3, 4), high, (50, 4000))
        assert k.shape == (50, 4000) and k.min() == 0 and k.max() == high - 1
        counts = np.bincount(k.ravel(), minlength=high)
        expected = k.size / high
        chi2 = ((counts - expected) ** 2 / expected).sum()
        # chi-square with high - 1 degrees of freedom: mean high - 1, sd sqrt(2 (high - 1)); 4.5 sd ~ p < 1e-4
        assert chi2 < (high - 1) + 4.5 * np.sqrt(2 * (high - 1)), chi2
        assert np.array_equal(k, uniform_ints(rng(1, 2, 3, 4), high, (50, 4000)))
