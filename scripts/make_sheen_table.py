"""Measure Cycles' Sheen BSDF (Microfiber) directional albedo R(μo, roughness) and store it as
restir_engine/core/materials/data/sheen_albedo.json (core/materials/nodes/ops_layers.sheen_albedo reads it).

A white sphere of the lobe in a uniform white world of radiance 1, direct light only (so a pixel is the lobe's
albedo toward its view), seen by an orthographic camera: a pixel at normalized radius ρ sees μo = √(1 - ρ²). Pixels
are averaged in bins of μo around each node. Run with the Blender 5.2 venv:
    .venv313/bin/python scripts/make_sheen_table.py [--samples 512] [--size 384]
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [os.path.join(ROOT, "tests"), ROOT, os.path.join(ROOT, "scripts")]

ROUGHNESS = [0.0, 0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.75, 0.9, 1.0]
MU = [round(0.1 + 0.05 * k, 2) for k in range(19)]  # 0.1 .. 1.0
OUT = os.path.join(ROOT, "restir_engine", "core", "materials", "data", "sheen_albedo.json")


def measure(rough: float, samples: int, size: int) -> list:
    import bpy
    import numpy as np
    from bpy_scenes import camera, configure_cycles, enable_nodes, render_passes, reset
    scene = reset()
    bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, location=(0, 0, 0), segments=256, ring_count=128)
    obj = bpy.context.active_object
    bpy.ops.object.shade_smooth()
    m = bpy.data.materials.new("Sheen")
    enable_nodes(m)
    nodes = m.node_tree.nodes
    nodes.remove(nodes["Principled BSDF"])
    sh = nodes.new("ShaderNodeBsdfSheen")
    sh.distribution = "MICROFIBER"
    sh.inputs["Color"].default_value = (1, 1, 1, 1)
    sh.inputs["Roughness"].default_value = rough
    m.node_tree.links.new(sh.outputs[0], nodes["Material Output"].inputs["Surface"])
    obj.data.materials.append(m)
    camera((0, -6, 0), (math.radians(90), 0, 0), ortho_scale=2.0)
    world = scene.world or bpy.data.worlds.new("World")
    scene.world = world
    enable_nodes(world)
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (1, 1, 1, 1)
    bg.inputs["Strength"].default_value = 1.0
    scene.render.resolution_x = scene.render.resolution_y = size
    configure_cycles(scene, samples, 0, 0)
    scene.cycles.filter_width = 0.01
    img = render_passes(scene)["Combined"][..., :3].mean(axis=2)
    yy, xx = np.mgrid[0:size, 0:size] + 0.5
    rho = np.hypot(xx - size / 2, yy - size / 2) / (size / 2)
    mu = np.sqrt(np.clip(1 - rho ** 2, 0, 1))
    inside = rho < 0.998
    return [float(img[inside & (np.abs(mu - m0) < 0.0125)].mean()) for m0 in MU]


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=512)
    ap.add_argument("--size", type=int, default=384)
    args = ap.parse_args()
    import bpy
    table = [measure(r, args.samples, args.size) for r in ROUGHNESS]
    for r, row in zip(ROUGHNESS, table):
        print(r, [round(v, 4) for v in row])
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    with open(OUT, "w") as f:
        json.dump({"what": "Cycles' Sheen BSDF (Microfiber) directional albedo R(mu_o, roughness), measured by "
                           "scripts/make_sheen_table.py", "bpy": bpy.app.version_string, "roughness": ROUGHNESS,
                   "mu": MU, "albedo": [[round(v, 5) for v in row] for row in table]}, f, indent=1)
        f.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
