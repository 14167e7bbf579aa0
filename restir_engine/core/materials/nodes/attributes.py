"""The attributes a node program reads at a batch of surface points, computed on first use.

World-space vectors are (3, n) float32 rows; normals face the viewer where the view is known. Names (as the
exporter's programs read them): "position", "normal" (shading), "true_normal", "incoming" (towards the viewer),
"backfacing" (1 or 0), "uv" (u, v, 0), "generated" (the object's texture space, [0, 1] over its box),
"object" (object-space position), "object_normal", "reflection", "parametric", "object_location",
"object_color", "object_alpha", "object_random", "is_camera_ray" / "is_shadow_ray" (1 or 0: Light Path, as the
ray that reached the point), the Light Path outputs of PATH_ATTRIBUTES (the ray's type and the bounces before it,
given per hit by the path that reached it; else :data:`SURFACE_DEFAULT` / :data:`EMISSION_DEFAULT`), "attr:<name>" / "attr_alpha:<name>" for a colour attribute
(RGB and alpha, linear), OBJECT_PROPERTY / OBJECT_PROPERTY_ALPHA + "<KIND>:<name>" for a property of the instance's
object (the Attribute node's Object and Instancer types: ObjectTable.properties, (r, g, b, a) per instance), "tangent_uv" / "tangent_sign" (the UV map's interpolated tangent and bitangent sign, or
None without tangents) and "footprint" (a pixel's width on the surface, scene units)."""
from __future__ import annotations

import numpy as np

from ...sampling import barycentric, dot, inverse3, norm

_F = np.float32
#: Light Path outputs read per hit (1 / 0 flags and counts) as Cycles defines them for the ray reaching a point: its
#: lobe (diffuse, glossy or singular: glossy counts singular too), side (reflection or transmission), the bounces
#: before it (Ray Depth; diffuse and glossy reflections and transmissions apart) and the transparent surfaces passed
PATH_ATTRIBUTES = ("is_diffuse_ray", "is_glossy_ray", "is_singular_ray", "is_reflection_ray", "is_transmission_ray",
                   "ray_depth", "diffuse_depth", "glossy_depth", "transmission_depth", "transparent_depth")
#: what a surface reached by an unknown ray reads: a diffuse reflection after one bounce
SURFACE_DEFAULT = {"is_diffuse_ray": 1.0, "is_reflection_ray": 1.0, "ray_depth": 1.0, "diffuse_depth": 1.0}
#: what an emitter sampled for next-event estimation, or a surface a shadow ray passes, reads (Cycles: no ray type,
#: one bounce past the lit point, taken here as a camera hit's)
EMISSION_DEFAULT = {"ray_depth": 1.0}
OBJECT_PROPERTY = "object_property:"  # + "KIND:name": RGB (3, n)
OBJECT_PROPERTY_ALPHA = "object_property_alpha:"  # + "KIND:name": alpha (n,)


class HitAttributes:
    """Surface points on triangles ``prim`` of ``tris`` (scene.TriangleSet) at barycentrics (b1, b2); ``wo``
    (3, n) towards the viewer, ``normal`` and ``true_normal`` (3, n) facing it, when the caller has them;
    ``textures``: the material table's images."""

    def __init__(self, tris, prim, b1, b2, textures, wo=None, normal=None, true_normal=None, footprint=None,
                 camera_ray: bool = False, ray_length=None, shadow_ray: bool = False, path: dict | None = None,
                 emission: bool = False):
        self.tris, self.prim = tris, np.asarray(prim, np.intp)
        self.b1, self.b2 = np.asarray(b1, np.float32), np.asarray(b2, np.float32)
        self.textures = textures
        self._cache = {}
        if wo is not None:
            self._cache["incoming"] = wo
        if normal is not None:
            self._cache["normal"] = normal
        if true_normal is not None:
            self._cache["true_normal"] = true_normal
        self._wo = wo
        self._given = {"normal": normal, "true_normal": true_normal, "footprint": footprint}
        self.camera_ray = bool(camera_ray)
        self._cache["is_camera_ray"] = np.full(len(self.prim), _F(1.0 if camera_ray else 0.0), np.float32)
        self.shadow_ray = bool(shadow_ray)
        self._cache["is_shadow_ray"] = np.full(len(self.prim), _F(1.0 if shadow_ray else 0.0), np.float32)
        if ray_length is not None:
            self._cache["ray_length"] = np.broadcast_to(np.asarray(ray_length, np.float32), self.b1.shape)
        if footprint is not None:
            self._cache["footprint"] = np.broadcast_to(np.asarray(footprint, np.float32), self.b1.shape)
        # Light Path: the given path's values (read on first use), else a camera hit's (all 0) or a default
        self._path = path or {}
        self._path_default = {} if camera_ray else (EMISSION_DEFAULT if emission or shadow_ray else SURFACE_DEFAULT)

    def shifted(self, delta) -> "HitAttributes":
        """The same points moved by ``delta`` (3, n) in their triangles' planes (barycentrics moved, so that
        positions, texture coordinates and attributes all move with them); normals and the view stay."""
        v = np.take(self.tris.verts, self.prim, axis=0)
        e1, e2 = (v[:, 1] - v[:, 0]).T, (v[:, 2] - v[:, 0]).T
        g11, g12, g22 = dot(e1, e1), dot(e1, e2), dot(e2, e2)
        r1, r2 = dot(e1, delta), dot(e2, delta)
        det = g11 * g22 - g12 * g12
        det = np.where(np.abs(det) > 1e-30, det, _F(1e30))
        db1, db2 = (g22 * r1 - g12 * r2) / det, (g11 * r2 - g12 * r1) / det
        return HitAttributes(self.tris, self.prim, self.b1 + db1, self.b2 + db2, self.textures, wo=self._wo,
                             normal=self.get("normal"), true_normal=self.get("true_normal"),
                             footprint=self.get("footprint"), camera_ray=self.camera_ray,
                             ray_length=self._cache.get("ray_length"), shadow_ray=self.shadow_ray,
                             path={k: self.get(k) for k in PATH_ATTRIBUTES})

    def object_normal_to_world(self, n) -> np.ndarray:
        """Object-space normals (3, n) in world space (the inverse transpose of each instance's matrix)."""
        inst, objs = self._instances()
        if inst is None:
            return np.asarray(n, np.float32)
        m = objs.world_to_object[inst][:, :, :3].astype(np.float32)  # world -> object; normals go with Mᵀ
        return np.einsum("nji,jn->in", m, np.asarray(n, np.float32)).astype(np.float32)

    def world_to_object(self) -> np.ndarray | None:
        """(n, 3, 4) float64 world-to-object matrices of the hits' instances; None without instances."""
        inst, objs = self._instances()
        return None if inst is None else objs.world_to_object[inst].astype(np.float64)

    def __len__(self) -> int:
        return len(self.prim)

    def get(self, name: str):
        got = self._cache.get(name)
        if got is None:
            got = self._cache[name] = self._path_value(name) if name in PATH_ATTRIBUTES else self._compute(name)
        return got

    def _path_value(self, name: str) -> np.ndarray:
        got = self._path.get(name)
        if got is not None:
            return np.ascontiguousarray(np.broadcast_to(np.asarray(got, np.float32), self.b1.shape))
        return np.full(len(self.prim), _F(self._path_default.get(name, 0.0)), np.float32)

    def _corners(self, data):
        c = np.take(data, self.prim, axis=0)  # (n, 3 corners, k)
        return barycentric(c[:, 0].T, c[:, 1].T, c[:, 2].T, self.b1, self.b2).astype(np.float32)

    def _geometric(self):
        v = np.take(self.tris.verts, self.prim, axis=0)
        ng = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]).T
        return (ng / np.maximum(norm(ng), _F(1e-30))).astype(np.float32)

    def _facing(self, n):
        wo = self._wo
        if wo is None:
            return n
        return np.where(dot(self._geometric(), wo) < 0, -n, n).astype(np.float32)

    def _instances(self):
        inst = self.tris.instance
        objs = getattr(self.tris, "objects", None)
        if inst is None or objs is None or len(objs.world_to_object) == 0:
            return None, None
        return np.take(inst, self.prim), objs

    def _compute(self, name: str):
        n = len(self.prim)
        if name == "position":
            return self._corners(self.tris.verts)
        if name == "true_normal":
            return self._facing(self._geometric())
        if name == "normal":
            s = self._corners(self.tris.normals)
            ln = norm(s)
            ok = np.isfinite(ln) & (ln > 0.5)
            s = np.where(ok, s / np.where(ok, ln, 1), self._geometric())
            return self._facing(s.astype(np.float32))
        if name == "incoming":
            return self.get("normal")
        if name == "backfacing":
            if self._wo is None:
                return np.zeros(n, np.float32)
            return (dot(self._geometric(), self._wo) < 0).astype(np.float32)
        if name == "uv":
            if self.tris.uvs is None:
                return np.zeros((3, n), np.float32)
            uv = self._corners(self.tris.uvs)
            return np.concatenate([uv, np.zeros((1, n), np.float32)])
        if name == "parametric":
            return np.stack([1 - self.b1 - self.b2, self.b1, np.zeros(n, np.float32)]).astype(np.float32)
        if name == "reflection":
            nn, wi = self.get("normal"), self.get("incoming")
            return (2 * dot(nn, wi) * nn - wi).astype(np.float32)
        if name == "object":
            local = getattr(self.tris, "local_verts", None)
            if local is not None:  # the exported object-space corners: exact where the object is flat
                return self._corners(local)
            inst, objs = self._instances()
            if inst is None:
                return self.get("position")
            # the corners taken to object space in float64, then interpolated: a flat object's flat axis stays
            # exactly flat (a checker's cell boundary on it must not flicker with rounding)
            m = objs.world_to_object[inst].astype(np.float64)  # (n, 3, 4)
            c = np.take(self.tris.verts, self.prim, axis=0).astype(np.float64)  # (n, 3 corners, 3)
            local = np.einsum("nij,nkj->nki", m[:, :, :3], c) + m[:, None, :, 3]
            b1, b2 = self.b1.astype(np.float64), self.b2.astype(np.float64)
            p = local[:, 0] * (1 - b1 - b2)[:, None] + local[:, 1] * b1[:, None] + local[:, 2] * b2[:, None]
            return np.ascontiguousarray(p.T, dtype=np.float32)
        if name == "generated":
            inst, objs = self._instances()
            if inst is None:
                return self.get("object")
            return ((self.get("object").astype(np.float64) - objs.texspace_lo[inst].T) / objs.texspace_size[inst].T
                    ).astype(np.float32)
        if name == "object_normal":
            inst, objs = self._instances()
            nn = self.get("normal")
            if inst is None:
                return nn
            m = objs.world_to_object[inst][:, :, :3]  # normals go with the transposed world matrix: (M⁻¹)⁻ᵀ = Mᵀ
            lin = inverse3(m).astype(np.float32)
            out = np.einsum("nji,jn->in", lin, nn)
            return (out / np.maximum(norm(out), _F(1e-30))).astype(np.float32)
        if name in {"object_location", "object_color", "object_alpha", "object_random"}:
            inst, objs = self._instances()
            if inst is None:
                return np.zeros((3, n) if name in {"object_location", "object_color"} else n, np.float32)
            data = {"object_location": objs.location, "object_color": objs.color[:, :3],
                    "object_alpha": objs.color[:, 3], "object_random": objs.random}[name]
            return np.ascontiguousarray(data[inst].T, dtype=np.float32)
        if name in {"tangent_uv", "tangent_sign"}:
            tg = getattr(self.tris, "tangents", None)
            if tg is None:
                return None
            t = np.take(tg, self.prim, axis=0)  # (n, 3 corners, 4): xyz, sign
            if name == "tangent_sign":
                return np.ascontiguousarray(t[:, 0, 3], dtype=np.float32)
            tan = barycentric(t[:, 0, :3].T, t[:, 1, :3].T, t[:, 2, :3].T, self.b1, self.b2)
            return (tan / np.maximum(norm(tan), _F(1e-30))).astype(np.float32)
        if name == "footprint":
            return np.full(n, _F(1e-3), np.float32)
        if name == "tangent":  # Geometry > Tangent: radial about the object's Z axis, as Cycles' default
            g = self.get("generated")
            d = np.stack([_F(0.5) - g[1], g[0] - _F(0.5), np.zeros(n, np.float32)])
            d = self.object_normal_to_world(d)
            nn = self.get("normal")
            t = np.cross(d.T, nn.T).T
            t = np.cross(nn.T, t.T).T
            return (t / np.maximum(norm(t), _F(1e-30))).astype(np.float32)
        if name == "ray_length":
            return np.zeros(n, np.float32)
        if name == "object_index":
            inst, objs = self._instances()
            idx = None if inst is None else getattr(objs, "pass_index", None)
            return np.zeros(n, np.float32) if idx is None else np.ascontiguousarray(idx[inst], dtype=np.float32)
        if name.startswith((OBJECT_PROPERTY, OBJECT_PROPERTY_ALPHA)):
            return self._object_property(name)
        if name.startswith("attr:") or name.startswith("attr_alpha:"):
            key = name.split(":", 1)[1]
            data = (getattr(self.tris, "attributes", None) or {}).get(key)
            if data is None:
                return np.zeros((3, n) if name.startswith("attr:") else n, np.float32)
            vals = self._corners(data)  # (4, n)
            return np.ascontiguousarray(vals[:3]) if name.startswith("attr:") else np.ascontiguousarray(vals[3])
        raise KeyError(f"unknown hit attribute {name!r}")

    def _object_property(self, name: str):
        """An Object / Instancer attribute's RGB (3, n) or alpha (n,) at the points (0 without an object table)."""
        alpha = name.startswith(OBJECT_PROPERTY_ALPHA)
        key = name[len(OBJECT_PROPERTY_ALPHA if alpha else OBJECT_PROPERTY):]
        inst, objs = self._instances()
        table = None if inst is None else (getattr(objs, "properties", None) or {}).get(key)
        n = len(self.prim)
        if table is None:
            return np.zeros(n if alpha else (3, n), np.float32)
        return np.ascontiguousarray(table[inst, 3] if alpha else table[inst, :3].T, dtype=np.float32)


class DirectionAttributes:
    """The attributes a world's node program reads for directions ``dirs`` (3, n) (unit, world space, pointing away
    from the scene), as Cycles gives a world shader: the direction as position and texture coordinates
    (Generated, Object), the opposite one as the normal and the incoming view; no surface (UV 0, not backfacing).
    ``without_sun``: Sky Textures leave their sun discs out (the world's image for sampling; lights/world.py samples
    the discs apart)."""

    def __init__(self, dirs, textures, camera_ray: bool = False, without_sun: bool = False):
        self.dirs = np.ascontiguousarray(dirs, np.float32)
        self.textures = textures
        self.camera_ray = camera_ray
        self.without_sun = without_sun

    def __len__(self) -> int:
        return self.dirs.shape[1]

    def world_to_object(self):
        """None: a world shader has no object (object space is world space)."""
        return None

    def get(self, name: str):
        n = len(self)
        if name in {"position", "generated", "object"}:
            return self.dirs
        if name in {"normal", "true_normal", "incoming", "object_normal"}:
            return -self.dirs
        if name == "reflection":
            return self.dirs
        if name in {"uv", "parametric", "object_location", "object_color", "tangent"} or \
                name.startswith(("attr:", OBJECT_PROPERTY)):
            return np.zeros((3, n), np.float32)
        if name == "footprint":
            return np.full(n, _F(1e-3), np.float32)
        if name == "is_camera_ray":
            return np.full(n, _F(1.0 if self.camera_ray else 0.0), np.float32)
        if name == "is_shadow_ray":
            return np.zeros(n, np.float32)
        if name == "ray_length":
            return np.full(n, _F(3.4e38), np.float32)
        if name in {"tangent_uv", "tangent_sign"}:
            return None
        return np.zeros(n, np.float32)  # backfacing, object alpha / random, attribute and property alphas
