"""Holdout against Cycles (same bpy, CPU): a sphere with a Holdout shader and a cube whose object is set to
Holdout (Object > Visibility), in front of a lit floor, 1 bounce: per 4 x 4 image cell, the colour and the alpha
of Combined within the materials tests' bound (tests/stats.py); with the holdout ignored (the sphere's shader a
black diffuse, the cube opaque), the alpha must fail."""
import math

import bpy
import numpy as np
from bpy_scenes import camera, configure_cycles, configure_restir, diffuse, light, plane, render_passes, reset
from cycles_reference import cycles_cells
from stats import assert_cells_match, image_cells

SIZE = (64, 48)
MASKS = image_cells(SIZE, 4)


def _scene(holdout=True):
    scene = reset()
    plane("Floor", 8.0, (0, 0, 0), material=diffuse("HoldFloor", (0.6, 0.6, 0.6)))
    wall = plane("Wall", 8.0, (0, 2.0, 2.0), (math.radians(90), 0, 0), material=diffuse("HoldWall", (0.4, 0.5, 0.7)))
    wall.name = "Wall"
    mat = bpy.data.materials.new("HoldSphere")
    mat.use_nodes = True
    tree = mat.node_tree
    tree.nodes.remove(tree.nodes["Principled BSDF"])
    shader = tree.nodes.new("ShaderNodeHoldout" if holdout else "ShaderNodeBsdfDiffuse")
    if not holdout:
        shader.inputs["Color"].default_value = (0, 0, 0, 1)
    tree.links.new(shader.outputs[0], tree.nodes["Material Output"].inputs["Surface"])
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(-0.6, 0.0, 0.5), segments=24, ring_count=12)
    bpy.context.active_object.data.materials.append(mat)
    bpy.ops.mesh.primitive_cube_add(size=0.7, location=(0.7, 0.2, 0.35), rotation=(0, 0, 0.5))
    cube = bpy.context.active_object
    cube.data.materials.append(diffuse("HoldCube", (0.8, 0.3, 0.2)))
    cube.is_holdout = holdout
    light("AREA", (-1.0, -1.5, 3.0), (math.radians(30), 0, 0), energy=300.0, size=1.5)
    camera((0, -3.5, 1.5), (math.radians(75), 0, 0), lens=35)
    scene.render.resolution_x, scene.render.resolution_y = SIZE
    return scene


def _reduce(images):
    im = np.asarray(images, np.float64)[:, ::-1]
    rgb, alpha = im[..., :3].mean(axis=3), im[..., 3]
    return np.concatenate([np.stack([x[:, m].mean(axis=1) for m in MASKS], axis=1) for x in (rgb, alpha)], axis=1)


def _ours(build, reps=8):
    scene = build()
    out = []
    for seed in range(reps):
        configure_restir(scene, 32, 1, seed, integrator="PATH")
        out.append(render_passes(scene)["Combined"][..., :4])
    return _reduce(np.array(out))


def test_holdout_matches_cycles(addon):
    ours = _ours(_scene)
    ref = cycles_cells("holdout_b1", _scene, lambda sc, seed: configure_cycles(sc, 128, 1, seed),
                       lambda sc: render_passes(sc)["Combined"][..., :4], _reduce, 8, 128, 1)
    names = [f"{what} cell {k}" for what in ("colour", "alpha") for k in range(16)]
    seen = [i for i in range(32) if ref.mean(0)[i] > 0.02]
    assert_cells_match(ours[:, seen], ref[:, seen], [names[i] for i in seen])
    ignored = _ours(lambda: _scene(holdout=False), reps=4)
    alpha = slice(16, 32)
    assert (np.abs(ignored.mean(0)[alpha] - ref.mean(0)[alpha]) > 0.05).sum() >= 3, "ignoring the holdout passes"
