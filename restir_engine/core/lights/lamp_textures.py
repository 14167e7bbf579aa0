"""Lamps whose Emission colour or strength comes from a node graph that varies over the lamp (a texture: a gobo, a
pattern projected by a spot, an IES-like profile drawn with the Normal), evaluated as Cycles evaluates a light's
shader: at the point on the lamp, for the receiver it lights.

The graph's value is a colour factor (scene-linear RGB, unitless) on the lamp's constant radiance, which carries
its power, colour and the folded constants of its nodes. What the graph reads at a point q on the lamp seen from a
receiver p (``wo`` = the unit direction from q to p), as Cycles sets up a lamp's shading point:

- Position q; Incoming wo; Normal / True Normal: for point and spot lamps the sphere's outward normal at q (a lamp
  of Radius 0 has none: wo), for area lamps the emitting side's normal;
- Object and Generated: q in the lamp object's space; Object Normal: the normal in that space;
- UV (and Parametric): area lamps (x / size_x + 1/2, y / size_y + 1/2) of q in object space; point lamps the
  sphere mapping of the object-space normal (u = (1 - atan2(x, y) / π) / 2, v = 1 - acos(z) / π); spot lamps the
  image projected over the cone: (1/2 + x f, 1/2 + y f) of the object-space direction to the receiver (z towards
  the cone's axis) with f = cot(spot size / 2) / (2 z);
- Object Info of the lamp object (Location, Color, Alpha, Random, Pass Index) and its Object / Instancer attributes
  (the Attribute node's types: a property of the lamp object or its data); Light Path's ray flags 0 (a lamp's
  shader is evaluated as emission, not by a camera or shadow ray); Ray Length the distance to the receiver.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..materials.nodes.attributes import OBJECT_PROPERTY, OBJECT_PROPERTY_ALPHA
from ..sampling import dot, norm

_F = np.float32
AREA, POINT, SPOT = 0, 1, 2
OUTPUT = "lamp_emission"  # the programs' output: the colour factor (rgb)


@dataclass
class LampTextures:
    """Per lamp triangle (n): ``program`` (n,) int32 index into ``programs`` (-1: the lamp is constant), ``kind``
    (n,) int8 (AREA, POINT, SPOT), ``to_local`` (n, 3, 4) float32 world -> lamp object space, ``to_world`` (n, 3,
    3) float32 the object's linear part (object -> world), ``uv_scale`` (n, 2) float32 (area: 1 / size_x, 1 / size_y
    in object space; spot: cot(spot size / 2) / 2, 0), ``location`` (n, 3), ``color`` (n, 4), ``random`` (n,),
    ``pass_index`` (n,) float32 of the lamp object, ``sphere_normal`` (n,) bool (a point / spot lamp of non-zero
    Radius: the normal is the sphere's), ``power_scale`` (n,) float32 the graph's mean luminance factor (for picking lamps by power).
    ``textures``: the material table's images the programs read; ``properties`` the Object / Instancer attributes
    they read, per lamp triangle (as ObjectTable.properties per instance)."""

    programs: list
    program: np.ndarray
    kind: np.ndarray
    to_local: np.ndarray
    to_world: np.ndarray
    uv_scale: np.ndarray
    location: np.ndarray
    color: np.ndarray
    random: np.ndarray
    pass_index: np.ndarray
    sphere_normal: np.ndarray
    power_scale: np.ndarray = None
    textures: list = field(default_factory=list)
    properties: dict = field(default_factory=dict)  # {"KIND:name": (n, 4) rgba}: Object / Instancer attributes

    def __post_init__(self):
        if self.power_scale is None:
            self.power_scale = np.ones(len(self.program), np.float32)

    def textured(self, tri: np.ndarray) -> np.ndarray:
        """(k,) bool: lamp triangles ``tri`` whose radiance comes from a program."""
        return self.program[tri] >= 0


class LampAttributes:
    """What a lamp's node program reads at points q (3, k) on lamp triangles ``tri`` seen from receivers p (3, k)
    (see the module's docstring); ``normals`` (3, k): the area lamps' emitting side (unused for the others)."""

    def __init__(self, lt: LampTextures, tri: np.ndarray, q: np.ndarray, p: np.ndarray, normals: np.ndarray):
        self.lt, self.tri = lt, np.asarray(tri, np.intp)
        self.textures = lt.textures
        self.camera_ray = False
        self.q = np.asarray(q, np.float32)
        d = np.asarray(p, np.float32) - self.q
        self.dist = norm(d).astype(np.float32)
        self.wo = (d / np.maximum(self.dist, _F(1e-30))).astype(np.float32)
        kind = lt.kind[self.tri]
        n = np.where(kind == AREA, np.asarray(normals, np.float32), self.wo)
        sph = np.flatnonzero(lt.sphere_normal[self.tri] & (kind != AREA))
        if sph.size:
            out = self.q[:, sph] - lt.location[self.tri[sph]].T
            n[:, sph] = out / np.maximum(norm(out), _F(1e-30))
        self.n = n.astype(np.float32)
        self._cache = {}

    def __len__(self) -> int:
        return len(self.tri)

    def world_to_object(self) -> np.ndarray:
        """(k, 3, 4) float64 world-to-object matrices of the lamps."""
        return self.lt.to_local[self.tri].astype(np.float64)

    def object_normal_to_world(self, n) -> np.ndarray:
        m = self.lt.to_local[self.tri][:, :, :3]
        return np.einsum("nji,jn->in", m, np.asarray(n, np.float32)).astype(np.float32)

    def get(self, name: str):
        got = self._cache.get(name)
        if got is None:
            got = self._cache[name] = self._compute(name)
        return got

    def _local_point(self):
        m = self.lt.to_local[self.tri]
        return (np.einsum("nij,jn->in", m[:, :, :3], self.q) + m[:, :, 3].T).astype(np.float32)

    def _local_dir(self, v):
        """World directions (3, k) in object space, unit (a normal goes with the transposed object matrix)."""
        m = self.lt.to_world[self.tri]
        out = np.einsum("nji,jn->in", m, v)
        return (out / np.maximum(norm(out), _F(1e-30))).astype(np.float32)

    def _uv(self):
        k = len(self.tri)
        kind = self.lt.kind[self.tri]
        scale = self.lt.uv_scale[self.tri].T
        uv = np.zeros((3, k), np.float32)
        area = np.flatnonzero(kind == AREA)
        if area.size:
            x = self.get("object")[:2, area] * scale[:, area]
            uv[:2, area] = np.clip(x, -0.5, 0.5) + _F(0.5)
        point = np.flatnonzero(kind == POINT)
        if point.size:
            m = self.lt.to_local[self.tri[point]][:, :, :3]
            d = np.einsum("nij,jn->in", m, self.n[:, point])
            d /= np.maximum(norm(d), _F(1e-30))
            u = np.where((d[0] == 0) & (d[1] == 0), _F(0), (1 - np.arctan2(d[0], d[1]) / _F(np.pi)) / 2)
            uv[0, point] = u
            uv[1, point] = 1 - np.arccos(np.clip(d[2], -1, 1)) / _F(np.pi)
        spot = np.flatnonzero(kind == SPOT)
        if spot.size:
            m = self.lt.to_local[self.tri[spot]][:, :, :3]
            r = np.einsum("nij,jn->in", m, self.wo[:, spot])
            r /= np.maximum(norm(r), _F(1e-30))
            z = -r[2]
            f = scale[0, spot] / np.where(np.abs(z) > 1e-30, z, _F(1e-30))
            uv[0, spot] = 0.5 + r[0] * f
            uv[1, spot] = 0.5 + r[1] * f
        return uv

    def _compute(self, name: str):
        k = len(self.tri)
        lt, tri = self.lt, self.tri
        if name == "position":
            return self.q
        if name in {"normal", "true_normal"}:
            return self.n
        if name == "incoming":
            return self.wo
        if name == "reflection":
            return (2 * dot(self.n, self.wo) * self.n - self.wo).astype(np.float32)
        if name in {"object", "generated"}:
            return self._local_point()
        if name == "object_normal":
            return self._local_dir(self.n)
        if name in {"uv", "parametric"}:
            return self._uv()
        if name == "object_location":
            return np.ascontiguousarray(lt.location[tri].T, dtype=np.float32)
        if name == "object_color":
            return np.ascontiguousarray(lt.color[tri, :3].T, dtype=np.float32)
        if name == "object_alpha":
            return lt.color[tri, 3].astype(np.float32)
        if name == "object_random":
            return lt.random[tri].astype(np.float32)
        if name == "object_index":
            return lt.pass_index[tri].astype(np.float32)
        if name == "ray_length":
            return self.dist
        if name == "ray_depth":  # evaluated as emission: one bounce past the lit point (taken as a camera hit's)
            return np.ones(k, np.float32)
        if name == "footprint":
            return np.full(k, _F(1e-3), np.float32)
        if name in {"tangent_uv", "tangent_sign"}:
            return None
        if name.startswith((OBJECT_PROPERTY, OBJECT_PROPERTY_ALPHA)):
            alpha = name.startswith(OBJECT_PROPERTY_ALPHA)
            table = lt.properties.get(name[len(OBJECT_PROPERTY_ALPHA if alpha else OBJECT_PROPERTY):])
            if table is None:
                return np.zeros(k if alpha else (3, k), np.float32)
            return np.ascontiguousarray(table[tri, 3] if alpha else table[tri, :3].T, dtype=np.float32)
        if name == "tangent" or name.startswith("attr:"):
            return np.zeros((3, k), np.float32)
        return np.zeros(k, np.float32)  # backfacing, Light Path flags, attribute and property alphas


def lamp_texture_factor(lt: LampTextures, tri: np.ndarray, p: np.ndarray, q: np.ndarray,
                        normals: np.ndarray) -> np.ndarray:
    """Colour factor (3, k) float32 of lamp triangles ``tri`` at light points q seen from receivers p ((3, k)
    rows; ``normals`` the lamp triangles' emitting normals there): the programs' value, 1 for constant lamps.
    Loops over programs, not points."""
    out = np.ones((3, len(tri)), np.float32)
    prog = lt.program[tri]
    for k in np.unique(prog[prog >= 0]):
        rows = np.flatnonzero(prog == k)
        attrs = LampAttributes(lt, tri[rows], q[:, rows], p[:, rows], normals[:, rows])
        out[:, rows] = lt.programs[int(k)].run(attrs, (OUTPUT,))[OUTPUT]
    return out
