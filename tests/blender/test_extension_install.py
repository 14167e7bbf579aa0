"""The extension as a user gets it: scripts/build_extension.sh builds the zips, Blender's extension tool validates
the Linux zip, and a fresh Blender process (the bpy module, with a throw-away user folder) installs it with
bpy.ops.extensions.package_install_files, enables it and renders a small frame with the engine loaded from the
installed copy, not from this checkout. Runs on the Python of the current venv (3.11 / Blender 5.0 or 3.13 /
Blender 5.2 LTS)."""
import glob
import os
import subprocess
import sys
import textwrap

import bpy
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

INSTALL_AND_RENDER = textwrap.dedent("""
    import os, sys
    import bpy
    zip_path, out = sys.argv[-2], sys.argv[-1]
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default", enable_on_install=True)
    mod = next(m for name, m in sys.modules.items() if name.endswith(".restir_engine"))
    print("MODULE", mod.__file__)
    scene = bpy.context.scene
    bpy.ops.mesh.primitive_plane_add(size=4)
    bpy.ops.object.light_add(type="POINT", location=(0, 0, 2))
    bpy.context.active_object.data.energy = 200
    bpy.ops.object.camera_add(location=(0, -4, 3), rotation=(0.9, 0, 0))
    scene.camera = bpy.context.active_object
    scene.render.engine = "RESTIR"
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 32, 24, 100
    scene.restir.samples = 2
    scene.render.filepath = out
    scene.render.image_settings.file_format = "PNG"
    bpy.ops.render.render(write_still=True)
    print("RENDERED", os.path.exists(out))
""")


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
    script = tmp_path / "install.py"
    script.write_text(INSTALL_AND_RENDER)
    env = dict(os.environ, BLENDER_USER_RESOURCES=str(tmp_path / "user"), PYTHONPATH="")
    out = tmp_path / "frame.png"
    p = subprocess.run([sys.executable, str(script), zips[0], str(out)], capture_output=True, text=True, env=env,
                       cwd=str(tmp_path), check=False, timeout=600)
    assert p.returncode == 0, p.stdout[-3000:] + p.stderr[-3000:]
    module = next(line.split(" ", 1)[1] for line in p.stdout.splitlines() if line.startswith("MODULE"))
    assert module.startswith(str(tmp_path / "user")), module  # the installed copy, not the checkout
    assert "RENDERED True" in p.stdout and out.exists()
