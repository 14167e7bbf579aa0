"""Render a .blend with the ReSTIR engine through the ``bpy`` module, like
``blender -b FILE.blend -E RESTIR [-o PATH] [-F FORMAT] [-s START] [-e END] (-a | -f N)``.

Usage: python -m restir_engine FILE.blend [-o PATH] [-F FORMAT] [-s N] [-e N] (-a | -f N)
       [--samples N] [--seed N] [--max-bounces N] [--percentage P]
Output path, format and frame range come from the file unless overridden. Exit status 1 on errors.
"""
from __future__ import annotations

import argparse
import os
import sys


def parse(argv):
    p = argparse.ArgumentParser(prog="python -m restir_engine", description=__doc__.split("\n\n")[0])
    p.add_argument("blend", help=".blend file to render")
    p.add_argument("-o", "--render-output", help="output path, '#' = frame digits (as blender -o)")
    p.add_argument("-F", "--render-format", help="image format, e.g. PNG, OPEN_EXR, OPEN_EXR_MULTILAYER, JPEG")
    p.add_argument("-s", "--frame-start", type=int)
    p.add_argument("-e", "--frame-end", type=int)
    g = p.add_mutually_exclusive_group()
    g.add_argument("-a", "--render-anim", action="store_true", help="render the frame range (default)")
    g.add_argument("-f", "--render-frame", type=int, help="render this one frame")
    p.add_argument("--samples", type=int)
    p.add_argument("--seed", type=int)
    p.add_argument("--max-bounces", type=int)
    p.add_argument("--percentage", type=int, help="resolution percentage")
    p.add_argument("--engine", default="RESTIR", help="render engine id (CYCLES for a reference render)")
    return p.parse_args(argv)


def _set_format(scene, fmt: str):
    settings = scene.render.image_settings
    fmt = fmt.upper()
    if fmt == "OPEN_EXR_MULTILAYER":
        if hasattr(settings, "media_type"):
            settings.media_type = "MULTI_LAYER_IMAGE"
        else:
            settings.file_format = "OPEN_EXR_MULTILAYER"
        return
    if fmt == "EXR":
        fmt = "OPEN_EXR"
    if hasattr(settings, "media_type"):
        settings.media_type = "IMAGE"
    settings.file_format = fmt


def main(argv=None) -> int:
    args = parse(sys.argv[1:] if argv is None else argv)
    if not os.path.isfile(args.blend):
        print(f"error: no such file: {args.blend}", file=sys.stderr)
        return 1
    import bpy

    from . import register
    if not hasattr(bpy.types.Scene, "restir"):
        register()
    bpy.ops.wm.open_mainfile(filepath=os.path.abspath(args.blend))
    scene = bpy.context.scene
    scene.render.engine = args.engine
    if args.render_output:
        out = args.render_output
        scene.render.filepath = out if out.startswith("//") else os.path.abspath(out) + ("/" if out.endswith("/") else "")
    if args.render_format:
        _set_format(scene, args.render_format)
    if args.frame_start is not None:
        scene.frame_start = args.frame_start
    if args.frame_end is not None:
        scene.frame_end = args.frame_end
    if args.render_frame is not None:
        scene.frame_start = scene.frame_end = args.render_frame
    if args.percentage is not None:
        scene.render.resolution_percentage = args.percentage
    for opt, attr in ((args.samples, "samples"), (args.seed, "seed"), (args.max_bounces, "max_bounces")):
        if opt is not None:
            setattr(scene.restir, attr, opt)
            if args.engine == "CYCLES" and hasattr(scene.cycles, attr):
                setattr(scene.cycles, attr, opt)
    if scene.camera is None:
        print("error: the scene has no active camera; add one (Scene Properties > Camera)", file=sys.stderr)
        return 1
    try:
        bpy.ops.render.render(animation=True)
    except RuntimeError as exc:
        print(f"error: render failed: {exc}", file=sys.stderr)
        return 1
    for frame in range(scene.frame_start, scene.frame_end + 1, max(1, scene.frame_step)):
        print("Saved:", scene.render.frame_path(frame=frame))
    return 0


if __name__ == "__main__":
    sys.exit(main())
