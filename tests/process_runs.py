"""Renders of one exported scene in Blender's process and in worker processes, for tests that the workers give
the same image (the team shut down afterwards, so later tests start from none)."""
from __future__ import annotations


def one_and_two_processes(core_scene, settings):
    """(the frame rendered in this process, the frame rendered by 2 worker processes)."""
    from restir_engine.core.parallel import processes
    from restir_engine.core.renderer import render_frame
    try:
        return render_frame(core_scene, settings, processes=1), render_frame(core_scene, settings, processes=2)
    finally:
        processes.shutdown()
