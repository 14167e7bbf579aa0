"""Shader AOVs against Cycles (same bpy, CPU): a colour AOV (a checker of object coordinates) and a value AOV (a
Noise) written by AOV Output nodes of two materials (a third material writes none), read from each engine's
multilayer EXR: per 4 x 4 pixel cell within 5 standard errors over the seeds + 0.5 % + 2e-3 (float32 and Cycles'
pixel filter table); power: without the second material's AOV outputs, the cells must fail."""
import math
import os
import tempfile

import bpy
import numpy as np
from bpy_scenes import camera, configure_cycles, configure_restir, diffuse, light, plane, reset

SIZE = (48, 32)


def _scene(drop=False):
    import node_graphs as ng
    scene = reset()
    vl = scene.view_layers[0]
    for name, kind in (("Tint", "COLOR"), ("Rough", "VALUE")):
        aov = vl.aovs.add()
        aov.name, aov.type = name, kind
    plane("Floor", 6.0, (0, 0, 0), material=diffuse("AovFloor", (0.5, 0.5, 0.5)))  # no AOV output: 0
    for k, (x, scale) in enumerate(((-0.6, 3.0), (0.6, 6.0))):
        mat = diffuse(f"AovMat{k}", (0.7, 0.7, 0.7))
        tree = mat.node_tree
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(x, 0.0, 0.5), segments=24, ring_count=12)
        bpy.context.active_object.data.materials.append(mat)
        if drop and k == 1:
            continue
        out = tree.nodes.new("ShaderNodeOutputAOV")
        out.aov_name = "Tint"
        chk = ng._node(tree, "ShaderNodeTexChecker")
        ng._set(chk, "Scale", scale)
        tree.links.new(ng._coords(tree, "Object"), chk.inputs["Vector"])
        tree.links.new(chk.outputs["Color"], out.inputs["Color"])
        nz = ng._node(tree, "ShaderNodeTexNoise")
        out2 = tree.nodes.new("ShaderNodeOutputAOV")
        out2.aov_name = "Rough"
        tree.links.new(nz.outputs["Fac"], out2.inputs["Value"])
    light("POINT", (0, -2, 3), (0, 0, 0), energy=100.0)
    camera((0, -3.2, 1.2), (math.radians(80), 0, 0), lens=35)
    scene.render.resolution_x, scene.render.resolution_y = SIZE
    return scene


def _aovs(scene):
    import OpenEXR
    from harness.render import use_multilayer_exr
    use_multilayer_exr(scene)
    with tempfile.TemporaryDirectory() as tmp:
        scene.render.filepath = os.path.join(tmp, "aov.exr")
        bpy.ops.render.render(write_still=True)
        out = {}
        for part in OpenEXR.File(scene.render.filepath).parts:
            for name, ch in part.channels.items():
                bits = name.split(".")
                if len(bits) >= 2 and bits[1] in ("Tint", "Rough"):
                    px = np.asarray(ch.pixels, np.float32)[::-1]
                    out[bits[1]] = px if px.ndim == 3 else px[..., None]
    return out


def _cells(img):
    h, w, c = img.shape
    return img.reshape(h // 4, 4, w // 4, 4, c).mean(axis=(1, 3)).ravel()


def _runs(build, configure, reps):
    rows = []
    for seed in range(reps):
        scene = build()
        configure(scene, seed)
        got = _aovs(scene)
        rows.append(np.concatenate([_cells(got["Tint"][..., :3]), _cells(got["Rough"][..., :1])]))
    return np.array(rows, np.float64)


def test_shader_aovs_match_cycles(addon):
    ours = _runs(_scene, lambda sc, s: configure_restir(sc, 16, 0, s, integrator="PATH"), 6)
    ref = _runs(_scene, lambda sc, s: configure_cycles(sc, 64, 0, s), 3)
    se = np.sqrt(ours.var(0, ddof=1) / len(ours) + ref.var(0, ddof=1) / len(ref))
    bad = np.abs(ours.mean(0) - ref.mean(0)) > 5 * se + 0.005 * np.abs(ref.mean(0)) + 2e-3
    assert not bad.any(), f"{bad.sum()} of {bad.size} cells differ (worst {np.abs(ours.mean(0) - ref.mean(0)).max():.4f})"
    assert (ref.mean(0) > 0.05).sum() > 20
    swapped = _runs(lambda: _scene(drop=True), lambda sc, s: configure_restir(sc, 16, 0, s, integrator="PATH"), 2)
    assert (np.abs(swapped.mean(0) - ref.mean(0)) > 5 * se + 0.005 * np.abs(ref.mean(0)) + 2e-3).sum() > 10
