"""Cryptomatte against Cycles (same bpy, CPU): a scene of overlapping objects with the object, material and asset
layers on, written to a multilayer EXR by each engine; the matte of every name (the sum of its ranks' coverages,
the Cryptomatte node's result) compared pixel by pixel, and the metadata (layer names, manifests: ours lists what
Cycles' lists but its built-in shaders) compared. Tolerance per pixel: 5 binomial standard errors of the pooled
coverage at our 16 rays and Cycles' 64 samples, plus 0.02 (Cycles' pixel filter table and sample pattern); power:
the matte of a name must not match another name's. Cycles renders here (48 x 32, 64 samples, no bounces: about a
second), as its passes and metadata are not cell means the stored references hold."""
import math
import os
import tempfile

import bpy
import numpy as np

from bpy_scenes import camera, configure_cycles, configure_restir, diffuse, light, plane, reset

SIZE = (48, 32)


def _scene():
    scene = reset()
    plane("Floor", 6.0, (0, 0, 0), material=diffuse("FloorMat", (0.5, 0.5, 0.5)))
    bpy.ops.mesh.primitive_cube_add(size=0.8, location=(-0.4, 0.0, 0.4), rotation=(0, 0, 0.4))
    cube = bpy.context.active_object
    cube.name = "Cube"
    cube.data.materials.append(diffuse("Red", (0.8, 0.1, 0.1)))
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.45, location=(0.35, -0.3, 0.45), segments=24, ring_count=12)
    ball = bpy.context.active_object
    ball.name = "Ball"
    ball.data.materials.append(diffuse("Blue", (0.1, 0.2, 0.8)))
    ball.parent = cube  # its asset is the cube
    light("POINT", (1.0, -1.5, 2.5), (0, 0, 0), energy=200.0)
    camera((0, -3.2, 1.8), (math.radians(62), 0, 0), lens=35)
    scene.render.resolution_x, scene.render.resolution_y = SIZE
    vl = scene.view_layers[0]
    vl.use_pass_cryptomatte_object = vl.use_pass_cryptomatte_material = vl.use_pass_cryptomatte_asset = True
    vl.pass_cryptomatte_depth = 4
    return scene


def _render(scene):
    """({layer prefix: (h, w, 4 * passes) in R, G, B, A order per pass}, metadata {key: value})."""
    import OpenEXR
    from harness.render import use_multilayer_exr
    use_multilayer_exr(scene)
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "crypto.exr")
        scene.render.filepath = path
        bpy.ops.render.render(write_still=True)
        f = OpenEXR.File(path)
        part = f.parts[0]
        header = {k: (v.decode() if isinstance(v, bytes) else v) for k, v in part.header.items()}
        layers = {}
        for p in f.parts:
            for name, ch in p.channels.items():
                parts = name.split(".")
                if len(parts) < 3 or not parts[1].startswith("Crypto"):
                    continue
                layers.setdefault(parts[1], {})[parts[2].lower()] = np.asarray(ch.pixels, np.float32)[::-1]
    out = {}
    for pass_name, chans in sorted(layers.items()):
        prefix = pass_name[:-2]
        out.setdefault(prefix, []).append(np.stack([chans[c] for c in "rgba"], axis=-1))
    return {k: np.concatenate(v, axis=-1) for k, v in out.items()}, header


def _mattes(layer, names):
    from restir_engine.core.pipeline.cryptomatte import hash_float, name_hash
    ids, cov = layer[..., 0::2], layer[..., 1::2]
    return {n: (cov * (ids == np.float32(hash_float(name_hash(n))))).sum(axis=-1) for n in names}


def test_cryptomatte_matches_cycles(addon):
    scene = _scene()
    configure_restir(scene, 16, 0, 0, integrator="PATH")
    ours, meta_ours = _render(scene)
    scene = _scene()
    configure_cycles(scene, 64, 0, 0)
    ref, meta_ref = _render(scene)
    names = {"CryptoObject": ["Cube", "Ball", "Floor"], "CryptoMaterial": ["Red", "Blue", "FloorMat"],
             "CryptoAsset": ["Cube", "Floor"]}
    for prefix, wanted in names.items():
        mo, mr = _mattes(ours[prefix], wanted), _mattes(ref[prefix], wanted)
        for n in wanted:
            p = np.clip((16 * mo[n] + 64 * mr[n]) / 80, 0, 1)  # pooled coverage
            se = np.sqrt(p * (1 - p) / 16 + p * (1 - p) / 64)
            bad = np.abs(mo[n] - mr[n]) > 5 * se + 0.02
            assert not bad.any(), f"{prefix} {n}: {bad.sum()} pixels differ (worst {np.abs(mo[n] - mr[n]).max():.3f})"
            assert mr[n].sum() > 10, f"{prefix} {n} is not in view"
            other = [m for m in wanted if m != n][0]
            assert (np.abs(mo[other] - mr[n]) > 5 * se + 0.02).sum() > 10  # power: another name's matte differs
    keys = [k for k in meta_ref if k.startswith("cryptomatte/")]
    assert keys
    for k in keys:
        if k.endswith("/manifest"):
            import json
            mine, theirs = json.loads(meta_ours[k]), json.loads(meta_ref[k])
            if "aa21542" in k or "CryptoMaterial" in meta_ref[k.replace("manifest", "name")]:
                # Cycles also lists its built-in shaders (default surface, light, background)
                assert mine.items() <= theirs.items(), k
            else:
                assert mine == theirs, k
        else:
            assert meta_ours.get(k) == meta_ref[k], k
