"""``python -m restir_engine`` renders a .blend like ``blender -b FILE -E RESTIR -a / -f N``."""
import os
import subprocess
import sys

import bpy
import pytest
from bpy_scenes import cornell_box, reset

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


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


@pytest.mark.parametrize("args,line", [
    (["--samples", "-3"], "error: argument --samples: must be at least 1, not -3"),
    (["--samples", "x"], "error: argument --samples: must be an integer, not 'x'"),
    (["--max-bounces", "-1"], "error: argument --max-bounces: must be at least 0, not -1"),
    (["--percentage", "0"], "error: argument --percentage: must be at least 1, not 0"),
    (["-s", "5", "-e", "2", "-a"], "error: frame end 2 is before frame start 5"),
])
def test_bad_arguments_get_one_line_and_status_2(blend, args, line):
    r = run_cli(str(blend), *args)
    assert r.returncode == 2
    assert r.stderr.strip().splitlines() == [line]


def test_unknown_engine_corrupt_file_and_inverted_range_against_the_file(blend, tmp_path):
    r = run_cli(str(blend), "--engine", "FOO", "-f", "1")
    assert r.returncode == 1 and r.stderr.startswith("error: unknown engine 'FOO'; available:")
    assert "RESTIR" in r.stderr and "CYCLES" in r.stderr and len(r.stderr.strip().splitlines()) == 1
    bad = tmp_path / "corrupt.blend"
    bad.write_bytes(b"BLENDER-v500" + os.urandom(2000))
    r = run_cli(str(bad), "-f", "1")
    assert r.returncode == 1 and r.stderr.strip().splitlines()[-1].startswith(f"error: cannot read {bad}")
    r = run_cli(str(blend), "-e", "0", "-a")  # the file's range is 1..2
    assert r.returncode == 1 and "before the file's frame start 1" in r.stderr
    r = run_cli(str(blend), "-s", "4", "-e", "5", "-o", str(tmp_path / "m_####"), "-F", "PNG", "--samples", "1")
    assert r.returncode == 0, r.stderr  # a range above the file's: moved, not clamped
    assert (tmp_path / "m_0004.png").exists() and (tmp_path / "m_0005.png").exists()
