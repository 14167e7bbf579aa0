"""Install the built extension zip into a throw-away user folder in a fresh Blender process (the bpy module of
the Python given) and render a small frame with the engine loaded from the installed copy. Shared by
tests/blender/test_extension_install.py and the LTS smoke test (tests/lts_smoke.py)."""
from __future__ import annotations

import os
import subprocess
from dataclasses import dataclass

# the script run in the fresh process; it exits without Blender's teardown (bpy 4.5 deadlocks in it)
INSTALL_AND_RENDER = """
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
print("RENDERED", os.path.exists(out), flush=True)
# a frame of 2 chunks in 2 worker processes, which load the installed copy's core without the add-on
scene.render.resolution_x, scene.render.resolution_y = 256, 256
scene.restir.samples, scene.restir.processes = 1, 2
bpy.ops.render.render()
team = sys.modules[mod.__name__ + ".core.parallel.processes"]._TEAM
print("PROCESSES", team.size if team is not None and team.alive() else 0, flush=True)
os._exit(0)
"""


@dataclass
class Installed:
    returncode: int
    module: str     # the file the engine was imported from ('' when it was not)
    rendered: bool  # the frame was written
    output: str     # the process's stdout and stderr
    processes: int  # worker processes alive after the second frame (0: none)


def install_and_render(python: str, zip_path: str, folder: str, timeout: float = 600) -> Installed:
    """Run INSTALL_AND_RENDER with ``python``, the user folder and the frame under ``folder``."""
    script = os.path.join(folder, "install.py")
    with open(script, "w") as f:
        f.write(INSTALL_AND_RENDER)
    out = os.path.join(folder, "frame.png")
    env = dict(os.environ, BLENDER_USER_RESOURCES=os.path.join(folder, "user"), PYTHONPATH="")
    p = subprocess.run([python, script, zip_path, out], capture_output=True, text=True, env=env, cwd=folder,
                       check=False, timeout=timeout)
    module = next((ln.split(" ", 1)[1] for ln in p.stdout.splitlines() if ln.startswith("MODULE")), "")
    procs = next((int(ln.split()[1]) for ln in p.stdout.splitlines() if ln.startswith("PROCESSES")), 0)
    return Installed(p.returncode, module, "RENDERED True" in p.stdout and os.path.exists(out), p.stdout + p.stderr,
                     procs)
