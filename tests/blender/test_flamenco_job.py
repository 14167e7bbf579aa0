"""The Flamenco job type (scripts/flamenco/restir_render.js) end to end: compiled under Node.js with a stand-in for
Flamenco's job-authoring API (tests/flamenco_stub.js), its tasks' commands run through our bpy CLI (which takes
blender's `-E` and `--python-expr`), and the frames of the chunked job equal a sequential render of the same
animation exactly (temporal ReSTIR history rebuilt by preroll inside each chunk)."""
import json
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest
from bpy_scenes import configure_restir, cornell_box

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
JOB = os.path.join(ROOT, "scripts", "flamenco", "restir_render.js")
STUB = os.path.join(ROOT, "tests", "flamenco_stub.js")
FRAMES = 6


def compile_job(settings: dict) -> list:
    node = shutil.which("node") or shutil.which("nodejs")
    if node is None:
        pytest.skip("Node.js is not installed")
    r = subprocess.run([node, STUB, JOB, json.dumps(settings)], capture_output=True, text=True, check=True)
    return json.loads(r.stdout)


def run_cli(blend: str, args: list) -> None:
    r = subprocess.run([sys.executable, "-m", "restir_engine", blend] + args, capture_output=True, text=True,
                       cwd=ROOT, check=False, timeout=600)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]


def animated_blend(path: str) -> str:
    import bpy
    scene = cornell_box("AREA", (24, 24))
    cam = scene.camera
    for f in range(1, FRAMES + 1):
        cam.location.x = 0.03 * (f - 1)
        cam.keyframe_insert("location", frame=f)
    configure_restir(scene, 1, 0, integrator="RESTIR", direct_method="RESTIR", spatial_neighbors=2)
    scene.frame_start, scene.frame_end = 1, FRAMES
    bpy.ops.wm.save_as_mainfile(filepath=path)
    return path


def test_chunked_flamenco_job_equals_sequential_render(addon, tmp_path):
    from harness.render import read_exr
    blend = animated_blend(str(tmp_path / "anim.blend"))
    run_cli(blend, ["-E", "RESTIR", "--python-expr", "import bpy; bpy.context.scene.restir.preroll_frames = 0",
                    "-o", str(tmp_path / "seq" / "f_####"), "-F", "OPEN_EXR_MULTILAYER", "-s", "1", "-e",
                    str(FRAMES), "-a"])
    tasks = compile_job({"blendfile": blend, "frames": f"1-{FRAMES}", "chunk_size": 4,
                         "render_output_path": str(tmp_path / "job" / "f_####"), "format": "OPEN_EXR_MULTILAYER"})
    assert [t["name"] for t in tasks] == ["render-1-4", "render-5-6"]
    for task in tasks:
        (cmd,) = task["commands"]
        assert cmd["type"] == "blender-render" and cmd["params"]["exe"] == "{blender}"
        assert cmd["params"]["args"][:2] == ["-E", "RESTIR"] and cmd["params"]["args"][-1] == "-a"
        run_cli(cmd["params"]["blendfile"], cmd["params"]["args"])
    moved = 0
    for f in range(1, FRAMES + 1):
        seq = read_exr(str(tmp_path / "seq" / f"f_{f:04d}.exr"))["Combined"]
        job = read_exr(str(tmp_path / "job" / f"f_{f:04d}.exr"))["Combined"]
        assert np.array_equal(seq, job), f"frame {f} differs from the sequential render"
        moved += f > 1 and not np.array_equal(seq, read_exr(str(tmp_path / "seq" / "f_0001.exr"))["Combined"])
    assert moved == FRAMES - 1  # the frames are not all alike: the comparison can see a change
    # and it sees missing history: the second chunk without preroll differs from the sequential frames
    (late,) = [t for t in compile_job({"blendfile": blend, "frames": f"1-{FRAMES}", "chunk_size": 4, "preroll": 0,
                                       "render_output_path": str(tmp_path / "cold" / "f_####"),
                                       "format": "OPEN_EXR_MULTILAYER"}) if t["name"] == "render-5-6"]
    run_cli(blend, late["commands"][0]["params"]["args"])
    assert not np.array_equal(read_exr(str(tmp_path / "seq" / "f_0005.exr"))["Combined"],
                              read_exr(str(tmp_path / "cold" / "f_0005.exr"))["Combined"])


def test_job_preroll_setting_is_capped_and_starts_at_zero():
    tasks = compile_job({"blendfile": "/x.blend", "frames": "1-10", "chunk_size": 4, "preroll": 3,
                         "render_output_path": "/out/f_####", "format": "PNG"})
    prerolls = [int(t["commands"][0]["params"]["args"][3].rsplit("=", 1)[1]) for t in tasks]
    assert prerolls == [0, 3, 3]
    tasks = compile_job({"blendfile": "/x.blend", "frames": "1-10", "chunk_size": 4,
                         "render_output_path": "/out/f_####", "format": "PNG"})
    assert [int(t["commands"][0]["params"]["args"][3].rsplit("=", 1)[1]) for t in tasks] == [0, 4, 8]
