"""``python -m restir_engine`` renders a .blend like ``blender -b FILE -E RESTIR -a / -f N``."""
import os
import subprocess
import sys

import bpy
import pytest
from bpy_scenes import cornell_box, reset

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "restir_engine", *args], cwd=ROOT, capture_output=True, text=True,
                          timeout=300)


@pytest.fixture
def blend(addon, tmp_path):
    scene = cornell_box("EMISSIVE", (24, 24))
    scene.restir.samples = 1
    scene.frame_start, scene.frame_end = 1, 2
    scene.render.filepath = "//frames/img_"
    scene.render.image_settings.file_format = "PNG"
    path = tmp_path / "box.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    return path


def test_animation_uses_the_files_output_settings(blend):
    r = run_cli(str(blend), "-a")
    assert r.returncode == 0, r.stderr
    for f in (1, 2):
        assert (blend.parent / "frames" / f"img_{f:04d}.png").exists()


def test_single_frame_with_overrides(blend, tmp_path):
    out = tmp_path / "o" / "x_####"
    r = run_cli(str(blend), "-o", str(out), "-F", "OPEN_EXR", "-f", "2", "--samples", "2", "--max-bounces", "0")
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "o" / "x_0002.exr").exists()
    assert not (tmp_path / "o" / "x_0001.exr").exists()
    assert "Saved:" in r.stdout


def test_missing_file_and_missing_camera_fail_cleanly(addon, tmp_path):
    r = run_cli(str(tmp_path / "nope.blend"))
    assert r.returncode == 1 and "no such file" in r.stderr
    reset()
    bpy.ops.mesh.primitive_cube_add()
    path = tmp_path / "nocam.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    r = run_cli(str(path), "-f", "1")
    assert r.returncode == 1 and "camera" in r.stderr
