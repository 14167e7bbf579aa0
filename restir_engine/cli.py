"""Render a .blend with the ReSTIR engine through the ``bpy`` module, like
``blender -b FILE.blend -E RESTIR [-o PATH] [-F FORMAT] [-s START] [-e END] (-a | -f N)``.

Usage: python -m restir_engine FILE.blend [-E ENGINE] [--python-expr EXPR] [-o PATH] [-F FORMAT] [-s N] [-e N]
       (-a | -f N) [--samples N] [--seed N] [--max-bounces N] [--percentage P] [--[no-]denoise] [-t N]
Output path, format and frame range come from the file unless overridden. A bad argument gets one line
``error: ...`` and exit status 2; an unreadable file, an unknown engine or a failed render exit status 1.
"""
from __future__ import annotations

import argparse
import os
import re
import signal
import sys


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (``error: ...``, exit status 2)."""

    def error(self, message):
        self.exit(2, f"error: {message}\n")


def _at_least(low: int):
    """An argparse type: an integer not below ``low``."""
    def check(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"must be an integer, not {text!r}") from None
        if value < low:
            raise argparse.ArgumentTypeError(f"must be at least {low}, not {value}")
        return value
    return check


def parse(argv):
    p = _Parser(prog="python -m restir_engine", description=__doc__.split("\n\n")[0])
    p.add_argument("blend", help=".blend file to render")
    p.add_argument("-o", "--render-output", help="output path, '#' = frame digits (as blender -o)")
    p.add_argument("-F", "--render-format", help="image format, e.g. PNG, OPEN_EXR, OPEN_EXR_MULTILAYER, JPEG")
    p.add_argument("-s", "--frame-start", type=_at_least(0))
    p.add_argument("-e", "--frame-end", type=_at_least(0))
    g = p.add_mutually_exclusive_group()
    g.add_argument("-a", "--render-anim", action="store_true", help="render the frame range (default)")
    g.add_argument("-f", "--render-frame", type=_at_least(0), help="render this one frame")
    p.add_argument("--samples", type=_at_least(1))
    p.add_argument("--seed", type=_at_least(0))
    p.add_argument("--max-bounces", type=_at_least(0))
    p.add_argument("--percentage", type=_at_least(1), help="resolution percentage")
    p.add_argument("--denoise", action=argparse.BooleanOptionalAction, default=None,
                   help="denoise the frames (Render Properties > Sampling > Denoise; default: the file's setting)")
    p.add_argument("-t", "--threads", type=_at_least(0),
                   help="threads to render with, 0 = every logical core (as blender -t; default: the file's)")
    p.add_argument("-E", "--engine", default="RESTIR", help="render engine id (CYCLES for a reference render)")
    p.add_argument("--python-expr", action="append", default=[],
                   help="Python run after the file is loaded, before rendering (as blender's --python-expr)")
    args = p.parse_args(argv)
    if args.frame_start is not None and args.frame_end is not None and args.frame_end < args.frame_start:
        p.error(f"frame end {args.frame_end} is before frame start {args.frame_start}")
    return args


def _set_format(scene, fmt: str):
    settings = scene.render.image_settings
    fmt = fmt.upper()
    from .compat import set_output_format  # imports bpy: only once a render is asked for
    set_output_format(settings, "OPEN_EXR" if fmt == "EXR" else fmt)


def main(argv=None) -> int:
    args = parse(sys.argv[1:] if argv is None else argv)
    if os.path.isdir(args.blend):
        print(f"error: {args.blend} is a folder, not a .blend file", file=sys.stderr)
        return 1
    if not os.path.isfile(args.blend):
        print(f"error: no such file: {args.blend}", file=sys.stderr)
        return 1
    import bpy

    from . import register
    if not hasattr(bpy.types.Scene, "restir"):
        register()
    try:
        bpy.ops.wm.open_mainfile(filepath=os.path.abspath(args.blend))
    except RuntimeError as exc:
        reason = str(exc).strip().splitlines()[-1].split("failed: ")[-1]
        print(f"error: cannot read {args.blend}: {reason}", file=sys.stderr)
        return 1
    for expr in args.python_expr:
        try:
            exec(compile(expr, "<--python-expr>", "exec"), {"bpy": bpy, "__name__": "__main__"})
        except Exception as exc:  # noqa: BLE001 - the user's expression; report it in one line
            print(f"error: --python-expr failed: {type(exc).__name__}: {exc}", file=sys.stderr)
            return 1
    scene = bpy.context.scene
    try:
        scene.render.engine = args.engine
    except TypeError as exc:  # the message lists the registered engines: "... not found in ('A', 'B')"
        listed = re.search(r"not found in \((.*)\)", str(exc))
        known = listed.group(1).replace("'", "") if listed else "see Blender's Render Properties"
        print(f"error: unknown engine {args.engine!r}; available: {known}", file=sys.stderr)
        return 1
    if args.render_output:
        out = args.render_output
        scene.render.filepath = out if out.startswith("//") else os.path.abspath(out) + ("/" if out.endswith("/") else "")
    if args.render_format:
        _set_format(scene, args.render_format)
    if args.frame_end is not None and args.frame_end < (args.frame_start if args.frame_start is not None
                                                        else scene.frame_start):
        print(f"error: frame end {args.frame_end} is before the file's frame start {scene.frame_start}",
              file=sys.stderr)
        return 1
    if args.frame_start is not None and args.frame_end is None and args.frame_start > scene.frame_end:
        print(f"error: frame start {args.frame_start} is after the file's frame end {scene.frame_end}",
              file=sys.stderr)
        return 1
    if args.frame_start is not None:  # set the end first when moving the range up: Blender clamps start <= end
        if args.frame_end is not None and args.frame_end > scene.frame_end:
            scene.frame_end = args.frame_end
        scene.frame_start = args.frame_start
    if args.frame_end is not None:
        scene.frame_end = args.frame_end
    if args.render_frame is not None:
        scene.frame_start = scene.frame_end = args.render_frame
    if args.percentage is not None:
        scene.render.resolution_percentage = args.percentage
    if args.threads is not None:  # Render Properties > Performance > Threads, read by the engine
        scene.render.threads_mode = "FIXED" if args.threads > 0 else "AUTO"
        if args.threads > 0:
            scene.render.threads = min(args.threads, 1024)
    for opt, attr in ((args.samples, "samples"), (args.seed, "seed"), (args.max_bounces, "max_bounces"),
                      (args.denoise, "use_denoising")):
        if opt is not None:
            setattr(scene.restir, attr, opt)
            if args.engine == "CYCLES" and hasattr(scene.cycles, attr):
                setattr(scene.cycles, attr, opt)
    if scene.camera is None:
        print("error: the scene has no active camera; add one (Scene Properties > Camera)", file=sys.stderr)
        return 1
    _stop_on_interrupt()
    try:
        if args.render_frame is not None and not scene.render.is_movie_format:
            _render_still(bpy, scene, args.render_frame)
        else:
            _render_animation(bpy, scene)
    except RuntimeError as exc:
        print(f"error: render failed: {exc}", file=sys.stderr)
        return 1
    return 0


EXIT_INTERRUPTED = 130  # the shell's status for a process stopped by Ctrl+C (128 + SIGINT)


def _stop_on_interrupt() -> None:
    """Ctrl+C stops the job at once with status 130, writing nothing more: the frame being rendered is not saved
    and no later frame starts. (Blender, left to Python's default, swallows the KeyboardInterrupt inside the
    render callback, saves the unfinished frame and renders on, and the process exits 0.)"""
    def stop(_signum, _frame):
        os.write(2, b"error: interrupted (Ctrl+C): the frame being rendered was not saved\n")
        from .core.parallel import processes
        processes.abandon()  # no worker and no shared memory left behind
        os._exit(EXIT_INTERRUPTED)
    signal.signal(signal.SIGINT, stop)


def _render_still(bpy, scene, frame: int) -> None:
    """Render one frame as Blender's F12 does (no preroll: docs/USAGE.md) and save it under the name an
    animation render gives that frame (``render.frame_path``)."""
    scene.frame_set(frame)
    bpy.ops.render.render(write_still=False)
    path = scene.render.frame_path(frame=frame)
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    bpy.data.images["Render Result"].save_render(filepath=path, scene=scene)
    print("Saved:", path, flush=True)


def _render_animation(bpy, scene) -> None:
    """Render the frame range through Blender's animation path, printing each frame's file once it is written."""
    def saved(scene_written, *_args):
        print("Saved:", scene_written.render.frame_path(frame=scene_written.frame_current), flush=True)
    bpy.app.handlers.render_write.append(saved)
    try:
        bpy.ops.render.render(animation=True)
    finally:
        bpy.app.handlers.render_write.remove(saved)

def _end_workers() -> None:
    """Close the render worker processes and their shared memory (``os._exit`` skips the atexit hook that would,
    and Python's resource tracker would then report the segments as leaked)."""
    from .core.parallel import processes
    try:
        processes.shutdown()
    except Exception as exc:  # noqa: BLE001 - the frames are written; a failed close must not change the status
        print(f"warning: render workers did not close cleanly: {exc}", file=sys.stderr)


def run(argv=None) -> None:
    """``main`` as a process: exit with its status straight after the output is flushed, without Blender's
    teardown (it writes nothing a render needs, and the bpy 4.5 module deadlocks in it: its delayed-close thread
    waits on a condition variable that a static destructor destroys)."""
    try:
        code = main(argv)
    except SystemExit as exc:  # argparse's errors
        code = exc.code if isinstance(exc.code, int) else 1
    _end_workers()
    sys.stdout.flush()
    sys.stderr.flush()
    os._exit(code)


if __name__ == "__main__":
    run()
