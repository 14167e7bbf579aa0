"""A mesh's per-corner attributes for node programs: named colour / geometry attributes as RGBA, and a named UV
map's tangents (attribute "tangent@<map>")."""
from __future__ import annotations

import numpy as np

from .derived_attributes import DERIVED, read_derived


TANGENT_PREFIX = "tangent@"  # attribute "tangent@<UV map>": that map's MikkTSpace tangents and bitangent signs


def read_tangents(mesh, uv_map: str, loops, nt: int):
    """(t, 3, 4) object-space MikkTSpace tangents (xyz) and bitangent signs (w) of the UV map ``uv_map`` at each
    triangle's corners (a Normal Map node naming that map); None when the mesh has no such map or Blender cannot
    compute them (n-gons)."""
    if mesh.uv_layers.get(uv_map) is None:
        return None
    try:
        mesh.calc_tangents(uvmap=uv_map)
    except RuntimeError:
        return None
    tl = np.empty(len(mesh.loops) * 3, np.float32)
    mesh.loops.foreach_get("tangent", tl)
    sign = np.empty(len(mesh.loops), np.float32)
    mesh.loops.foreach_get("bitangent_sign", sign)
    return np.concatenate([tl.reshape(-1, 3), sign[:, None]], axis=1)[loops].reshape(nt, 3, 4)


def read_attribute(mesh, name: str, vidx, loops, nt: int):
    """(t, 3, 4) RGBA corner values of a colour attribute (or a float / vector geometry attribute), linear; None
    when the mesh has none of that name."""
    if name in DERIVED:  # computed from the shape (Geometry > Pointiness): the value in every channel
        vals = np.repeat(read_derived(mesh, name)[:, None], 4, axis=1)
        return vals[vidx].reshape(nt, 3, 4)
    attr = None
    if name == "":
        ca = mesh.color_attributes
        idx = getattr(ca, "render_color_index", -1)
        attr = ca[idx] if 0 <= idx < len(ca) else (ca[0] if len(ca) else None)
    else:
        attr = mesh.attributes.get(name)
    if attr is None:
        return None
    n = len(attr.data)
    if attr.data_type in {"FLOAT_COLOR", "BYTE_COLOR"}:
        buf = np.empty(n * 4, np.float32)
        attr.data.foreach_get("color", buf)  # scene-linear for both storage types
        vals = buf.reshape(n, 4)
    elif attr.data_type in {"FLOAT_VECTOR", "FLOAT2", "FLOAT"}:
        width = {"FLOAT_VECTOR": 3, "FLOAT2": 2, "FLOAT": 1}[attr.data_type]
        buf = np.empty(n * width, np.float32)
        attr.data.foreach_get("vector" if width > 1 else "value", buf)
        vals = np.ones((n, 4), np.float32)
        vals[:, :3] = 0
        if width == 1:
            vals[:, :3] = buf[:, None]
        else:
            vals[:, :width] = buf.reshape(n, width)
    else:
        return None
    if attr.domain == "POINT":
        return vals[vidx].reshape(nt, 3, 4)
    if attr.domain == "CORNER":
        return vals[loops].reshape(nt, 3, 4)
    if attr.domain == "FACE":
        poly = np.empty(nt, np.int32)
        mesh.loop_triangles.foreach_get("polygon_index", poly)
        return np.repeat(vals[poly][:, None], 3, axis=1)
    return None
