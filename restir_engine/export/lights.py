"""Blender Light objects -> Lamps (non-occluding emitters) with Cycles' power conventions.

  area  (square, rectangle, disk, ellipse): one-sided Lambertian emitter facing local -Z,
        radiance L = P / (π A)  (A: world-space area, object scale included)
  point: sphere of radius r (Radius; 1 mm when 0) emitting L = P / (π A_sphere) = P / (4π² r²),
        i.e. intensity P / (4π) W/sr in every direction, as Cycles' sphere lights. The core treats it as a
        true sphere (sampled by the cone it subtends, rays intersect it analytically); its triangles are
        only a proxy for finding ray hits: an icosphere scaled so that it encloses the sphere
  spot : the point-light sphere with Cycles' cone attenuation smoothstep((cosθ - cos(size/2)) / (blend (1 - cos(size/2))))
  sun  : distant light, irradiance = strength (W/m²) on a surface facing it, cone of the sun's angle
Colours multiply the power; everything is scene-linear RGB.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..core.scene import Lamps, TriangleSet
from .limits import clamped_radiance

DISK_SEGMENTS = 48
SPHERE_LEVEL = 1  # 80 proxy triangles per point/spot light (hits are then found on the true sphere)
MIN_RADIUS = 1e-3


def _icosphere(level: int) -> np.ndarray:
    """Unit icosphere triangles (t, 3, 3) wound outward."""
    p = (1 + 5 ** 0.5) / 2
    v = np.array([[-1, p, 0], [1, p, 0], [-1, -p, 0], [1, -p, 0], [0, -1, p], [0, 1, p], [0, -1, -p], [0, 1, -p],
                  [p, 0, -1], [p, 0, 1], [-p, 0, -1], [-p, 0, 1]], np.float64)
    f = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2],
                  [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5],
                  [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])
    tris = v[f]
    tris /= np.linalg.norm(tris, axis=2, keepdims=True)
    for _ in range(level):
        a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
        ab, bc, ca = (a + b), (b + c), (c + a)
        ab, bc, ca = (x / np.linalg.norm(x, axis=1, keepdims=True) for x in (ab, bc, ca))
        tris = np.concatenate([np.stack(t, axis=1) for t in ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))])
    return tris


def _enclosing(tris: np.ndarray) -> np.ndarray:
    """Unit icosphere triangles scaled so that every face lies outside the unit sphere (margin 0.1 %)."""
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    inradius = float(np.einsum("ij,ij->i", n, tris[:, 0]).min())
    return tris * (1.001 / inradius)


_SPHERE = _enclosing(_icosphere(SPHERE_LEVEL))


def _area_shape(light) -> np.ndarray:
    """Local-space triangles of an area light (z = 0), wound so the normal is -Z (emission side)."""
    sx = float(light.size)
    sy = float(light.size_y) if light.shape in {"RECTANGLE", "ELLIPSE"} else sx
    if light.shape in {"SQUARE", "RECTANGLE"}:
        a, b = sx / 2, sy / 2
        c = np.array([[-a, -b, 0], [a, -b, 0], [a, b, 0], [-a, b, 0]], np.float64)
        tris = np.array([[c[0], c[2], c[1]], [c[0], c[3], c[2]]])
    else:
        ang = np.linspace(0, 2 * np.pi, DISK_SEGMENTS + 1)
        ring = np.stack([np.cos(ang) * sx / 2, np.sin(ang) * sy / 2, np.zeros_like(ang)], axis=1)
        center = np.zeros((DISK_SEGMENTS, 3))
        tris = np.stack([center, ring[1:], ring[:-1]], axis=1)
        # scale the polygon to the true ellipse area so the power is exact
        poly_area = 0.5 * DISK_SEGMENTS * np.sin(2 * np.pi / DISK_SEGMENTS)
        tris *= np.sqrt(np.pi / poly_area)
    return tris


def _falloff(found: list, name: str, warnings: list) -> tuple:
    """(k, smooth) of the Light Falloff nodes a lamp's Emission reads (``found``: (node name, the indices of the
    outputs used: 0 Quadratic, 1 Linear, 2 Constant, smooth)); (0, 0) without one. Two different ones are named in a
    warning and the first is used."""
    kinds = {(k, smooth) for _n, used, smooth in found for k in (used or [0])}
    if not kinds:
        return 0, 0.0
    first = next((k, smooth) for _n, used, smooth in found for k in (used or [0]))
    if len(kinds) > 1:
        warnings.append(f"Light '{name}': its Light Falloff nodes mix falloffs; only one is supported "
                        f"({('Quadratic', 'Linear', 'Constant')[first[0]]}, Smooth {first[1]:g}) and used")
    return first


def _light_node_scale(light, warnings: list, name: str, falloff: list | None = None, registry=None,
                      program: list | None = None):
    """RGB factor of a light's node tree: its Emission node's Color x Strength, each folded to a constant through
    whatever nodes feed it (RGB, Math, Mix, Blackbody, Light Falloff ...; core/materials/nodes); 1 without nodes.
    ``falloff`` (a list of two) receives the (k, smooth) of a Light Falloff node the Emission reads (scene.Lamps).
    A graph that varies over the light (a texture) is compiled into a node program (core/lights/lamp_textures.py)
    appended to ``program`` (with the material ``registry`` its images go to), and the factor is 1; without
    ``program`` (a sun) it is named in a warning and its sockets' own values are used."""
    falloff = [0, 0.0] if falloff is None else falloff
    tree = light.node_tree
    if tree is None or not getattr(light, "use_nodes", True):
        return np.ones(3)
    from .flat_nodes import cycles_output, flat_output
    out = cycles_output(tree, "OUTPUT_LIGHT")
    outs = [flat_output(out)] if out is not None else []
    if not outs or not outs[0].inputs["Surface"].is_linked:
        return np.zeros(3)
    node = outs[0].inputs["Surface"].links[0].from_node
    if node.type != "EMISSION":
        warnings.append(f"Light '{name}': its node tree ends in '{node.name}' ({node.type}), not an Emission node; "
                        "colour x power is used")
        return np.ones(3)
    from .node_graph import GraphCompiler
    notes = []
    images = (lambda image, alpha: registry._texture(light, image, alpha=alpha)) if registry is not None else \
        (lambda image, alpha: 0)
    g = GraphCompiler(images, notes.append)
    if registry is not None:
        g.camera, g.view_layer = registry.camera, registry.view_layer
    g.falloffs = []
    color, strength = g.value(node.inputs["Color"], "color"), g.value(node.inputs["Strength"], "float")
    warnings.extend(f"Light '{name}': {n}" for n in dict.fromkeys(notes))
    falloff[:] = _falloff(g.falloffs, name, warnings)
    if (color.const is None or strength.const is None) and program is not None:
        from ..core.lights.lamp_textures import OUTPUT
        program.append(g.program({OUTPUT: g.emit("scale", {}, [color, strength], ("color",))[0]}))
        return np.ones(3)
    out = []
    for reg, sock in ((color, node.inputs["Color"]), (strength, node.inputs["Strength"])):
        if reg.const is not None:
            out.append(np.asarray(reg.constant_value(), np.float64))
            continue
        warnings.append(f"Light '{name}': its {sock.name} varies over the light (a texture?), which suns do not "
                        "support; the socket's own value is used")
        v = sock.default_value
        out.append(np.array(v[:3] if sock.name == "Color" else v, np.float64))
    return out[0] * out[1]


def _lamp_power(light, name: str, warnings: list, falloff: list | None = None, registry=None,
                program: list | None = None) -> np.ndarray:
    """Colour x Power (W) x 2^Exposure, times the Temperature's colour where the light uses one and its node
    tree's factor (``falloff``, ``registry``, ``program``: see :func:`_light_node_scale`)."""
    power = np.array(light.color[:3], np.float64) * float(light.energy)
    power *= 2.0 ** float(getattr(light, "exposure", 0.0))
    if getattr(light, "use_temperature", False):
        from ..core.lights.blackbody import blackbody_rgb
        power *= blackbody_rgb(float(light.temperature)).astype(np.float64).reshape(3)
    return power * _light_node_scale(light, warnings, name, falloff, registry, program)


def _area(tris: np.ndarray) -> float:
    return float(0.5 * np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1).sum())


class _LampRecord(NamedTuple):
    """What lights/lamp_textures.LampTextures keeps of one lamp (see its fields)."""

    program: object = None
    kind: int = 0
    to_local: np.ndarray = np.zeros((3, 4))
    to_world: np.ndarray = np.eye(3)
    uv_scale: tuple = (0.0, 0.0)
    location: np.ndarray = np.zeros(3)
    color: tuple = (0.0, 0.0, 0.0, 1.0)
    random: float = 0.0
    pass_index: float = 0.0
    sphere_normal: bool = False
    properties: dict = {}


def _texture_record(program, light, inst, m: np.ndarray) -> _LampRecord:
    """A textured lamp's record: its program, kind, frames, UV scale, Object Info, whether its normal is the
    sphere's (a lamp of non-zero Radius: Cycles' point and spot lamps are spheres then, whatever Soft Falloff says)
    and the Object / Instancer attribute values its program reads ({key: rgba}, export/object_properties.py)."""
    from ..core.lights import lamp_textures as lt
    from . import object_properties
    from .meshes import object_random
    obj = inst.object
    if light.type == "AREA":
        sx = float(light.size)
        sy = float(light.size_y) if light.shape in {"RECTANGLE", "ELLIPSE"} else sx
        kind, uv_scale = lt.AREA, (1.0 / max(sx, 1e-12), 1.0 / max(sy, 1e-12))
    elif light.type == "SPOT":
        kind, uv_scale = lt.SPOT, (0.5 / max(np.tan(float(light.spot_size) / 2), 1e-12), 0.0)
    else:
        kind, uv_scale = lt.POINT, (0.0, 0.0)
    try:
        inv = np.linalg.inv(m)
    except np.linalg.LinAlgError:
        inv = np.linalg.pinv(m)
    keys = {k for k in map(object_properties.key_of, program.reads) if k is not None}
    return _LampRecord(program, kind, inv[:3, :4], m[:3, :3], uv_scale, m[:3, 3], tuple(obj.color),
                       object_random(inst), float(getattr(obj, "pass_index", 0)), float(light.shadow_soft_size) > 0,
                       object_properties.instance_values(inst, obj, keys))


def _lamp_textures(records: list, counts: list, textures: list):
    """lights/lamp_textures.LampTextures per lamp triangle from each lamp's :func:`_texture_record` (None: a
    constant lamp) and its triangle count."""
    from ..core.lights.lamp_textures import LampTextures
    from .object_properties import MISSING
    programs, index = [], []
    for r in records:
        index.append(-1 if r is None else len(programs))
        if r is not None:
            programs.append(r.program)
    full = [_LampRecord() if r is None else r for r in records]

    def rep(field, dtype):
        return np.repeat(np.array([getattr(r, field) for r in full], dtype), counts, axis=0)
    keys = sorted({k for r in full for k in r.properties})
    properties = {k: np.repeat(np.array([r.properties.get(k, MISSING) for r in full], np.float32), counts, axis=0)
                  for k in keys}
    return LampTextures(programs, np.repeat(np.array(index, np.int32), counts), rep("kind", np.int8),
                        rep("to_local", np.float32), rep("to_world", np.float32), rep("uv_scale", np.float32),
                        rep("location", np.float32), rep("color", np.float32), rep("random", np.float32),
                        rep("pass_index", np.float32), rep("sphere_normal", bool), textures=textures,
                        properties=properties)


#: points at which a textured lamp's graph is averaged for its share of the lamps' power
_POWER_DIRECTIONS = 256


def _power_scales(lamps) -> np.ndarray:
    """(n,) float32 per lamp triangle: the mean luminance of a textured lamp's colour factor over the directions it
    shines in (point and spot lamps, spots within their cone) or over its surface along its normal (area lamps), at
    least 1e-3 (a lamp dark where it was probed is still picked); 1 for constant lamps."""
    from ..core.lights.lamp_textures import AREA, lamp_texture_factor
    from ..core.materials.params import luminance
    from ..core.sampling import orthonormal_basis
    lt = lamps.textured
    out = np.ones(len(lt.program), np.float32)
    k = _POWER_DIRECTIONS
    i = np.arange(k) + 0.5
    for prog in np.unique(lt.program[lt.program >= 0]):
        rows = np.flatnonzero(lt.program == prog)
        tri = rows[0]
        if lt.kind[tri] == AREA:
            first, count = rows[0], len(rows)
            pick = first + (np.arange(k) % count)
            b1 = (i % 16) / 16
            b2 = (i // 16) / 16
            b1, b2 = np.where(b1 + b2 > 1, 1 - b1, b1), np.where(b1 + b2 > 1, 1 - b2, b2)
            v = lamps.tris.verts[pick].astype(np.float64)
            q = (v[:, 0] + (v[:, 1] - v[:, 0]) * b1[:, None] + (v[:, 2] - v[:, 0]) * b2[:, None]).T
            n = lamps.tris.normals[pick, 0].T
            p = q + n
        else:
            pick = np.full(k, tri)
            z = 1 - 2 * i / k
            if lamps.spot_cos[tri] > -1.5:  # within the cone only
                z = 1 - (1 - float(lamps.spot_cos[tri])) * i / k
            phi = i * np.pi * (3 - np.sqrt(5))
            r = np.sqrt(np.maximum(1 - z * z, 0))
            local = np.stack([r * np.cos(phi), r * np.sin(phi), z])
            axis = lamps.spot_axis[tri] if lamps.spot_cos[tri] > -1.5 else np.array([0.0, 0.0, 1.0])
            t, b = orthonormal_basis(np.asarray(axis, np.float32).reshape(3, 1))
            d = t * local[0] + b * local[1] + np.asarray(axis, np.float64).reshape(3, 1) * local[2]
            q = np.repeat(lt.location[tri].reshape(3, 1), k, axis=1)
            p, n = q + d, d
        f = lamp_texture_factor(lt, pick, p.astype(np.float32), q.astype(np.float32), n.astype(np.float32))
        out[rows] = max(float(np.abs(luminance(f.T)).mean()), 1e-3)
    return out


def export_lamps(depsgraph, registry, warnings: list, groups: dict | None = None) -> Lamps:
    """The depsgraph's Light objects; ``groups`` ({light group name: index}, export/light_groups.py) gives each lamp
    its group (Lamps.group per triangle, sun_group per sun; -1: none)."""
    groups = groups or {}
    parts = []  # (world tris, material index, spot, camera visible, sphere radius, light group, falloff)
    suns = []
    for inst in depsgraph.object_instances:
        obj = inst.object
        if obj.type != "LIGHT" or not inst.show_self:
            continue
        light = obj.data
        m = np.array(inst.matrix_world, np.float64)
        falloff = [0, 0.0]
        program = [] if light.type != "SUN" else None
        power = _lamp_power(light, obj.name, warnings, falloff, registry, program)
        if not np.isfinite(m).all() or not np.isfinite(power).all():
            warnings.append(f"Light '{obj.name}' has a non-finite transform or power and was skipped")
            continue
        if not power.any():  # negative power subtracts light, as in Cycles (sampled by its magnitude)
            continue
        visible = bool(getattr(obj, "visible_camera", True))
        if light.type == "SUN":
            if tuple(falloff) != (0, 0.0):
                warnings.append(f"Sun '{obj.name}': Light Falloff does not apply to a sun; its falloff is ignored")
            axis = m[:3, 2] / max(np.linalg.norm(m[:3, 2]), 1e-30)
            suns.append((axis, np.cos(min(float(light.angle), np.pi) / 2),
                         clamped_radiance(power, f"Sun '{obj.name}' irradiance", warnings),
                         groups.get(getattr(obj, "lightgroup", ""), -1)))
            continue
        if light.type == "AREA":
            local = _area_shape(light)
            world = local @ m[:3, :3].T + m[:3, 3]
            area = _area(world)
            if area <= 0:
                warnings.append(f"Light '{obj.name}' has zero area and was skipped")
                continue
            if getattr(light, "spread", np.pi) < np.pi - 1e-3:
                warnings.append(f"Light '{obj.name}': area light spread below 180° is not supported (treated as 180°)")
            radiance = power / (np.pi * area)
            spot = (np.zeros(3), np.zeros(3), -2.0, 0.0)
            sphere = 0.0
        elif light.type in {"POINT", "SPOT"}:
            r = max(float(light.shadow_soft_size), MIN_RADIUS)
            center = m[:3, 3]
            world = _SPHERE * r + center  # lamps keep their radius whatever the object scale, as in Cycles
            radiance = power / (np.pi * 4 * np.pi * r * r)
            sphere = r
            if light.type == "SPOT":
                axis = -m[:3, 2] / max(np.linalg.norm(m[:3, 2]), 1e-30)
                cos_half = float(np.cos(float(light.spot_size) / 2))
                spot = (center, axis, cos_half, (1 - cos_half) * float(light.spot_blend))
            else:
                spot = (center, np.zeros(3), -2.0, 0.0)
        else:
            warnings.append(f"Light '{obj.name}': type {light.type} is not supported")
            continue
        if not getattr(light, "normalize", True):
            # Normalize off (Blender 4.2+): the power is not spread over the light's surface, as Cycles reads it
            radiance = power / np.pi
        mat = registry.add_row({"name": f"(light {obj.name})", "base_color": (0, 0, 0), "f0": 0.0,
                                "emission": tuple(radiance), "two_sided_emission": False})
        textured = _texture_record(program[0], light, inst, m) if program else None
        parts.append((world.astype(np.float32), mat, spot, visible, sphere,
                      groups.get(getattr(obj, "lightgroup", ""), -1), tuple(falloff), textured))

    lamps = Lamps.empty()
    if parts:
        verts = np.concatenate([p[0] for p in parts])
        counts = [len(p[0]) for p in parts]
        ng = np.cross(verts[:, 1] - verts[:, 0], verts[:, 2] - verts[:, 0])
        ng /= np.maximum(np.linalg.norm(ng, axis=1), 1e-30)[:, None]
        def rep(vals, dtype):
            return np.repeat(np.array(vals, dtype), counts, axis=0)
        lamps.tris = TriangleSet(verts, np.repeat(ng[:, None], 3, axis=1).astype(np.float32),
                                 rep([p[1] for p in parts], np.int32))
        lamps.spot_center = rep([p[2][0] for p in parts], np.float32)
        lamps.spot_axis = rep([p[2][1] for p in parts], np.float32)
        lamps.spot_cos = rep([p[2][2] for p in parts], np.float32)
        lamps.spot_smooth = rep([p[2][3] for p in parts], np.float32)
        lamps.camera_visible = rep([p[3] for p in parts], bool)
        lamps.sphere_radius = rep([p[4] for p in parts], np.float32)
        lamps.group = rep([p[5] for p in parts], np.int16)
        lamps.falloff = rep([p[6][0] for p in parts], np.float32)
        lamps.falloff_smooth = rep([p[6][1] for p in parts], np.float32)
        first = np.repeat(np.cumsum([0] + counts[:-1]), counts)
        lamps.sphere_first = np.where(lamps.sphere_radius > 0, first, -1).astype(np.int32)
        if any(p[7] is not None for p in parts):
            lamps.textured = _lamp_textures([p[7] for p in parts], counts, registry.textures)
            lamps.textured.power_scale = _power_scales(lamps)
    if suns:
        lamps.sun_dir = np.array([s[0] for s in suns], np.float32)
        lamps.sun_cos = np.array([s[1] for s in suns], np.float32)
        lamps.sun_irradiance = np.array([s[2] for s in suns], np.float32)
        lamps.sun_group = np.array([s[3] for s in suns], np.int16)
    return lamps
