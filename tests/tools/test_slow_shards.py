"""The CI's deal of the slow suite between the two Blenders (tests/conftest.dealt): each slow test in exactly one
share, the shares' times in the proportions asked for."""
import numpy as np
from conftest import dealt


def test_shares_partition_the_slow_tests_in_proportion():
    rng = np.random.default_rng(7)
    seconds = {f"tests/cycles/test_x.py::test_{k}": float(s) for k, s in enumerate(rng.lognormal(2.5, 1.0, 100))}
    names = list(seconds) + ["tests/cycles/test_x.py::test_new"]  # one without a measured time
    for weights in ([1, 1], [5, 4], [3, 1, 2]):
        shares = [dealt(names, k, weights, seconds) for k in range(len(weights))]
        assert sum(len(s) for s in shares) == len(names) and set().union(*shares) == set(names)
        loads = np.array([sum(seconds.get(n, 0.0) for n in s) for s in shares])
        longest = max(seconds.values())
        # greedy longest-first: each share within one longest test of its proportion of the total
        assert np.all(np.abs(loads - loads.sum() * np.array(weights) / sum(weights)) <= longest), loads


def test_the_deal_does_not_depend_on_the_order_tests_are_collected_in():
    names = [f"t::{k}" for k in range(30)]
    seconds = {n: float(k % 7) for k, n in enumerate(names)}
    assert dealt(names, 0, [5, 4], seconds) == dealt(names[::-1], 0, [5, 4], seconds)
