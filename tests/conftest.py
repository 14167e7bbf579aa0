import json
import os
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
for p in (ROOT, os.path.dirname(os.path.abspath(__file__)), os.path.join(ROOT, "scripts")):
    if p not in sys.path:
        sys.path.insert(0, p)


@pytest.fixture(scope="session")
def addon():
    """The add-on registered once for the session (the bpy module keeps one Blender per process)."""
    import bpy

    import restir_engine
    if not hasattr(bpy.types.Scene, "restir"):
        restir_engine.register()
    yield restir_engine


@pytest.fixture(autouse=True)
def _core_renders_in_this_process():
    """The core renders in the test's own process unless a test asks for worker processes: an F12 through the
    engine sets Render Properties > Performance > Processes (Auto) for every later render of the process, and tests
    of the core read its internals (the history's arrays, patched functions) in this process."""
    yield
    from restir_engine.core.parallel import processes
    processes.set_process_count(None)


@pytest.fixture(autouse=True)
def _threads_of_this_suite():
    """The core's threads: RESTIR_TEST_THREADS where set (scripts/test.sh runs the two Blenders' suites at once and
    gives each its share of the cores; bpy renders take it from harness.render.configure_restir), else every
    logical core."""
    from restir_engine.core.parallel import pool
    pool.set_thread_count(int(os.environ.get("RESTIR_TEST_THREADS", "0")) or None)


@pytest.fixture(scope="session", autouse=True)
def _end_worker_processes():
    yield
    from restir_engine.core.parallel import processes
    processes.shutdown()


SUBJECTS = ("core", "restir", "materials", "blender", "cycles", "tools")
# the long statistical suites, run alone with -m slow (or left out with -m "not slow")
SLOW = {"cycles"}


def pytest_addoption(parser):
    parser.addoption("--slow-shard", default=None, metavar="K/N[:W0,W1,...]",
                     help="run only the K-th (0-based) of N shares of the slow tests (every other test runs), the "
                          "shares in the proportions W (default equal); scripts/test.sh gives each Blender one "
                          "share, so each slow test runs once per CI")


def _slow_share(option: str | None):
    """(k, weights) of a --slow-shard value, or None."""
    if option is None:
        return None
    part, _, weights = option.partition(":")
    k, n = (int(v) for v in part.split("/"))
    w = [int(v) for v in weights.split(",")] if weights else [1] * n
    if not 0 <= k < n or len(w) != n or min(w) < 1:
        raise pytest.UsageError(f"--slow-shard {option}: K must be in 0..N-1 and W N positive integers")
    return k, w


def dealt(nodeids, k: int, weights, seconds=None) -> set:
    """The K-th share of ``nodeids``: longest first (``seconds`` per test, by default tests/data/slow_durations.json;
    a test not listed counts as the median), each to the share whose time over its weight would be least after it
    (ties by name), so that the shares' times stand in the proportions ``weights``."""
    if seconds is None:
        with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "slow_durations.json")) as f:
            seconds = json.load(f)["seconds"]
    known = sorted(seconds.values())
    typical = known[len(known) // 2] if known else 1.0
    load = [0.0] * len(weights)
    mine = set()
    for nodeid in sorted(nodeids, key=lambda n: (-seconds.get(n, typical), n)):
        t = seconds.get(nodeid, typical)
        j = min(range(len(weights)), key=lambda s: ((load[s] + t) / weights[s], s))
        load[j] += t
        if j == k:
            mine.add(nodeid)
    return mine


def pytest_collection_modifyitems(config, items):
    """Mark each test with its subject (its folder under tests/) and the slow suites with ``slow``; with
    ``--slow-shard K/N`` deselect the slow tests outside the K-th share (:func:`dealt`: a parametrized test's cases
    fall into different shares)."""
    for item in items:
        parts = os.path.relpath(str(item.fspath), os.path.dirname(os.path.abspath(__file__))).split(os.sep)
        subject = parts[0] if len(parts) > 1 and parts[0] in SUBJECTS else None
        if subject is not None:
            item.add_marker(getattr(pytest.mark, subject))
        if subject in SLOW or item.get_closest_marker("slow_case"):
            item.add_marker(pytest.mark.slow)
    share = _slow_share(config.getoption("--slow-shard"))
    if share is None:
        return
    k, weights = share
    slow = [item.nodeid for item in items if item.get_closest_marker("slow")]
    outside = set(slow) - dealt(slow, k, weights)
    config.hook.pytest_deselected(items=[item for item in items if item.nodeid in outside])
    items[:] = [item for item in items if item.nodeid not in outside]
