"""The extension manifest passes Blender's own validator (blender_ext.py from the bpy wheel)."""
import glob
import os
import shutil
import subprocess
import sys
import tomllib

import bpy

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def test_manifest_validates_with_blenders_extension_tool(tmp_path):
    scripts = os.path.dirname(os.path.dirname(os.path.dirname(bpy.__file__)))  # .../bpy/<ver>/scripts
    ext = glob.glob(os.path.join(scripts, "addons_core", "bl_pkg", "cli", "blender_ext.py"))
    assert ext, "blender_ext.py not found in the bpy wheel"
    stage = tmp_path / "restir_engine"
    shutil.copytree(os.path.join(ROOT, "restir_engine"), stage, ignore=shutil.ignore_patterns("__pycache__"))
    shutil.copy(os.path.join(ROOT, "blender_manifest.toml"), stage)
    r = subprocess.run([sys.executable, ext[0], "validate", str(stage)], capture_output=True, text=True, check=False)
    assert r.returncode == 0, r.stdout + r.stderr


def test_manifest_wheels_match_the_pinned_embreex():
    with open(os.path.join(ROOT, "blender_manifest.toml"), "rb") as f:
        manifest = tomllib.load(f)
    with open(os.path.join(ROOT, "requirements.txt")) as f:
        pinned = next(line.split("==")[1].strip() for line in f if line.startswith("embreex=="))
    assert manifest["wheels"] and all(f"embreex-{pinned}-" in w for w in manifest["wheels"])
    assert "numpy" not in " ".join(manifest["wheels"])  # Blender ships numpy
    # Python 3.11 (Blender 4.2-5.0) and 3.13 (5.1-5.2 LTS) wheels for every platform, and both venvs pin the same
    for tag in ("cp311", "cp313"):
        for plat in ("manylinux", "win_amd64", "macosx_13_0_arm64", "macosx_13_0_x86_64"):
            assert any(f"-{tag}-{tag}-" in w and plat in w for w in manifest["wheels"]), (tag, plat)
    with open(os.path.join(ROOT, "requirements-py313.txt")) as f:
        assert f"embreex=={pinned}\n" in f.read()
    assert manifest["blender_version_max"] >= "5.3.0"  # 5.2 LTS installs


def test_license_file_matches_the_manifest():
    with open(os.path.join(ROOT, "blender_manifest.toml"), "rb") as f:
        manifest = tomllib.load(f)
    assert manifest["license"] == ["SPDX:GPL-3.0-or-later"]
    with open(os.path.join(ROOT, "LICENSE")) as f:
        head = f.read(300)
    assert "GNU GENERAL PUBLIC LICENSE" in head and "Version 3" in head


def test_core_never_imports_bpy():
    for path in glob.glob(os.path.join(ROOT, "restir_engine", "core", "**", "*.py"), recursive=True):
        with open(path) as f:
            text = f.read()
        assert "import bpy" not in text and "from bpy" not in text, path
