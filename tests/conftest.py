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
