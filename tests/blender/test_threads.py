"""Blender's Threads setting (Render Properties > Performance > Threads) sets the pool's size in F12, the viewport
and the CLI's ``-t``; Auto uses every logical core. The image does not depend on it (tests/core/test_thread_count.py)."""
import os
import subprocess
import sys

import bpy
import numpy as np
from bpy_scenes import configure_restir, cornell_box, render_passes

from restir_engine.core.parallel import pool as pool_mod

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def test_f12_follows_the_threads_setting(addon):
    scene = cornell_box("EMISSIVE", (24, 16))
    configure_restir(scene, 1, 1)
    try:
        scene.render.threads_mode = "FIXED"
        scene.render.threads = 3
        fixed = render_passes(scene)["Combined"]
        assert pool_mod.pool()._max_workers == 3
        scene.render.threads_mode = "AUTO"
        auto = render_passes(scene)["Combined"]
        assert pool_mod.pool()._max_workers == (os.cpu_count() or 1)
        assert np.array_equal(fixed, auto)  # the same seed, the same image
    finally:
        pool_mod.set_thread_count(None)


def test_cli_threads_flag(addon, tmp_path):
    scene = cornell_box("EMISSIVE", (16, 16))
    scene.restir.samples = 1
    path = tmp_path / "t.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    report = ("import bpy; bpy.app.handlers.render_post.append(lambda *a: print('pool', __import__("
              "'restir_engine.core.parallel.pool', fromlist=['pool']).pool()._max_workers, flush=True))")
    for flag, want in (("5", 5), ("0", os.cpu_count() or 1)):
        r = subprocess.run([sys.executable, "-m", "restir_engine", str(path), "--python-expr", report, "-t", flag,
                            "-f", "1", "-o", str(tmp_path / "t_####"), "-F", "PNG"], cwd=ROOT, capture_output=True,
                           text=True, timeout=300)
        assert r.returncode == 0, r.stderr
        assert f"pool {want}" in r.stdout, r.stdout[-2000:]
    r = subprocess.run([sys.executable, "-m", "restir_engine", str(path), "-t", "-2"], cwd=ROOT, capture_output=True,
                       text=True, timeout=300)
    assert r.returncode == 2 and "--threads: must be at least 0" in r.stderr


def test_f12_renders_in_worker_processes_with_the_same_image(addon):
    """Render Properties > Performance > Processes: F12 in 2 worker processes gives the image of Blender's process
    alone (a 256x256 frame has 2 chunks of pixels, one per process)."""
    from restir_engine.core.parallel import processes
    scene = cornell_box("EMISSIVE", (256, 256))
    configure_restir(scene, 1, 1)
    try:
        scene.restir.processes = 1
        alone = render_passes(scene)["Combined"]
        scene.restir.processes = 2
        shared = render_passes(scene)["Combined"]
        assert processes._TEAM is not None and processes._TEAM.size == 2 and processes._TEAM.alive()
        assert np.array_equal(alone, shared)
    finally:
        scene.restir.processes = 0
        processes.shutdown()
        processes.set_process_count(None)
