"""One light table over every emitter, with power-proportional selection.

Entries, in order: emissive scene triangles, Blender lamps (non-occluding: area-light triangles, and point/spot
spheres, one entry per sphere) and suns (distant lights). Everything before the suns is a "surface light" whose
points (light, b1, b2) are barycentrics on a triangle, or on a sphere z = 1 - 2 b1, φ = 2π b2 around its centre
(uniform in area for uniform (b1, b2)). Next-event estimation (:meth:`LightTable.sample`) samples a triangle
uniformly in area, p_ω = p_select · (1/A) · d² / |cos θ_light|, and a sphere uniformly in the cone it subtends
from the receiver (as Cycles), p_ω = p_select / (2π (1 - cos θ_max)): no sample lands on its far side.
Light points for resampling (light_tiles.sample_points) are uniform in area on both kinds.
Suns are sampled uniformly in their cone and are handled by light sampling only (a BSDF ray
that escapes never collects a sun, except a delta ray from glass, where no light is sampled), which keeps the MIS
estimator unbiased.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..materials.nodes import HitAttributes, emission_programs, run_programs
from ..materials.params import luminance
from ..materials.textures import apply_texture, mean_color
from ..sampling import AliasTable, barycentric, cols, dot, norm, orthonormal_basis, uniform_triangle, vmax
from ..scene import MaterialTable, Scene, TriangleSet
from .receiver import receiver_factor
from .sphere import one_minus_cos_cone, sphere_coords, sphere_direction

EMPTY = np.zeros(0, np.int64)


def triangle_geometry(verts: np.ndarray):
    """Unit geometric normals (winding order) (n, 3) and areas (n,) of (n, 3, 3) triangles."""
    c = np.cross(verts[:, 1] - verts[:, 0], verts[:, 2] - verts[:, 0])
    ln = np.sqrt(c[:, 0] * c[:, 0] + c[:, 1] * c[:, 1] + c[:, 2] * c[:, 2])
    ng = c / np.maximum(ln, 1e-30)[:, None]
    return ng.astype(np.float32), (0.5 * ln).astype(np.float32)


def emitted_radiance(tris: TriangleSet, materials: MaterialTable, tri: np.ndarray,
                     b1: np.ndarray, b2: np.ndarray, wo: np.ndarray | None = None, camera_ray: bool = False,
                     footprint: np.ndarray | None = None, path: dict | None = None,
                     sampled: bool = False) -> np.ndarray:
    """Emitted radiance (3, n) rows, W·sr⁻¹·m⁻², at barycentrics (b1, b2) of triangles ``tri``, towards unit
    directions ``wo`` (3, n) where a node program reads the view (Layer Weight, Fresnel, Incoming, Backfacing;
    without ``wo`` the view is along the surface normal); ``camera_ray``: seen by camera rays (Light Path);
    ``footprint`` (n,): the pixel's width there (scene units), where known; ``path``: the Light Path values of the
    rays that found the points (attributes.PATH_ATTRIBUTES, (n,) each), or ``sampled``: points chosen by light
    sampling (Light Path reads them as emission)."""
    mat = tris.material[tri]
    le = np.take(materials.emission, mat, axis=0)
    if tris.uvs is not None and (materials.emit_tex[mat] >= 0).any():
        c = np.take(tris.uvs, tri, axis=0)
        uv = barycentric(c[:, 0], c[:, 1], c[:, 2], b1[:, None], b2[:, None])  # (n, 2) texture coordinates
        le = apply_texture(le, materials.emit_tex[mat], uv, materials.textures)
    le = np.ascontiguousarray(le.T, dtype=np.float32)
    for rows, out in run_programs(materials, mat, lambda r: HitAttributes(
            tris, tri[r], b1[r], b2[r], materials.textures, wo=None if wo is None else cols(wo, r),
            camera_ray=camera_ray, footprint=None if footprint is None else footprint[r],
            path=None if path is None else {k: v[r] for k, v in path.items()}, emission=sampled), ("emission",)):
        le[:, rows] = out["emission"]
    return le


#: points per triangle at which an emission program is evaluated to estimate the triangle's power: the centroid,
#: the midpoints towards the corners and the corners (barycentrics b1, b2)
_POWER_POINTS = np.array([[1 / 3, 1 / 3], [2 / 3, 1 / 6], [1 / 6, 2 / 3], [1 / 6, 1 / 6],
                          [1, 0], [0, 1], [0, 0]], np.float32)


def program_emission_density(tris: TriangleSet, materials: MaterialTable) -> tuple:
    """(triangles, luminance (k,)) of the triangles whose material's node program computes the emission: the mean
    emitted luminance over :data:`_POWER_POINTS` (for power-proportional selection), at least a tenth of their
    material's mean over all of them (a triangle whose points happen to be dark still gets picked), and a tiny
    positive value where the material is dark at every point (hits on it still count its emission)."""
    prog = emission_programs(materials)
    tri = np.flatnonzero(prog[tris.material]) if len(tris) else EMPTY
    if not tri.size:
        return tri, np.zeros(0, np.float32)
    k = len(_POWER_POINTS)
    pts = np.repeat(tri, k)
    b = np.tile(_POWER_POINTS, (tri.size, 1))
    le = emitted_radiance(tris, materials, pts, b[:, 0], b[:, 1], sampled=True)
    dens = np.maximum(luminance(le.T), 0).reshape(tri.size, k).mean(axis=1)
    mat = tris.material[tri]
    sums = np.bincount(mat, dens, minlength=len(materials.emission))
    counts = np.maximum(np.bincount(mat, minlength=len(materials.emission)), 1)
    floor = (sums / counts)[mat] * 0.1
    return tri, np.maximum(np.maximum(dens, floor), 1e-12).astype(np.float32)


@dataclass
class LightSample:
    """Per shading point (n): unit direction wi (3, n), distance (n,) (inf for suns), radiance Le (3, n)
    arriving along -wi, pdf (n,) in solid angle (selection included; 0 = no light), delta (n,) bool,
    pos (3, n) the sampled point on a triangle light (unused for suns), light (n,) the light's index (triangle
    lights, then suns; -1: none)."""

    pos: np.ndarray
    wi: np.ndarray
    dist: np.ndarray
    le: np.ndarray
    pdf: np.ndarray
    delta: np.ndarray
    light: np.ndarray = None

    @staticmethod
    def zeros(n: int) -> "LightSample":
        return LightSample(np.zeros((3, n), np.float32), np.zeros((3, n), np.float32), np.zeros(n, np.float32),
                           np.zeros((3, n), np.float32), np.zeros(n, np.float32), np.zeros(n, bool),
                           np.full(n, -1, np.int64))


class LightTable:
    def __init__(self, scene: Scene, scene_radius: float):
        geom, lamps, mats = scene.geometry, scene.lamps, scene.materials
        self.scene_radius = scene_radius
        # emissive scene triangles: non-zero emission (texture mean included)
        emit_lum = luminance(mats.emission)
        tex_mean = np.array([luminance(mean_color(t)[None])[0] for t in mats.textures], np.float32)
        emit_scale = np.where(mats.emit_tex >= 0, tex_mean[np.maximum(mats.emit_tex, 0)] if len(tex_mean) else 0.0, 1.0)
        sides = np.where(mats.two_sided_emission, 2.0, 1.0) * np.pi
        mat_power_density = np.abs(emit_lum) * emit_scale * sides  # |power|: a negative light is sampled too
        geom_density = mat_power_density[geom.material] if len(geom) else np.zeros(0)
        prog_tri, prog_density = program_emission_density(geom, mats)
        if prog_tri.size:  # emission from node programs: per triangle
            geom_density = geom_density.copy()
            geom_density[prog_tri] = np.abs(prog_density) * sides[geom.material[prog_tri]]
        g_idx = np.flatnonzero(geom_density > 0) if len(geom) else np.zeros(0, np.int64)
        # lamp entries: area-light triangles, and the first proxy triangle of each point/spot sphere
        first_of_sphere = (lamps.sphere_first < 0) | (lamps.sphere_first == np.arange(len(lamps.sphere_first)))
        l_idx = np.flatnonzero((mat_power_density[lamps.tris.material] > 0) & first_of_sphere) if len(lamps.tris) \
            else np.zeros(0, np.int64)
        self.geom_ids = g_idx
        self.lamp_ids = l_idx
        self.tri_verts = np.concatenate([geom.verts[g_idx], lamps.tris.verts[l_idx]]).astype(np.float32)
        self.tri_normal, self.tri_area = triangle_geometry(self.tri_verts) if len(self.tri_verts) else (
            np.zeros((0, 3), np.float32), np.zeros(0, np.float32))
        # spheres: radius (0 = a triangle light), centre as corner 0 with zero edges, area 4πr²
        self.sphere_r = np.concatenate([np.zeros(len(g_idx), np.float32), lamps.sphere_radius[l_idx]]).astype(np.float32)
        sph = np.flatnonzero(self.sphere_r > 0)
        self.any_sphere = bool(sph.size)
        if sph.size:
            self.tri_verts[sph] = lamps.spot_center[l_idx[sph - len(g_idx)]][:, None, :]
            self.tri_normal[sph] = 0.0
            self.tri_area[sph] = 4.0 * np.pi * self.sphere_r[sph] ** 2
        tri_mat = np.concatenate([geom.material[g_idx], lamps.tris.material[l_idx]]).astype(np.int64)
        self.tri_two_sided = mats.two_sided_emission[tri_mat] if len(tri_mat) else np.zeros(0, bool)
        # (3, n_tri) rows for column gathers: corner 0, edges to corners 1 and 2, unit normal (light_tiles)
        v = self.tri_verts
        self.rows_v0 = np.ascontiguousarray(v[:, 0].T)
        self.rows_e1 = np.ascontiguousarray((v[:, 1] - v[:, 0]).T)
        self.rows_e2 = np.ascontiguousarray((v[:, 2] - v[:, 0]).T)
        self.rows_normal = np.ascontiguousarray(self.tri_normal.T)
        # radiance of each light where no texture modulates it (most lights): one gather per point
        self.tri_le = mats.emission[tri_mat].astype(np.float32) if len(tri_mat) else np.zeros((0, 3), np.float32)
        tri_uvs = len(tri_mat) and (geom.uvs is not None or lamps.tris.uvs is not None)
        self.tri_textured = (mats.emit_tex[tri_mat] >= 0) if tri_uvs else np.zeros(len(tri_mat), bool)
        if prog_tri.size:  # emission from node programs: evaluated at each point, like a texture
            self.tri_textured = self.tri_textured | emission_programs(mats)[tri_mat]
        self.any_textured = bool(self.tri_textured.any())
        self.rows_le = np.ascontiguousarray(self.tri_le.T)
        self.any_spots = bool(len(lamps.tris) and lamps.receiver_dependent()[l_idx].any())
        # power (W, luminance-weighted) decides selection; zero-area triangles get zero power
        lamp_density = mat_power_density[lamps.tris.material[l_idx]]
        if lamps.textured is not None:  # a textured lamp's graph scales its power (lights/lamp_textures.py)
            lamp_density = lamp_density * lamps.textured.power_scale[l_idx]
        tri_density = np.concatenate([geom_density[g_idx], lamp_density]) if len(tri_mat) else np.zeros(0)
        tri_power = tri_density * self.tri_area if len(tri_mat) else np.zeros(0, np.float32)
        sun_power = np.abs(luminance(lamps.sun_irradiance)) * np.pi * scene_radius ** 2 if len(lamps.sun_dir) \
            else np.zeros(0)
        self.n_tri = len(self.tri_verts)
        self.n_geom = len(g_idx)
        self.n_sun = len(lamps.sun_dir)
        power = np.concatenate([tri_power, sun_power]).astype(np.float64)
        self.power = power
        self.geom_to_light = np.full(len(geom), -1, np.int64)
        self.geom_to_light[g_idx] = np.arange(len(g_idx))
        self.lamp_to_light = np.full(len(lamps.tris), -1, np.int64)
        self.lamp_to_light[l_idx] = len(g_idx) + np.arange(len(l_idx))
        proxy = np.flatnonzero(lamps.sphere_first >= 0) if len(lamps.tris) else EMPTY
        self.lamp_to_light[proxy] = self.lamp_to_light[lamps.sphere_first[proxy]]  # every proxy triangle: its sphere
        self.alias = AliasTable(power) if (power > 0).any() else None
        # separate tables for ReSTIR: triangle lights are resampled, suns are light-sampled on their own
        self.tri_alias = AliasTable(power[:self.n_tri]) if (power[:self.n_tri] > 0).any() else None
        self.sun_alias = AliasTable(power[self.n_tri:]) if (power[self.n_tri:] > 0).any() else None
        # float32 per-light pdfs in area measure (m⁻²): selection by ``alias`` (all lights) or ``tri_alias``
        area = np.maximum(self.tri_area, 1e-30)
        self.sel_pdf_area = (self.alias.pdf[:self.n_tri] / area).astype(np.float32) if self.alias is not None \
            else np.zeros(self.n_tri, np.float32)
        self.tri_pdf_area = (self.tri_alias.pdf / area).astype(np.float32) if self.tri_alias is not None \
            else np.zeros(self.n_tri, np.float32)
        self.sel_pdf = self.alias.pdf[:self.n_tri].astype(np.float64) if self.alias is not None \
            else np.zeros(self.n_tri)
        self.scene = scene
        # stable ids across frames: scene triangle index, or len(scene triangles) + lamp triangle index
        self.light_uid = np.concatenate([g_idx, len(geom) + l_idx]).astype(np.int64)
        self.uid_space = (len(geom), len(lamps.tris))
        self.signature = (self.n_tri, self.n_sun, hash(power.tobytes()), False)
        self.env = None  # world_points.WorldSphere: the world as light points for reservoirs (attach_world)
        self.env_index = self.n_tri  # the light index of a world point in reservoirs

    def attach_world(self, sphere) -> None:
        """Let reservoirs hold points of the world (a world_points.WorldSphere) under light index ``env_index``
        (= n_tri, after every surface light); its stable id is one past the lamp triangles'."""
        self.env = sphere
        self.light_uid = np.concatenate([self.light_uid, [int(sum(self.uid_space))]]).astype(np.int64)
        self.signature = self.signature[:3] + (True,)

    def env_rows(self, light: np.ndarray) -> np.ndarray:
        """Positions in ``light`` of world points (none without an attached world)."""
        return np.flatnonzero(light == self.env_index) if self.env is not None else EMPTY

    @property
    def empty(self) -> bool:
        return self.alias is None

    def tri_pdf_solid_angle(self, light: np.ndarray, dist: np.ndarray, cos_light: np.ndarray) -> np.ndarray:
        """Solid-angle pdf with which :meth:`sample` would pick this point of triangle light ``light`` (a
        sphere's pdf depends on the receiver: :meth:`pdf_solid_angle`)."""
        return self.sel_pdf_area[light] * (dist * dist / np.maximum(np.abs(cos_light), np.float32(1e-8)))

    def pdf_solid_angle(self, light: np.ndarray, receiver: np.ndarray, dist: np.ndarray,
                        cos_light: np.ndarray) -> np.ndarray:
        """Solid-angle pdf (n,) with which :meth:`sample` picks the point of surface light ``light`` at distance
        ``dist`` and light cosine ``cos_light`` from ``receiver`` (3, n): triangles by area, spheres by cone."""
        pdf = self.tri_pdf_solid_angle(light, dist, cos_light)
        sph = self._spheres(light)
        if sph.size:
            pdf[sph] = self._cone_pdf(light[sph], np.take(receiver, sph, axis=1), dist[sph], cos_light[sph])
        return pdf

    def _spheres(self, light: np.ndarray) -> np.ndarray:
        """Positions in ``light`` of sphere lights."""
        return np.flatnonzero(self.sphere_r[light] > 0) if self.any_sphere else EMPTY

    def _from_points(self, light, p):
        """Spheres ``light`` seen from points p (3, k), in float64: the vector to the centre (3, k), its length
        (k,) and the radius (k,)."""
        pc = np.take(self.rows_v0, light, axis=1).astype(np.float64) - p.astype(np.float64)
        return pc, np.sqrt(np.einsum("ij,ij->j", pc, pc)), self.sphere_r[light].astype(np.float64)

    def area_coords(self, light: np.ndarray, u2: np.ndarray, u3: np.ndarray):
        """Point coordinates (b1, b2) uniform in area on surface lights ``light`` from uniforms u2, u3:
        barycentrics on triangles, the uniforms themselves on spheres (sphere coordinates)."""
        b1, b2 = uniform_triangle(u2, u3)
        sph = self._spheres(light)
        if sph.size:
            b1[sph], b2[sph] = u2[sph], u3[sph]
        return b1, b2

    def _cone_pdf(self, light, receiver, dist, cos_light):
        """Cone-sampling pdf (solid angle) of spheres ``light`` from receivers (3, k); receivers inside a sphere
        sample it by area."""
        _pc, dc, r = self._from_points(light, receiver)
        x = r * r / np.maximum(dc * dc, 1e-300)
        inside = x >= 1.0
        cone = self.sel_pdf[light] / (2.0 * np.pi * np.where(inside, 1.0, one_minus_cos_cone(x)))
        area = self.sel_pdf_area[light] * dist * dist / np.maximum(np.abs(cos_light), 1e-8)
        return np.where(inside, area, cone).astype(np.float32)

    def sphere_hits(self, light: np.ndarray, o: np.ndarray, d: np.ndarray, tmax: np.ndarray):
        """Rays o + t d ((3, k) rows, unit d) against spheres ``light``: distance t (k,) of the first crossing
        in (0, tmax) (inf = none), sphere coordinates (b1, b2) of that point and cos θ there (between -d and the
        outward normal)."""
        pc, _dc, r = self._from_points(light, o)
        oc = -pc
        dd = d.astype(np.float64)
        b = np.einsum("ij,ij->j", oc, dd)
        # discriminant from the closest approach (accurate for small far spheres): r² - |oc - b d|²
        perp = oc - b * dd
        disc = r * r - np.einsum("ij,ij->j", perp, perp)
        root = np.sqrt(np.maximum(disc, 0.0))
        t0, t1 = -b - root, -b + root
        t = np.where(t0 > 1e-7 * (1 + np.abs(b)), t0, t1)  # the near crossing, or the far one from inside
        ok = (disc >= 0) & (t > 0) & (t < tmax)
        t = np.where(ok, t, np.inf)
        n = (oc + np.where(ok, t, 0.0) * dd) / r
        n /= np.maximum(np.sqrt(np.einsum("ij,ij->j", n, n)), 1e-300)
        b1, b2 = sphere_coords(n)
        cos_l = -np.einsum("ij,ij->j", n, dd)
        return t.astype(np.float32), b1, b2, cos_l.astype(np.float32)

    def positions(self, light: np.ndarray, b1: np.ndarray, b2: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """World positions (3, n) of points (b1, b2) on surface lights ``light`` (into ``out`` if given):
        corner 0 plus the two edges, gathered as columns (a sphere: its centre plus r times the direction)."""
        q = np.take(self.rows_v0, light, axis=1, out=out)
        sph = self._spheres(light)
        if sph.size == len(light) and sph.size:  # spheres only (point lamps): no edges to add
            q += self.sphere_r[light] * sphere_direction(b1, b2)
            return q
        q += cols(self.rows_e1, light) * b1
        q += cols(self.rows_e2, light) * b2
        if sph.size:
            q[:, sph] += self.sphere_r[light[sph]] * sphere_direction(b1[sph], b2[sph])
        return q

    def normals(self, light: np.ndarray, b1: np.ndarray, b2: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """Unit normals (3, n) of surface lights at points (b1, b2) (into ``out`` if given)."""
        sph = self._spheres(light)
        if sph.size == len(light) and sph.size:
            if out is None:
                return sphere_direction(b1, b2)
            out[:] = sphere_direction(b1, b2)
            return out
        nrm = np.take(self.rows_normal, light, axis=1, out=out)
        if sph.size:
            nrm[:, sph] = sphere_direction(b1[sph], b2[sph])
        return nrm

    def point_towards(self, light: np.ndarray, b1: np.ndarray, b2: np.ndarray, p: np.ndarray):
        """Triangle light ``light`` at barycentrics (b1, b2) seen from points p (3, n): the light point
        (3, n), unit direction wi from p (3, n), distance (n,), cos at the light (n,) and the radiance
        arriving at p (3, n) (zero from a back face of a one-sided emitter, spot cones applied)."""
        env = self.env_rows(light)
        if env.size == len(light):  # world points only
            q, nrm, le = self.env.points(b1, b2)
            two_sided = False
        else:
            if env.size:
                light = light.copy()
                light[env] = 0
            q = self.positions(light, b1, b2)
            nrm = self.normals(light, b1, b2)
            le = self.radiance_of(light, b1, b2, p)
            two_sided = self.tri_two_sided[light]
            if env.size:
                q[:, env], nrm[:, env], le[:, env] = self.env.points(b1[env], b2[env])
                two_sided = two_sided.copy()
                two_sided[env] = False
        d = q - p
        dl = norm(d)
        w = d / np.maximum(dl, np.float32(1e-30))
        cos_l = -dot(w, nrm)
        facing = ((cos_l > 0) | two_sided) & (dl > 0) & (np.abs(cos_l) > 1e-8)
        le *= facing
        return q, w, dl, cos_l, le

    def radiance_of(self, light: np.ndarray, b1, b2, p_receiver: np.ndarray) -> np.ndarray:
        """Radiance (3, n) leaving triangle light ``light`` at (b1, b2) towards p_receiver (3, n),
        before the sidedness test (spot cones included unless p_receiver is None)."""
        scene = self.scene
        out = cols(self.rows_le, light)
        if self.any_textured:
            tex = np.flatnonzero(self.tri_textured[light])
            if tex.size:
                lt = light[tex]
                geo = lt < self.n_geom
                for sel, tris, ids, offset in ((geo, scene.geometry, self.geom_ids, 0),
                                               (~geo, scene.lamps.tris, self.lamp_ids, self.n_geom)):
                    if sel.any():
                        rows = tex[sel]
                        wo = None
                        if p_receiver is not None:  # towards the receiver, for view-dependent node programs
                            wo = cols(p_receiver, rows) - self.positions(light[rows], b1[rows], b2[rows])
                            wo = wo / np.maximum(norm(wo), np.float32(1e-30))
                        out[:, rows] = emitted_radiance(tris, scene.materials, ids[lt[sel] - offset], b1[rows],
                                                        b2[rows], wo, sampled=True)
        if p_receiver is not None and self.any_spots:
            lm = np.flatnonzero(light >= self.n_geom)
            if lm.size:
                t = self.lamp_ids[light[lm] - self.n_geom]
                out[:, lm] *= receiver_factor(scene.lamps, t, np.take(p_receiver, lm, axis=1),
                                              self.positions(light[lm], b1[lm], b2[lm]))
        return out

    def spot_lamp_tri(self, light: np.ndarray) -> np.ndarray:
        """Lamp triangle index (n,) int32 of lights whose radiance depends on the receiver (a spot cone, a Light
        Falloff, a node texture: lights/receiver.py), -1 for every other light."""
        out = np.full(len(light), -1, np.int32)
        if not self.any_spots:
            return out
        lm = np.flatnonzero((light >= self.n_geom) & (light < self.n_tri))
        if lm.size:
            t = self.lamp_ids[light[lm] - self.n_geom]
            spot = self.scene.lamps.receiver_dependent()[t]
            out[lm[spot]] = t[spot]
        return out

    def sample(self, p: np.ndarray, u: np.ndarray) -> LightSample:
        """Pick one light per point p (3, n) with power-proportional probability and a point on it.
        ``u`` is (4, n) uniforms."""
        n = p.shape[1]
        if self.alias is None or n == 0:
            return LightSample.zeros(n)
        light = self.alias.sample(u[0], u[1])
        if self.n_sun == 0:  # surface lights only: no column selections
            pos, wi, dist, le, pdf = self._surface_sample(light, u[2], u[3], p)
            return LightSample(pos, wi, dist, le, pdf, np.zeros(n, bool), light)
        out = LightSample.zeros(n)
        out.light = light
        tri = np.flatnonzero(light < self.n_tri)
        if tri.size:
            pos, wi, dist, le, pdf = self._surface_sample(light[tri], u[2, tri], u[3, tri], np.take(p, tri, axis=1))
            out.pos[:, tri], out.wi[:, tri], out.dist[tri], out.le[:, tri], out.pdf[tri] = pos, wi, dist, le, pdf
        sun = np.flatnonzero(light >= self.n_tri)
        if sun.size:
            self._sun_sample(light[sun] - self.n_tri, self.alias.pdf[light[sun]], u[:, sun], sun, out)
        return out

    def _surface_sample(self, light, u2, u3, p):
        """Points on surface lights ``light`` for receivers p (3, n): triangles uniformly in area, spheres in
        their cone. Returns position, direction, distance, radiance arriving, solid-angle pdf (0: no light)."""
        b1, b2 = uniform_triangle(u2, u3)
        sph = self._spheres(light)
        if sph.size:  # cone sampling; a receiver inside the sphere samples its area
            b1[sph], b2[sph] = self._cone_sample(light[sph], np.take(p, sph, axis=1), u2[sph], u3[sph])
        q, w, dl, cos_l, rad = self.point_towards(light, b1, b2, p)
        pdf = self.pdf_solid_angle(light, p, dl, cos_l)
        ok = (vmax(np.abs(rad)) > 0) & np.isfinite(pdf)
        rad *= ok
        return q, w, dl, rad, pdf * ok

    def _cone_sample(self, light, p, u2, u3):
        """Sphere coordinates (b1, b2) of the points where directions drawn uniformly in the cone subtended by
        spheres ``light`` from p (3, k) first meet them (uniform area points for p inside a sphere).

        float32 without cancellation: with a the unit axis toward the centre (distance d), the direction
        w = cos θ a + sin θ e (e ⊥ a) meets the sphere at s = d cos θ - q, q = sqrt(r² - d² sin² θ), where the unit
        normal is (s w - d a)/r = -(d sin² θ + q cos θ)/r · a + (s sin θ / r) · e: both parts are sums of
        non-negative terms (the direct difference s w - d a loses d/r of its digits)."""
        f32 = np.float32
        pc = np.take(self.rows_v0, light, axis=1) - p
        dc = np.sqrt(dot(pc, pc))
        r = self.sphere_r[light].astype(np.float32)
        x = (r * r) / np.maximum(dc * dc, f32(1e-30))
        inside = x >= 1.0
        x = np.where(inside, f32(0.0), x)
        one_minus = u2 * one_minus_cos_cone(x)  # u · (1 - cos θmax), float32
        cos_t = 1.0 - one_minus
        sin2 = one_minus * (2.0 - one_minus)
        sin_t = np.sqrt(sin2)
        q = np.sqrt(np.maximum(f32(0.0), r * r - dc * dc * sin2))
        inv_r = 1.0 / np.maximum(r, f32(1e-30))
        n_axis = -(dc * sin2 + q * cos_t) * inv_r
        n_perp = (dc * cos_t - q) * sin_t * inv_r
        axis = pc / np.maximum(dc, f32(1e-30))
        t, b = orthonormal_basis(axis)
        phi = f32(2.0 * np.pi) * u3
        n = axis * n_axis + (t * np.cos(phi) + b * np.sin(phi)) * n_perp
        n /= np.maximum(np.sqrt(dot(n, n)), f32(1e-30))
        b1, b2 = sphere_coords(n)
        if inside.any():
            b1[inside], b2[inside] = u2[inside], u3[inside]
        return b1, b2

    def sample_suns(self, n: int, u: np.ndarray) -> LightSample:
        """One sun per point, chosen by power among suns only (ReSTIR's companion to resampled
        triangle lights). ``u`` is (4, n) uniforms; all samples are flagged ``delta`` (no MIS)."""
        out = LightSample.zeros(n)
        if self.sun_alias is not None and n:
            s = self.sun_alias.sample(u[0], u[1])
            self._sun_sample(s, self.sun_alias.pdf[s], u, np.arange(n), out)
            out.light = self.n_tri + s
        return out

    def _sun_sample(self, s, p_sel, u, cols_out, out: LightSample):
        """Fill columns ``cols_out`` of ``out`` with directions in suns ``s``'s cones (u: (4, k) uniforms)."""
        lamps = self.scene.lamps
        axis = lamps.sun_dir[s].T.astype(np.float32)
        cmax = lamps.sun_cos[s]
        is_delta = cmax >= 1.0 - 1e-9
        # uniform direction in the cone around the sun axis
        cos_t = 1.0 - u[2] * (1.0 - cmax)
        sin_t = np.sqrt(np.maximum(0.0, 1.0 - cos_t * cos_t))
        phi = 2 * np.pi * u[3]
        t, b = orthonormal_basis(axis)
        dvec = t * (sin_t * np.cos(phi)) + b * (sin_t * np.sin(phi)) + axis * cos_t
        solid = 2 * np.pi * (1.0 - cmax)
        # radiance of a disc of half-angle a whose cosine-weighted integral is the irradiance E
        sin2 = np.maximum(1.0 - cmax * cmax, 1e-30)
        irr = lamps.sun_irradiance[s].T
        rad = irr / (np.pi * sin2)
        out.wi[:, cols_out] = np.where(is_delta, axis, dvec)
        out.dist[cols_out] = np.inf
        # for a delta sun store Le·(1/p_sel) with pdf = p_sel and flag delta: the estimator divides by pdf
        out.le[:, cols_out] = np.where(is_delta, irr, rad)
        out.pdf[cols_out] = np.where(is_delta, p_sel, p_sel / np.maximum(solid, 1e-30))
        out.delta[cols_out] = True  # suns are never hit by BSDF rays: no MIS
