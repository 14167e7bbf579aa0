"""Smoke test of the add-on on an older Blender LTS that the manifest names (run by scripts/test_lts.sh with that
bpy's venv; not collected by pytest): the add-on registers, F12 of the demo scene writes finite passes (denoised, as by
default), the CLI renders an animation of two frames and a single frame and exits promptly, and the built
extension installs into a throw-away user folder and renders from there. Prints one line per check and exits 0 when
all pass, 1 otherwise; exits without Blender's teardown (the bpy 4.5 module deadlocks in it, see restir_engine/cli.py)."""
from __future__ import annotations

import glob
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "scripts"), os.path.join(ROOT, "tests")]

CHECKS: list[tuple[str, bool, str]] = []


def check(name: str, ok: bool, detail: str = "") -> None:
    CHECKS.append((name, bool(ok), detail))
    print(f"{'ok  ' if ok else 'FAIL'} {name}" + (f": {detail}" if detail and not ok else ""), flush=True)


def cli(*args, timeout=300):
    t0 = time.perf_counter()
    try:
        r = subprocess.run([sys.executable, "-m", "restir_engine", *args], cwd=ROOT, capture_output=True, text=True,
                           timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, time.perf_counter() - t0
    return r, time.perf_counter() - t0


def main() -> int:
    import bpy
    import numpy as np

    import restir_engine
    from harness.render import render_scene
    from make_demo_scene import build_demo
    print(f"bpy {bpy.app.version_string}, numpy {np.__version__}", flush=True)
    restir_engine.register()
    check("register", hasattr(bpy.types.Scene, "restir"))
    build_demo(frames=3, resolution=(64, 36))
    scene = bpy.context.scene
    scene.render.engine = "RESTIR"
    scene.restir.samples = 2
    view_layer = bpy.context.view_layer
    view_layer.use_pass_z = view_layer.use_pass_normal = view_layer.use_pass_vector = True
    passes, _wall = render_scene(scene)
    finite = all(np.isfinite(a).all() for a in passes.values())
    from restir_engine.engine import LAST_FRAME_STATS
    check("F12 passes", finite and passes["Combined"][..., :3].mean() > 0 and LAST_FRAME_STATS.get("samples") == 2
          and {"Combined", "Depth", "Normal", "Vector"} <= set(passes), ", ".join(sorted(passes)))
    check("F12 denoised (Blender's own OIDN)", LAST_FRAME_STATS.get("denoise_seconds", 0) > 0, str(LAST_FRAME_STATS))
    with tempfile.TemporaryDirectory() as tmp:
        blend = os.path.join(tmp, "demo.blend")
        bpy.ops.wm.save_as_mainfile(filepath=blend, copy=True)
        r, seconds = cli(blend, "-o", os.path.join(tmp, "a_####"), "-F", "PNG", "-s", "1", "-e", "2", "-a")
        check("CLI -a exits", r is not None and r.returncode == 0, f"{seconds:.0f} s" if r is None else r.stderr[-500:])
        check("CLI -a frames", all(os.path.exists(os.path.join(tmp, f"a_{f:04d}.png")) for f in (1, 2)))
        r, seconds = cli(blend, "-o", os.path.join(tmp, "f_####"), "-F", "PNG", "-f", "2")
        check("CLI -f exits", r is not None and r.returncode == 0 and os.path.exists(os.path.join(tmp, "f_0002.png")),
              f"{seconds:.0f} s" if r is None else r.stderr[-500:])
        check_extension(tmp)
    restir_engine.unregister()
    failed = [name for name, ok, _d in CHECKS if not ok]
    print(f"{len(CHECKS) - len(failed)} of {len(CHECKS)} checks passed" + (f"; failed: {failed}" if failed else ""),
          flush=True)
    return 1 if failed else 0


def check_extension(tmp: str) -> None:
    """The zip scripts/build_extension.sh builds installs into a throw-away user folder and renders from there."""
    zips = glob.glob(os.path.join(ROOT, "dist", "restir_engine-*-linux_x64.zip"))
    if not zips:
        b = subprocess.run(["bash", os.path.join(ROOT, "scripts", "build_extension.sh")], capture_output=True,
                           text=True, cwd=ROOT)
        zips = glob.glob(os.path.join(ROOT, "dist", "restir_engine-*-linux_x64.zip"))
        if not zips:
            check("extension builds", False, b.stderr[-500:])
            return
    from extension_install import install_and_render
    try:
        result = install_and_render(sys.executable, zips[0], tmp)
    except subprocess.TimeoutExpired:
        check("extension installs and renders", False, "timed out")
        return
    check("extension installs and renders", result.returncode == 0 and result.rendered and
          result.module.startswith(os.path.join(tmp, "user")), result.output[-800:])
    check("extension renders in worker processes", result.processes == 2, result.output[-800:])

if __name__ == "__main__":
    try:
        code = main()
    except Exception as exc:  # noqa: BLE001 - one line, then the exit status
        import traceback
        traceback.print_exc()
        print(f"FAIL smoke: {type(exc).__name__}: {exc}", flush=True)
        code = 1
    sys.stdout.flush()
    os._exit(code)
