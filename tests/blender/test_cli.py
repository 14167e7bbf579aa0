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


def test_denoise_option(blend, tmp_path):
    """--no-denoise writes the raw estimate, --denoise the denoised one: with the Denoising Data passes on, the
    denoised frame's Noisy Image is the --no-denoise frame's Combined bit for bit, and its Combined differs."""
    import numpy as np
    from harness.render import read_exr
    data = ("--python-expr", "import bpy; bpy.context.scene.view_layers[0].restir.use_pass_denoising_data = True")

    def render(flag):
        out = tmp_path / flag / "x_####"
        r = run_cli(str(blend), "-o", str(out), "-F", "OPEN_EXR_MULTILAYER", "-f", "1", flag, *data)
        assert r.returncode == 0, r.stderr
        return read_exr(str(tmp_path / flag / "x_0001.exr"))

    raw, den = render("--no-denoise"), render("--denoise")
    assert "Noisy Image" not in raw
    np.testing.assert_array_equal(den["Noisy Image"], raw["Combined"])
    assert np.abs(den["Combined"][..., :3] - raw["Combined"][..., :3]).max() > 1e-3


def test_worker_processes_close_before_the_cli_exits(blend, tmp_path):
    """A frame rendered by two worker processes: the CLI closes them and their shared memory before it exits (else
    Python's resource tracker reports leaked segments on stderr, as it did)."""
    expr = ("import bpy; s = bpy.context.scene; s.render.resolution_x, s.render.resolution_y = 320, 240; "
            "s.restir.processes = 2")
    r = run_cli(str(blend), "-o", str(tmp_path / "w_####"), "-F", "PNG", "-f", "1", "--python-expr", expr)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "w_0001.png").exists()
    assert "leaked" not in r.stderr, r.stderr[-800:]


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


FRAMES_SEEN = ("--python-expr", "import bpy; bpy.app.handlers.frame_change_post.append("
               "lambda sc, *a: print('frame set', sc.frame_current, flush=True))")


def test_single_frame_never_prerolls_and_a_chunk_does(blend, tmp_path):
    """docs/USAGE.md: ``-f N`` renders as F12 (no preroll); a chunk ``-s S -e E -a`` prerolls (positive control)."""
    common = ("--python-expr", "import bpy; bpy.context.scene.restir.direct_method = 'RESTIR'", *FRAMES_SEEN,
              "-o", str(tmp_path / "p_####"), "-F", "PNG")
    r = run_cli(str(blend), *common, "-f", "5")
    assert r.returncode == 0, r.stderr
    # frame 4 is evaluated for the motion into frame 5; a preroll of 3 would render frames 2, 3 and 4
    assert not any(f"frame set {f}" in r.stdout for f in (2, 3)), r.stdout
    assert r.stdout.count("Saved:") == 1 and (tmp_path / "p_0005.png").exists()
    r = run_cli(str(blend), *common, "-s", "5", "-e", "5", "-a")
    assert r.returncode == 0, r.stderr
    assert all(f"frame set {f}" in r.stdout for f in (2, 3)), r.stdout


def test_ctrl_c_stops_the_job_writes_nothing_and_exits_130(blend, tmp_path):
    """A farm must not count an interrupted frame as done: Ctrl+C during frame 2 of 3 leaves frame 1 saved,
    no file for frames 2 and 3, exit status 130, within seconds."""
    import signal
    import time
    out = tmp_path / "c_####"
    proc = subprocess.Popen([sys.executable, "-m", "restir_engine", str(blend), "-o", str(out), "-F", "PNG",
                             "-s", "1", "-e", "3", "-a", "--samples", "100"], cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    try:
        first = proc.stdout.readline()
        while first and not first.startswith("Saved:"):
            first = proc.stdout.readline()
        assert first.startswith("Saved:") and first.strip().endswith("c_0001.png"), proc.stderr.read()
        time.sleep(0.5)  # frame 2 is rendering now
        workers = _workers_of(proc.pid)
        proc.send_signal(signal.SIGINT)
        t0 = time.perf_counter()
        rest, err = proc.communicate(timeout=60)
        stopped = time.perf_counter() - t0
    finally:
        proc.kill()
    assert proc.returncode == 130, (rest, err)
    assert "interrupted" in err and stopped < 5.0
    assert "leaked" not in err, err  # the workers' shared memory was unlinked before the exit
    assert not _running(workers), "render workers outlived the interrupted job"
    assert (tmp_path / "c_0001.png").exists()
    assert not (tmp_path / "c_0002.png").exists() and not (tmp_path / "c_0003.png").exists()
    assert "Saved:" not in rest


def test_a_texture_that_is_a_pipe_and_a_folder_given_as_the_file(blend, tmp_path):
    """An image whose file is a FIFO would block the export for ever (Blender opens it to learn its size): the
    render goes on with the texture magenta and a warning. A folder given as the .blend gets its own line."""
    fifo = tmp_path / "pipe.png"
    os.mkfifo(fifo)
    image = bpy.data.images.new("Piped", 4, 4)
    image.source = "FILE"
    image.filepath = str(fifo)
    material = bpy.data.materials["White"]
    tex = material.node_tree.nodes.new("ShaderNodeTexImage")
    tex.image = image
    shader = next(n for n in material.node_tree.nodes if n.type in {"BSDF_DIFFUSE", "BSDF_PRINCIPLED"})
    material.node_tree.links.new(tex.outputs["Color"], shader.inputs[0])
    path = tmp_path / "piped.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), copy=True)
    r = run_cli(str(path), "-f", "1", "-o", str(tmp_path / "pipe_####"), "-F", "PNG")
    assert r.returncode == 0, r.stderr
    assert "not a regular file" in r.stdout + r.stderr
    assert (tmp_path / "pipe_0001.png").exists()
    r = run_cli(str(tmp_path), "-f", "1")
    assert r.returncode == 1 and r.stderr.strip() == f"error: {tmp_path} is a folder, not a .blend file"



def _workers_of(pid: int) -> list[int]:
    """The spawned render workers (multiprocessing's spawn_main) whose parent is ``pid``."""
    out = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            stat = open(f"/proc/{entry}/stat").read()
            cmd = open(f"/proc/{entry}/cmdline", "rb").read()
        except OSError:
            continue
        if int(stat.rsplit(")", 1)[1].split()[1]) == pid and b"spawn_main" in cmd:
            out.append(int(entry))
    return out


def _running(pids) -> list[int]:
    """Those of ``pids`` still running (not gone, not zombies)."""
    out = []
    for p in pids:
        try:
            state = open(f"/proc/{p}/stat").read().rsplit(")", 1)[1].split()[0]
        except OSError:
            continue
        if state != "Z":
            out.append(p)
    return out
