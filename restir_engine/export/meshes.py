"""Evaluated mesh instances -> world-space TriangleSet.

Every visible instance in ``depsgraph.object_instances`` (modifiers, particles, geometry-node
instances included; curves, text, surfaces and metaballs through their evaluated mesh) is
triangulated with ``calc_loop_triangles`` and read with ``foreach_get``; point clouds become spheres
(export/points.py). Local-space arrays are
cached per evaluated datablock so instances of one mesh are read once; no Python loop over triangles.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..core.scene import ObjectTable, TriangleSet
from . import object_properties
from .mesh_attributes import TANGENT_PREFIX, read_attribute, read_tangents
from .points import read_points

GEOMETRY_TYPES = {"MESH", "CURVE", "CURVES", "SURFACE", "FONT", "META", "POINTCLOUD"}
MAX_COORD = 1e7  # beyond this float32 precision makes ray offsets meaningless


def _read_mesh(mesh, want_uv: bool, want_tangents: bool = False, warnings: list | None = None,
               attributes: frozenset = frozenset()) -> dict | None:
    """Local-space triangle arrays of a mesh datablock: verts (t,3,3), normals (t,3,3),
    uvs (t,3,2) or None, tangents (t,3,4) (MikkTSpace tangent of the UV map and bitangent sign) or None,
    slot (t,) int32 material slot index, attributes {name: (t,3,4) RGBA} of the named colour / geometry
    attributes it has ("" = its render colour attribute), texspace (lo (3,), size (3,))."""
    mesh.calc_loop_triangles()
    tris = mesh.loop_triangles
    nt = len(tris)
    if nt == 0:
        return None
    nv = len(mesh.vertices)
    co = np.empty(nv * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    vidx = np.empty(nt * 3, np.int32)
    tris.foreach_get("vertices", vidx)
    loops = np.empty(nt * 3, np.int32)
    tris.foreach_get("loops", loops)
    nrm = np.empty(nt * 9, np.float32)
    try:
        if getattr(mesh, "normals_domain", "CORNER") == "FACE":
            # every face flat: the triangles' own normals, as Cycles shades flat faces (the corner normals of a mesh
            # deformed by an armature can lag behind its positions)
            tn = np.empty(nt * 3, np.float32)
            tris.foreach_get("normal", tn)
            nrm = np.repeat(tn.reshape(nt, 1, 3), 3, axis=1)
        else:
            tris.foreach_get("split_normals", nrm)
            nrm = nrm.reshape(nt, 3, 3)
    except (AttributeError, RuntimeError, TypeError):
        cn = np.empty(len(mesh.loops) * 3, np.float32)
        mesh.corner_normals.foreach_get("vector", cn)
        nrm = cn.reshape(-1, 3)[loops].reshape(nt, 3, 3)
    slot = np.empty(nt, np.int32)
    tris.foreach_get("material_index", slot)
    uvs = None
    if want_uv and mesh.uv_layers.active is not None:
        layer = next((u for u in mesh.uv_layers if u.active_render), mesh.uv_layers.active)
        uv = np.empty(len(mesh.loops) * 2, np.float32)
        layer.data.foreach_get("uv", uv)
        uvs = uv.reshape(-1, 2)[loops].reshape(nt, 3, 2)
    tangents = None
    if want_tangents and uvs is not None:
        try:
            mesh.calc_tangents(uvmap=layer.name)
            tl = np.empty(len(mesh.loops) * 3, np.float32)
            mesh.loops.foreach_get("tangent", tl)
            sign = np.empty(len(mesh.loops), np.float32)
            mesh.loops.foreach_get("bitangent_sign", sign)
            tangents = np.concatenate([tl.reshape(-1, 3), sign[:, None]], axis=1)[loops].reshape(nt, 3, 4)
        except RuntimeError as e:  # n-gons: Blender computes tangents for triangles and quads only
            if warnings is not None:
                warnings.append(f"Mesh '{mesh.name}': no tangents for its normal map ({e}); rendered without it")
    attrs = {}
    for name in attributes:
        if name.startswith(TANGENT_PREFIX):
            got = read_tangents(mesh, name[len(TANGENT_PREFIX):], loops, nt)
        else:
            got = read_attribute(mesh, name, vidx, loops, nt)
        if got is not None:
            attrs[name] = got
    local = co.reshape(-1, 3)
    return {"verts": local[vidx].reshape(nt, 3, 3), "normals": nrm, "uvs": uvs, "slot": slot,
            "tangents": tangents, "attributes": attrs, "texspace": _texspace(mesh, local)}


def read_corners(mesh) -> np.ndarray:
    """(t, 3, 3) float32 local-space corners of a mesh's loop triangles (as :func:`_read_mesh` orders them)."""
    mesh.calc_loop_triangles()
    tris = mesh.loop_triangles
    co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    vidx = np.empty(len(tris) * 3, np.int32)
    tris.foreach_get("vertices", vidx)
    return co.reshape(-1, 3)[vidx].reshape(len(tris), 3, 3)


def _texspace(mesh, local: np.ndarray) -> tuple:
    """(lo, size) of a mesh's texture space: Generated = (local position - lo) / size (Blender's auto texture
    space is its box; a flat axis gets size 2 around its centre, a tiny one 2e-5)."""
    if getattr(mesh, "use_auto_texspace", True) or not hasattr(mesh, "texspace_location"):
        lo, hi = (local.min(0), local.max(0)) if len(local) else (np.zeros(3), np.zeros(3))
        loc, half = (lo + hi) / 2, (hi - lo) / 2
    else:
        loc, half = np.array(mesh.texspace_location[:], np.float64), np.array(mesh.texspace_size[:], np.float64)
    half = np.where(half == 0, 1.0, np.where(np.abs(half) < 1e-5, np.copysign(1e-5, half), half))
    return (loc - half).astype(np.float32), (2 * half).astype(np.float32)


def hash_string(name: str) -> int:
    """Cycles' string hash (h = 37 h + byte over the UTF-8 bytes, uint32)."""
    h = 0
    for b in name.encode():
        h = (h * 37 + b) & 0xFFFFFFFF
    return h


def object_random(inst) -> float:
    """Object Info Random of an instance, as Cycles: the depsgraph's random id for instances, a hash of the
    object's name otherwise; float32(id) · 2⁻³²."""
    from ..core.materials.nodes.hashing import hash_uint
    if inst.is_instance:
        rid = int(inst.random_id) & 0xFFFFFFFF
    else:
        rid = int(hash_uint(np.uint32(hash_string(inst.object.name)), np.uint32(0)))
    return float(np.float32(rid) * np.float32(1.0 / 4294967296.0))


def instance_key(inst) -> tuple:
    """A key that names the same object instance in neighbouring frames (for motion vectors)."""
    parent = inst.parent.original.name if inst.is_instance and inst.parent is not None else ""
    return (inst.object.original.name if inst.object.original is not None else inst.object.name, parent,
            tuple(inst.persistent_id) if inst.is_instance else ())


def instance_matrices(depsgraph) -> dict:
    """World matrices (4x4 float64) of every visible geometry instance, by :func:`instance_key`."""
    out = {}
    for inst in depsgraph.object_instances:
        if inst.object.type in GEOMETRY_TYPES and inst.show_self:
            out[instance_key(inst)] = np.array(inst.matrix_world, np.float64)
    return out


def geometry_instances(depsgraph):
    """(instance, object) of every instance whose geometry is exported."""
    for inst in depsgraph.object_instances:
        obj = inst.object
        if obj.type not in GEOMETRY_TYPES or not inst.show_self:
            continue
        if not getattr(obj, "visible_camera", True) and not getattr(obj, "visible_diffuse", True):
            continue
        yield inst, obj


def slot_materials(obj) -> list:
    """The materials of an object's slots (None for an empty slot); where it has no slots (a point cloud made by
    Geometry Nodes), its data's materials."""
    mats = [s.material for s in obj.material_slots]
    if not mats and obj.type == "POINTCLOUD" and obj.data is not None:
        mats = list(obj.data.materials)
    return mats


def slot_signature(depsgraph) -> tuple:
    """The material names in every exported instance's slots, in export order (equal signatures: the
    triangles' material indices are unchanged)."""
    return tuple(tuple(m.name_full if m else "" for m in slot_materials(obj))
                 for _inst, obj in geometry_instances(depsgraph))


def export_geometry(depsgraph, registry, warnings: list, mesh_cache: dict | None = None, last=None):
    """Returns (TriangleSet, stats dict); the TriangleSet's ``instance`` holds each triangle's index into
    ``stats["instance_keys"]`` / ``stats["instance_matrices"]``. ``mesh_cache`` (optional, kept by the caller
    between exports whose meshes did not change: the viewport after a transform edit) holds the local arrays
    read from each evaluated mesh; ``stats["meshes_read"]`` counts the meshes read from Blender. ``last``: the
    (TriangleSet, stats) of an earlier export with the same ``mesh_cache``; where only instances' matrices changed
    since, only their triangles are transformed again (:func:`_retransformed`), the other arrays are last's."""
    blocks, reads, slots_seen = _collect_blocks(depsgraph, registry, warnings, mesh_cache)
    if not blocks:
        return TriangleSet.empty(), {"triangles": 0, "instances": 0, "dropped": 0, "instance_keys": [],
                                     "instance_matrices": np.zeros((0, 4, 4)), "meshes_read": reads,
                                     "slot_signature": tuple(slots_seen)}
    if last is not None:
        out = _retransformed(blocks, last[0], last[1], registry)
        if out is not None:
            geometry, stats = out
            warnings.extend(stats["assembly_warnings"])
            return geometry, dict(stats, meshes_read=reads, slot_signature=tuple(slots_seen))
    return _assemble(blocks, reads, slots_seen, registry, warnings)


def _collect_blocks(depsgraph, registry, warnings: list, mesh_cache: dict | None) -> tuple:
    """(blocks, meshes read, slot names seen): a block per exported instance, (local arrays, world matrix, material
    index map, object name, instance key, (colour, random, name, asset, holdout, pass index))."""
    blocks: list[tuple] = []  # (local arrays, matrix, material index map)
    cache: dict = {}
    reads = 0
    slots_seen: list = []
    slot_cache: dict = {}
    unsupported_visibility: dict = {}  # object name -> the ray kinds it hides from that are not honoured
    for inst, obj in geometry_instances(depsgraph):
        data = obj.data
        key = data.as_pointer() if (obj.type in {"MESH", "POINTCLOUD"} and data is not None) else obj.as_pointer()
        materials = slot_materials(obj)
        mats_key = (key, tuple(m.name_full if m else "" for m in materials))
        if mats_key not in slot_cache:
            index = np.array([registry.material_index(m) for m in materials] or [0], np.int32)
            # what the materials read of the mesh (objects sharing a mesh may link different materials)
            slot_cache[mats_key] = (index, (registry.uses_textures(index), registry.uses_normal_maps(index),
                                            frozenset(registry.attribute_names(index))),
                                    registry.object_property_keys(index))
        slot_index, wants, property_keys = slot_cache[mats_key]
        slots_seen.append(mats_key[1])
        read_key = (key, wants)
        if read_key not in cache:
            want_uv, want_tangents, want_attrs = wants
            # the name guards against a freed mesh's address reused by another one
            kept = (key, data.name_full if data is not None else obj.name_full, want_uv, want_tangents, want_attrs)
            if mesh_cache is not None and kept in mesh_cache:
                cache[read_key] = mesh_cache[kept]
            elif obj.type == "POINTCLOUD":
                cache[read_key] = read_points(data) if data is not None else None
                reads += 1
                if cache[read_key] is not None:
                    warnings.append(f"Point cloud '{obj.name}': {len(data.points)} points rendered as spheres of "
                                    f"{cache[read_key]['triangles_per_point']} triangles each (Cycles traces exact "
                                    "spheres)")
                if mesh_cache is not None:
                    mesh_cache[kept] = cache[read_key]
            else:
                try:
                    mesh = obj.to_mesh()
                except RuntimeError:
                    mesh = None
                if mesh is None:
                    cache[read_key] = None
                    continue
                try:
                    cache[read_key] = _read_mesh(mesh, want_uv, want_tangents, warnings, want_attrs)
                    reads += 1
                finally:
                    obj.to_mesh_clear()
                if mesh_cache is not None:
                    mesh_cache[kept] = cache[read_key]
        arrays = cache[read_key]
        if arrays is None:
            continue
        properties = object_properties.instance_values(inst, obj, property_keys)
        for name in object_properties.unread_instance_attributes(inst, properties):
            message = (f"Attribute '{name}' (Instancer) is not a property of the instancer or of '{obj.name}': "
                       "instance attributes of Geometry Nodes instances cannot be read here, it reads 0")
            if message not in warnings:
                warnings.append(message)
        blocks.append((arrays, np.array(inst.matrix_world, np.float64), slot_index, obj.name,
                       instance_key(inst), (tuple(obj.color), object_random(inst), obj.name, asset_name(obj),
                                                         bool(getattr(obj, "is_holdout", False)),
                                                         float(getattr(obj, "pass_index", 0)),
                                                         bool(getattr(obj, "is_shadow_catcher", False)),
                                                         bool(getattr(obj, "visible_shadow", True)),
                                                         bool(getattr(obj, "visible_camera", True)),
                                                         properties)))
        unseen = [f for f in ("glossy", "transmission") if not getattr(obj, f"visible_{f}", True)]
        if unseen and obj.name not in unsupported_visibility:
            unsupported_visibility[obj.name] = unseen
    if unsupported_visibility:
        names = list(unsupported_visibility)
        warnings.append(f"Object > Visibility > Ray Visibility: only Camera and Shadow are honoured; "
                        f"{', '.join(names[:3])}"
                        f"{' and others' if len(names) > 3 else ''} stay visible to "
                        f"{', '.join(sorted({f for v in unsupported_visibility.values() for f in v}))} rays")

    return blocks, reads, slots_seen


def _placed(arrays: dict, m: np.ndarray) -> tuple:
    """(verts (n, 3, 3), normals (n, 3, 3), tangents (n, 3, 4) or None, the named UV maps' tangent attributes
    {name: (n, 3, 4)}) of a mesh's local arrays placed by the world matrix ``m`` (float32 results of float64
    arithmetic; normals by the inverse transpose, unit length; tangents by the linear part)."""
    n = len(arrays["verts"])
    lin = m[:3, :3]
    verts = (arrays["verts"].reshape(-1, 3) @ lin.T + m[:3, 3]).reshape(n, 3, 3).astype(np.float32)
    try:
        nm = np.linalg.inv(lin).T
    except np.linalg.LinAlgError:
        nm = lin
    nn = arrays["normals"].reshape(-1, 3) @ nm.T
    nn /= np.maximum(np.linalg.norm(nn, axis=1), 1e-30)[:, None]
    normals = nn.reshape(n, 3, 3).astype(np.float32)
    tangents = None if arrays["tangents"] is None else _placed_tangents(arrays["tangents"], lin)
    named = {a: _placed_tangents(v, lin) for a, v in arrays.get("attributes", {}).items()
             if a.startswith(TANGENT_PREFIX)}
    return verts, normals, tangents, named


def _placed_tangents(local: np.ndarray, lin: np.ndarray) -> np.ndarray:
    """(n, 3, 4) tangents and bitangent signs in object space -> world space by the linear part ``lin``."""
    n = len(local)
    out = np.empty((n, 3, 4), np.float32)
    tw = local[..., :3].reshape(-1, 3) @ lin.T   # surface vectors move with the linear part
    tw /= np.maximum(np.linalg.norm(tw, axis=1), 1e-30)[:, None]
    out[:, :, :3] = tw.reshape(n, 3, 3)
    # a mirroring transform flips the bitangent (the normal is transformed, the frame's handedness not)
    out[:, :, 3] = local[..., 3] * np.sign(np.linalg.det(lin) or 1.0)
    return out


def _usable(verts: np.ndarray) -> tuple:
    """(finite (n,), keep (n,)) bool: corners finite and not huge; and that with a non-zero area as well."""
    finite = np.isfinite(verts).all(axis=(1, 2)) & (np.abs(verts).max(axis=(1, 2)) < MAX_COORD)
    with np.errstate(invalid="ignore", over="ignore"):
        area2 = np.linalg.norm(np.cross(verts[:, 1] - verts[:, 0], verts[:, 2] - verts[:, 0]), axis=1)
    return finite, finite & (area2 > 0) & np.isfinite(area2)


def _retransformed(blocks, last, stats: dict, registry):
    """(TriangleSet, stats) from the last export's where only instances' world matrices changed (the same
    instances in the same order, the same cached mesh arrays, material slots and indices) and every triangle
    stays usable or unusable as before; None otherwise (the caller assembles everything)."""
    keys, arrays_seen = stats.get("instance_keys"), stats.get("block_arrays")
    if arrays_seen is None or len(blocks) != len(keys) or \
            stats.get("geometry_material_index") != dict(registry.index):
        return None
    for b, key, arrays, slot_map in zip(blocks, keys, arrays_seen, stats["slot_maps"]):
        if b[4] != key or b[0] is not arrays or not np.array_equal(b[2], slot_map):
            return None
    mats = np.array([b[1] for b in blocks], np.float64)
    changed = np.flatnonzero((mats != stats["instance_matrices"]).any(axis=(1, 2)))
    starts, kept = stats["block_starts"], stats["kept"]
    post = np.cumsum(kept) - 1  # each triangle's row after the unusable ones were dropped
    verts, normals = last.verts.copy(), last.normals.copy()
    tangents = None if last.tangents is None else last.tangents.copy()
    attributes = dict(last.attributes or {})
    named = [a for a in attributes if a.startswith(TANGENT_PREFIX)]
    for a in named:  # the named UV maps' tangents move with their instances (colours do not)
        attributes[a] = attributes[a].copy()
    for k in changed:  # the moved instances, each vectorized over its triangles
        s, e = int(starts[k]), int(starts[k + 1])
        v, nrm, tan, placed = _placed(blocks[k][0], blocks[k][1])
        _finite, keep = _usable(v)
        if not np.array_equal(keep, kept[s:e]):
            return None
        rows = post[s:e][keep]
        verts[rows] = v[keep]
        nrm = nrm[keep]
        nrm[~np.isfinite(nrm).all(axis=2)] = 0.0
        normals[rows] = nrm
        if tangents is not None and tan is not None:
            tangents[rows] = tan[keep]
        for a, vals in placed.items():
            attributes[a][rows] = vals[keep]
    geometry = dataclasses.replace(last, verts=verts, normals=normals, tangents=tangents,
                                   objects=_object_table(blocks), attributes=attributes or last.attributes)
    return geometry, dict(stats, instance_matrices=mats)


def _assemble(blocks, reads: int, slots_seen: list, registry, warnings: list) -> tuple:
    """(TriangleSet, stats) of the blocks: every instance placed, unusable triangles dropped (with warnings)."""
    first_warning = len(warnings)
    total = sum(len(b[0]["verts"]) for b in blocks)
    verts = np.empty((total, 3, 3), np.float32)
    normals = np.empty((total, 3, 3), np.float32)
    material = np.empty(total, np.int32)
    instance = np.empty(total, np.int32)
    need_uv = any(b[0]["uvs"] is not None for b in blocks)
    uvs = np.zeros((total, 3, 2), np.float32) if need_uv else None
    need_tangents = any(b[0]["tangents"] is not None for b in blocks)
    # a mesh without tangents gets zero ones: its normal map then leaves the normal as it is (m_z N)
    tangents = np.zeros((total, 3, 4), np.float32) if need_tangents else None
    attr_names = sorted({a for b in blocks for a in b[0].get("attributes", {})})
    local_verts = np.empty((total, 3, 3), np.float32) if any(registry.reads_object_space(b[2]) for b in blocks) \
        else None
    attributes = {a: np.zeros((total, 3, 4), np.float32) for a in attr_names}
    at = 0
    for k, (arrays, m, slot_map, _name, _key, _info) in enumerate(blocks):  # per instance, vectorized over triangles
        n = len(arrays["verts"])
        v, nrm, tan, placed = _placed(arrays, m)
        verts[at:at + n] = v
        normals[at:at + n] = nrm
        material[at:at + n] = slot_map[np.clip(arrays["slot"], 0, len(slot_map) - 1)]
        instance[at:at + n] = k
        if uvs is not None and arrays["uvs"] is not None:
            uvs[at:at + n] = arrays["uvs"]
        for a, vals in arrays.get("attributes", {}).items():
            attributes[a][at:at + n] = placed.get(a, vals)
        if local_verts is not None:
            local_verts[at:at + n] = arrays["verts"]
        if tangents is not None and tan is not None:
            tangents[at:at + n] = tan
        at += n
    # drop unusable triangles: non-finite or huge coordinates, zero area
    finite, keep = _usable(verts)
    if not finite.all():
        bad_names = sorted({b[3] for b, s, e in _spans(blocks) if not finite[s:e].all()})
        warnings.append(f"{int((~finite).sum())} triangles with NaN, infinite or huge (>{MAX_COORD:g}) coordinates "
                        f"were skipped (objects: {', '.join(bad_names[:5])})")
    # an object scaled to zero is how animators hide it: its triangles go without a word
    hidden = np.repeat([not np.any(b[1][:3, :3]) for b in blocks], [len(b[0]["verts"]) for b in blocks])
    n_degenerate = int((finite & ~keep & ~hidden).sum())
    if n_degenerate:
        warnings.append(f"{n_degenerate} zero-area triangles were skipped")
    if not keep.all():
        verts, normals, material, instance = verts[keep], normals[keep], material[keep], instance[keep]
        uvs = uvs[keep] if uvs is not None else None
        attributes = {a: v[keep] for a, v in attributes.items()}
        local_verts = local_verts[keep] if local_verts is not None else None
        tangents = tangents[keep] if tangents is not None else None
    bad_n = ~np.isfinite(normals).all(axis=2)
    if bad_n.any():
        normals[bad_n] = 0.0  # the shader falls back to the geometric normal
    stats = {"triangles": len(verts), "instances": len(blocks), "dropped": int((~keep).sum()),
             "instance_keys": [b[4] for b in blocks], "instance_matrices": np.array([b[1] for b in blocks]),
             "meshes_read": reads, "slot_signature": tuple(slots_seen),
             # each instance's triangles before the unusable ones were dropped, and which were kept (motion blur's
             # deformation steps read the same triangles again)
             "block_starts": np.cumsum([0] + [len(b[0]["verts"]) for b in blocks]), "kept": keep,
             # what a later export with the same mesh cache compares with (_retransformed)
             "block_arrays": [b[0] for b in blocks], "slot_maps": [b[2] for b in blocks],
             "geometry_material_index": dict(registry.index), "assembly_warnings": warnings[first_warning:]}
    return TriangleSet(verts, normals, material, uvs, instance, tangents, objects=_object_table(blocks),
                       attributes=attributes or None, local_verts=local_verts), stats


def _object_table(blocks) -> ObjectTable:
    """What shader nodes read of each exported instance (world matrix inverse, texture space, Object Info)."""
    from ..core.scene import affine_inverse
    mats = np.array([b[1] for b in blocks], np.float64)
    inv = affine_inverse(mats)[:, :3, :]  # float64: object coordinates on a flat axis stay exact
    lo = np.array([b[0]["texspace"][0] for b in blocks], np.float32)
    size = np.array([b[0]["texspace"][1] for b in blocks], np.float32)
    return ObjectTable(world_to_object=inv, texspace_lo=lo, texspace_size=size,
                       location=mats[:, :3, 3].astype(np.float32),
                       color=np.array([b[5][0] for b in blocks], np.float32).reshape(len(blocks), 4),
                       random=np.array([b[5][1] for b in blocks], np.float32),
                       names=tuple(b[5][2] for b in blocks), assets=tuple(b[5][3] for b in blocks),
                       holdout=np.array([b[5][4] for b in blocks], bool),
                       pass_index=np.array([b[5][5] for b in blocks], np.float32),
                       shadow_catcher=np.array([b[5][6] for b in blocks], bool),
                       casts_shadow=np.array([b[5][7] for b in blocks], bool),
                       camera_visible=np.array([b[5][8] for b in blocks], bool),
                       properties=_property_table(blocks))


def _property_table(blocks) -> dict | None:
    """{"KIND:name": (k, 4) float32} of the Object / Instancer attributes the instances' materials read (0 where an
    instance's own materials do not read it), or None where none is read."""
    keys = sorted({key for b in blocks for key in b[5][9]})
    if not keys:
        return None
    return {key: np.array([b[5][9].get(key, object_properties.MISSING) for b in blocks], np.float32).reshape(-1, 4)
            for key in keys}


def asset_name(obj) -> str:
    """The name of an object's top-most parent (itself without one): Cryptomatte's asset."""
    while obj.parent is not None:
        obj = obj.parent
    return obj.name


def _spans(blocks):
    at = 0
    for b in blocks:
        n = len(b[0]["verts"])
        yield b, at, at + n
        at += n
