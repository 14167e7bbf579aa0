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


@pytest.fixture(scope="session", autouse=True)
def _end_worker_processes():
    yield
    from restir_engine.core.parallel import processes
    processes.shutdown()


SUBJECTS = ("core", "restir", "materials", "blender", "cycles", "tools")
# the long statistical suites, run alone with -m slow (or left out with -m "not slow")
SLOW = {"cycles"}


def pytest_addoption(parser):
    parser.addoption("--slow-shard", default=None, metavar="K/N",
                     help="run only the K-th (0-based) of N shares of the slow tests (every other test runs); "
                          "scripts/test.sh gives each Blender one share, so each slow test runs once per CI")


def _slow_share(option: str | None):
    if option is None:
        return None
    k, n = (int(v) for v in option.split("/"))
    if not 0 <= k < n:
        raise pytest.UsageError(f"--slow-shard {option}: K must be in 0..N-1")
    return k, n


def pytest_collection_modifyitems(config, items):
    """Mark each test with its subject (its folder under tests/) and the slow suites with ``slow``; with
    ``--slow-shard K/N`` deselect the slow tests outside the K-th share (the slow tests sorted by name, dealt out in
    turn: a parametrized test's cases fall into different shares)."""
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
    k, n = share
    slow = sorted(item.nodeid for item in items if item.get_closest_marker("slow"))
    outside = {nodeid for i, nodeid in enumerate(slow) if i % n != k}
    config.hook.pytest_deselected(items=[item for item in items if item.nodeid in outside])
    items[:] = [item for item in items if item.nodeid not in outside]
