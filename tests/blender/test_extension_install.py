"""The extension as a user gets it: scripts/build_extension.sh builds the zips, Blender's extension tool validates
the Linux zip, and a fresh Blender process (the bpy module, with a throw-away user folder) installs it with
bpy.ops.extensions.package_install_files, enables it and renders a small frame with the engine loaded from the
installed copy, not from this checkout. Runs on the Python of the current venv (3.11 / Blender 5.0 or 3.13 /
Blender 5.2 LTS)."""
import glob
import os
import subprocess
import sys

import bpy
import pytest
from extension_install import install_and_render

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

def test_built_extension_validates_installs_and_renders(tmp_path):
    r = subprocess.run(["bash", os.path.join(ROOT, "scripts", "build_extension.sh")], capture_output=True, text=True,
                       cwd=ROOT, check=False)
    if r.returncode != 0 and "nor downloadable" in r.stderr:
        pytest.skip("embreex wheels neither cached nor downloadable here: " + r.stderr.strip().splitlines()[-1])
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    zips = glob.glob(os.path.join(ROOT, "dist", "restir_engine-*-linux_x64.zip"))
    assert len(zips) == 1, zips
    scripts = os.path.dirname(os.path.dirname(os.path.dirname(bpy.__file__)))
    ext = glob.glob(os.path.join(scripts, "addons_core", "bl_pkg", "cli", "blender_ext.py"))
    v = subprocess.run([sys.executable, ext[0], "validate", zips[0]], capture_output=True, text=True, check=False)
    assert v.returncode == 0, v.stdout + v.stderr
    result = install_and_render(sys.executable, zips[0], str(tmp_path))
    assert result.returncode == 0, result.output[-6000:]
    assert result.module.startswith(str(tmp_path / "user")), result.module  # the installed copy, not the checkout
    assert result.rendered
    assert result.processes == 2, result.output[-3000:]  # F12 in worker processes from the installed extension
