"""Cycles' side of the comparisons with Cycles, rendered once and kept as committed reference data.

A comparison reduces each of REPS independent Cycles renders (seeds 0..REPS-1) of a test scene to per-cell means
((REPS, cells): image blocks, spheres, floor cells); those per-seed cell means are all the statistics need (the
Welch z-scores and standard errors in tests/stats.py), so they are what is stored: one JSON file per case in
``tests/data/cycles/bpy-<major.minor>/`` (a test that needs Cycles' image itself, per pixel, stores it as float16 in
an .npz beside them: :func:`cycles_image`), with the seeds, samples, bounces, the bpy version that rendered them and a
fingerprint of the Blender scene Cycles was given (geometry, transforms, materials' node trees, lights, world,
images, camera, resolution and Cycles' own settings). A test whose scene no longer has that fingerprint fails and
says how to render the reference again, so stored data cannot silently go stale.

``RESTIR_CYCLES_REFS`` chooses where the Cycles side comes from:
  ``stored`` (default)  the committed data (a CI run renders only our side);
  ``render``            Cycles renders afresh and nothing is written (the slow suite as it ran before);
  ``update``            Cycles renders afresh and the data is written (scripts/make_cycles_refs.sh).
``RESTIR_FINGERPRINT_DUMP=FILE`` appends each fingerprinted record (JSON) to FILE, to see what changed in a scene.
"""
from __future__ import annotations

import hashlib
import json
import os

import bpy
import numpy as np

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "cycles")
MODES = ("stored", "render", "update")


def mode() -> str:
    value = os.environ.get("RESTIR_CYCLES_REFS", "stored")
    if value not in MODES:
        raise ValueError(f"RESTIR_CYCLES_REFS={value!r}; expected one of {MODES}")
    return value


def bpy_series() -> str:
    """'major.minor' of the running bpy (each series keeps its own references: Cycles changes between them)."""
    return ".".join(str(v) for v in bpy.app.version[:2])


def _path(case: str) -> str:
    return os.path.join(DATA, f"bpy-{bpy_series()}", f"{case}.json")


def _floats(values, digits: int = 6) -> list:
    return [round(float(v), digits) for v in np.asarray(values, np.float64).ravel()]


def _socket_value(sock):
    value = getattr(sock, "default_value", None)
    return None if value is None else _value(value)


_NODE_PROPS = ("blend_type", "data_type", "operation", "interpolation", "extension", "projection", "distribution",
               "subsurface_method", "space", "invert", "vector_type", "use_clamp", "clamp_factor", "clamp_result")


def _tree(tree) -> list:
    if tree is None:
        return []
    nodes = []
    for node in sorted(tree.nodes, key=lambda n: n.name):
        props = {p: str(getattr(node, p)) for p in _NODE_PROPS if hasattr(node, p)}
        image = getattr(node, "image", None)
        if image is not None:
            props["image"] = image.name
        inputs = [(s.identifier, _socket_value(s)) for s in node.inputs if not s.is_linked]
        nodes.append((node.bl_idname, node.name, props, inputs))
    links = sorted((ln.from_node.name, ln.from_socket.identifier, ln.to_node.name, ln.to_socket.identifier)
                   for ln in tree.links)
    return [nodes, links]


def _mesh(mesh) -> str:
    """sha256 of a mesh's vertices and faces, independent of where each face's corners start (the same primitive
    operator can start them at another corner in another call): per corner (vertex, its face's material, UVs) sorted,
    and the faces as sorted vertex sets, sorted."""
    co = np.zeros(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    loops = np.zeros(len(mesh.loops), np.int64)
    mesh.loops.foreach_get("vertex_index", loops)
    start = np.zeros(len(mesh.polygons), np.int64)
    mesh.polygons.foreach_get("loop_start", start)
    total = np.zeros(len(mesh.polygons), np.int64)
    mesh.polygons.foreach_get("loop_total", total)
    mats = np.zeros(len(mesh.polygons), np.int64)
    mesh.polygons.foreach_get("material_index", mats)
    face_of_loop = np.repeat(np.arange(len(start)), total)[np.argsort(np.repeat(start, total) +
                                                                      _ranks(total), kind="stable")]
    columns = [loops.astype(np.float64), mats[face_of_loop].astype(np.float64)]
    for layer in mesh.uv_layers:
        uv = np.zeros(len(mesh.loops) * 2, np.float32)
        layer.data.foreach_get("uv", uv)
        columns += [np.round(uv[0::2], 5).astype(np.float64), np.round(uv[1::2], 5).astype(np.float64)]
    corners = np.stack(columns, axis=1)
    corners = corners[np.lexsort(corners.T[::-1])]
    faces = sorted(tuple(sorted(loops[s0:s0 + n].tolist())) for s0, n in zip(start.tolist(), total.tolist()))
    h = hashlib.sha256(np.round(co, 5).tobytes())
    h.update(corners.tobytes())
    h.update(repr(faces).encode())
    return h.hexdigest()


def _ranks(total: np.ndarray) -> np.ndarray:
    """0, 1, ..., n-1 for each face of ``total`` corners, concatenated."""
    ends = np.cumsum(total)
    return np.arange(int(ends[-1]) if len(ends) else 0) - np.repeat(ends - total, total)


_LIGHT_PROPS = ("type", "energy", "color", "shadow_soft_size", "size", "size_y", "shape", "spot_size", "spot_blend",
                "angle", "use_soft_falloff", "spread")


def _value(v):
    try:
        return _floats(v)
    except (TypeError, ValueError):
        return str(v)


def scene_fingerprint(scene) -> str:
    """sha256 of what Cycles renders of ``scene`` (its seed left out: the references hold every seed)."""
    r = scene.render
    c = scene.cycles
    record = {"resolution": (r.resolution_x, r.resolution_y, r.resolution_percentage), "frame": scene.frame_current,
              "cycles": {k: _value(getattr(c, k)) for k in sorted(c.bl_rna.properties.keys())
                         if k not in ("seed", "rna_type") and hasattr(c, k) and not callable(getattr(c, k))
                         and isinstance(getattr(c, k), (int, float, bool, str))},
              "view_transform": scene.view_settings.view_transform, "film_transparent": r.film_transparent,
              "world": _tree(scene.world.node_tree) if scene.world and scene.world.use_nodes else None,
              "objects": [], "materials": {}, "images": {}}
    if scene.camera is not None:
        cam = scene.camera.data
        record["camera"] = (cam.type, _floats([cam.lens, cam.ortho_scale, cam.sensor_width, cam.shift_x, cam.shift_y,
                                               cam.clip_start, cam.clip_end]),
                            cam.sensor_fit, _floats(scene.camera.matrix_world))
    for ob in sorted(scene.objects, key=lambda o: o.name):
        if ob.hide_render:
            continue
        entry = [ob.name, ob.type, _floats(ob.matrix_world)]
        if ob.type == "MESH":
            entry.append(_mesh(ob.data))
            entry.append([s.material.name if s.material else None for s in ob.material_slots])
            for slot in ob.material_slots:
                mat = slot.material
                if mat is not None and mat.name not in record["materials"]:
                    record["materials"][mat.name] = _tree(mat.node_tree) if mat.use_nodes else _floats(mat.diffuse_color)
        elif ob.type == "LIGHT":
            entry.append({p: _value(getattr(ob.data, p)) for p in _LIGHT_PROPS if hasattr(ob.data, p)})
            entry.append(_tree(ob.data.node_tree) if getattr(ob.data, "use_nodes", False) else None)
        record["objects"].append(entry)
    for img in sorted(bpy.data.images, key=lambda i: i.name):
        if img.size[0] * img.size[1] == 0:
            continue
        px = np.empty(img.size[0] * img.size[1] * img.channels, np.float32)
        img.pixels.foreach_get(px)
        record["images"][img.name] = (tuple(img.size), img.colorspace_settings.name,
                                      hashlib.sha256(np.round(px, 5).tobytes()).hexdigest())
    text = json.dumps(record, sort_keys=True, default=str)
    if os.environ.get("RESTIR_FINGERPRINT_DUMP"):
        with open(os.environ["RESTIR_FINGERPRINT_DUMP"], "a") as f:
            f.write(text + "\n")
    return hashlib.sha256(text.encode()).hexdigest()


class StaleReference(AssertionError):
    pass


def cycles_cells(case: str, build, configure, render, reduce, reps: int, samples: int, bounces: int) -> np.ndarray:
    """(reps, cells) per-seed cell means of Cycles' renders of ``build()`` (seeds 0..reps-1), from the stored
    reference of ``case`` (or rendered, see the module docstring). ``configure(scene, seed)`` sets Cycles up for one
    seed, ``render(scene)`` returns its (h, w, 3) image and ``reduce(images (k, h, w, 3))`` the (k, cells) means."""
    scene = build()
    configure(scene, 0)
    fingerprint = scene_fingerprint(scene)
    how = mode()
    path = _path(case)
    meta = {"case": case, "reps": reps, "seeds": list(range(reps)), "samples": samples, "bounces": bounces}
    if how == "stored":
        if not os.path.exists(path):
            raise StaleReference(f"no stored Cycles reference {os.path.relpath(path)}: render it with "
                                 f"scripts/make_cycles_refs.sh (or run with RESTIR_CYCLES_REFS=render)")
        with open(path) as f:
            data = json.load(f)
        wanted = {**meta, "fingerprint": fingerprint}
        stored = {k: data.get(k) for k in wanted}
        if stored != wanted:
            diff = sorted(k for k in wanted if stored[k] != wanted[k])
            raise StaleReference(f"the stored Cycles reference {os.path.relpath(path)} was rendered for another "
                                 f"scene or settings ({', '.join(diff)} differ): render it again with "
                                 f"scripts/make_cycles_refs.sh")
        return np.asarray(data["cells"], np.float64)
    images = []
    for seed in range(reps):
        configure(scene, seed)
        images.append(render(scene))
    cells = np.asarray(reduce(np.array(images)), np.float64)
    if how == "update":
        os.makedirs(os.path.dirname(path), exist_ok=True)
        data = {**meta, "fingerprint": fingerprint, "bpy": bpy.app.version_string,
                "mean": cells.mean(axis=0).tolist(), "se": (cells.std(axis=0, ddof=1) / np.sqrt(reps)).tolist(),
                "cells": cells.tolist()}
        with open(path, "w") as f:
            json.dump(data, f, indent=1)
            f.write("\n")
    return cells


def cycles_image(case: str, scene, render, samples: int, bounces: int) -> np.ndarray:
    """(h, w, 3) float32 image of ``scene`` (already set up for Cycles) that ``render(scene)`` gives, from the stored
    reference of ``case`` (float16, ``tests/data/cycles/bpy-<series>/<case>.npz``, with the scene's fingerprint) or
    rendered (see the module docstring). Float16 keeps a relative 5e-4 per pixel: for comparisons of image errors,
    not of means to that precision."""
    fingerprint = scene_fingerprint(scene)
    how = mode()
    path = _path(case)[:-len(".json")] + ".npz"
    meta = {"case": case, "samples": samples, "bounces": bounces, "fingerprint": fingerprint}
    if how == "stored":
        if not os.path.exists(path):
            raise StaleReference(f"no stored Cycles reference {os.path.relpath(path)}: render it with "
                                 f"scripts/make_cycles_refs.sh (or run with RESTIR_CYCLES_REFS=render)")
        with np.load(path) as data:
            stored = json.loads(str(data["meta"]))
            image = data["image"].astype(np.float32)
        diff = sorted(k for k in meta if stored.get(k) != meta[k])
        if diff:
            raise StaleReference(f"the stored Cycles reference {os.path.relpath(path)} was rendered for another "
                                 f"scene or settings ({', '.join(diff)} differ): render it again with "
                                 f"scripts/make_cycles_refs.sh")
        return image
    image = np.asarray(render(scene), np.float32).astype(np.float16)
    if how == "update":
        os.makedirs(os.path.dirname(path), exist_ok=True)
        np.savez_compressed(path, image=image, meta=json.dumps({**meta, "bpy": bpy.app.version_string}))
    return image.astype(np.float32)
