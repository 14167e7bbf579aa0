"""Shading data at ray hits, shared by the path tracer and the ReSTIR stages.

Vectors are (3, n) float32 rows (x, y, z) in world space unless named ``*_l`` (local shading frame,
z = shading normal). Normals face the incoming ray (away from it at Translucent BSDF hits, whose lobe lies on the
far side); ``wo`` points back along it (towards the viewer).
"""
from __future__ import annotations

import numpy as np

from ..geometry.camera import pixel_footprint
from ..sampling import barycentric, cols, dot, norm, orthonormal_basis
from . import microfacet_tables
from .bsdf import ViewTerms
from .glass import GLASS_SALT
from .microfacet_tables import lerp_rows, mu_index
from .mix import hash_uniform, pick_components
from .nodes import HitAttributes, run_programs
from .lobe_fields import anisotropy_frame, keep_given, sheen_rows
from .params import SurfaceParams, subsurface_of
from .image_normals import bump_map, normal_map
from .textures import apply_texture


#: the BSDF fields a material's node program may compute (scene.MaterialTable.program)
PARAM_FIELDS = ("base_color", "metallic", "roughness", "f0", "specular_tint", "diffuse_roughness", "subsurface")
#: the anisotropy fields it may compute: the aspect (anisotropy.py), its rotation (turns) and the tangent (world,
#: (3, k)); and a sheen row's roughness (sheen.py)
ANISO_FIELDS = ("aniso_aspect", "aniso_rotation", "tangent")
SHEEN_FIELDS = ("sheen_roughness",)


class Surface:
    """Hits of rays o + t·d on scene triangles ``prim`` at barycentrics (u, v): p, ng, ns (facing the ray; turned
    away from it at Translucent BSDF hits, :meth:`facing_normals`), wo, the tangent frame (t, bt), wo_l, material
    index and BSDF params (textures applied)."""

    def __init__(self, ctx, prim, u, v, o, d, t, camera: bool = False, lambert: bool = False,
                 walks: bool | None = None, path: dict | None = None):
        """``camera``: hits of camera rays. ``walks`` (default: ``camera``): a subsurface share stays its own lobe
        (``params.sss``, walked by integrators/subsurface.py) at these hits, the first the camera's paths shade; at
        others it is part of the diffuse lobe. ``lambert``: every hit is a white Lambertian surface whatever its
        material (a subsurface walk's exit, as Cycles shades it). ``path``: the Light Path values of the rays that
        reached the hits (attributes.PATH_ATTRIBUTES, (n,) each; None: a camera hit's, or a diffuse bounce's)."""
        geom = ctx.scene.geometry
        self.camera = camera  # hits of camera rays (Light Path > Is Camera Ray in node programs)
        self.path = path
        self.reads_path = getattr(ctx, "reads_path", False)  # whether the paths carry their Light Path state
        self._t = t
        prim = prim.astype(np.intp)  # one index conversion for every gather below
        self.prim = prim
        self.b1, self.b2 = u, v
        self.p = (o + d * t).astype(np.float32, copy=False)
        mat = geom.material[prim].astype(np.intp)
        self.mat = mat  # the triangle's material (a Mix/Add shader stays itself here)
        mat, scale, tint = self._pick_mix_components(ctx, mat, d)
        ng = cols(ctx.geom_ng_rows, prim)
        ns = self._interpolated_normal(ctx, ng)
        ns, mapped, smooth_n = self._mapped_normal(ctx, mat, ns, ng, d)
        # shading normal on the geometric normal's side, both facing the incoming ray
        s_ng = np.where(dot(ng, d) > 0, np.float32(-1.0), np.float32(1.0))
        s_ns = np.where(dot(ns, ng) < 0, -s_ng, s_ng)
        self.ng = ng * s_ng
        self.ns = ns * s_ns
        self.wo = -d
        self.bsdf_mat = mat  # the material whose BSDF the hit uses
        self._material_params(ctx, mat, scale, tint)
        if lambert:
            self.params = SurfaceParams.from_material(np.ones((len(mat), 3), np.float32), np.zeros(len(mat)),
                                                      np.ones(len(mat)), np.zeros(len(mat)))
            self._varying = None
        elif ctx.has_subsurface and self.params.has_subsurface():
            if not (camera if walks is None else walks):
                self.params.fold_subsurface()
            else:  # as Cycles: a channel whose radius is below 1e-8 (or a material not walked) is diffuse
                mats = ctx.scene.materials
                self.params.fold_subsurface((mats.sss_radius[mat].T < 1e-8) | (mats.sss_method[mat] == 0))
        self._glass(ctx, mat, scale, tint, s_ng, lambert)
        away = None if lambert else self._translucent(ctx, mat)
        self.t, self.bt = orthonormal_basis(self.ns)
        self._bump_shadowing(mapped, smooth_n, s_ng if away is None else s_ng * away)
        self._view_frame()
        mu = self._specular_normal()
        self._anisotropy(ctx, mat)
        self._sheen(ctx, mat)
        if lambert:
            self.aniso = self.sheen = None
        # GGX albedo and the dielectric layer's Fresnel factor toward the viewer (about the specular normal): looked
        # up once per hit when first used (α and η are constant per material: one interpolation in μo)
        self._mu, self._tables = mu, (ctx.material_albedo, ctx.material_layer)
        self._at = self._albedo = self._layer = None
        if self._varying is not None:  # α or F0 vary per hit there: their tables at each hit's own (α, μo, F0)
            self._per_hit_tables(self._varying)

    def _attributes(self, ctx, r, wo, **given) -> HitAttributes:
        """What node programs read at hits ``r`` (indices): the view ``wo`` (3, k) and whatever else is ``given``
        (normals), the pixel's footprint at the ray's length (geometry.camera.pixel_footprint), whether they are
        camera hits, and the ray length."""
        t = np.asarray(self._t, np.float32)[r]
        if given.get("footprint") is None:
            given["footprint"] = pixel_footprint(ctx.scene.camera, t)
        path = None if self.path is None else {k: v[r] for k, v in self.path.items()}
        return HitAttributes(ctx.scene.geometry, self.prim[r], self.b1[r], self.b2[r], ctx.scene.materials.textures,
                             wo=wo, camera_ray=self.camera, ray_length=t, path=path, **given)

    def _uv(self, geom, rows) -> np.ndarray:
        """(k, 2) texture coordinates of the hits ``rows``."""
        c = np.take(geom.uvs, self.prim[rows], axis=0)
        return barycentric(c[:, 0], c[:, 1], c[:, 2], self.b1[rows][:, None], self.b2[rows][:, None])

    def _pick_mix_components(self, ctx, mat, d):
        """Mix/Add shaders: one component per hit, scaled by the weights' sum (core/materials/mix.py). Returns
        (the material each hit uses (n,), the scale (n,) float32 or None where no hit is mixed, the picked
        components' colour factors (3, n) or None where none has one)."""
        if not ctx.has_mix:
            return mat, None, None
        mats, geom = ctx.scene.materials, ctx.scene.geometry
        mixed = np.flatnonzero(mats.mix_first[mat] >= 0)
        if not mixed.size:
            return mat, None, None
        prim, u, v = self.prim, self.b1, self.b2
        uv = self._uv(geom, mixed) if geom.uvs is not None else None
        def attrs_of(rows):  # the mixed hits ``rows`` (indices into ``mixed``), for weights from node programs
            r = mixed[rows]
            return self._attributes(ctx, r, -cols(d, r))
        comp, w, colour = pick_components(mats, mat, mixed, hash_uniform(prim[mixed], u[mixed], v[mixed]), uv,
                                          attrs_of)
        mat = mat.copy()
        mat[mixed] = comp
        scale = np.ones(len(mat), np.float32)
        scale[mixed] = w
        tint = None
        if colour is not None:
            tint = np.ones((3, len(mat)), np.float32)
            tint[:, mixed] = colour
        return mat, scale, tint

    def _interpolated_normal(self, ctx, ng) -> np.ndarray:
        """(3, n) unit shading normals: interpolated on smooth triangles, the corner normal on flat ones, the
        geometric normal where the interpolation degenerates."""
        prim, u, v = self.prim, self.b1, self.b2
        smooth = np.flatnonzero(~ctx.geom_flat[prim])
        if smooth.size == len(prim):
            c = cols(ctx.geom_normal_rows, prim)
            ns = barycentric(c[0:3], c[3:6], c[6:9], u, v)
        else:  # flat-shaded triangles: the corner normal as it is
            ns = cols(ctx.geom_normal_rows[0:3], prim)
            if smooth.size:
                c = cols(ctx.geom_normal_rows, prim[smooth])
                ns[:, smooth] = barycentric(c[0:3], c[3:6], c[6:9], u[smooth], v[smooth])
        ln = norm(ns)
        ns /= np.maximum(ln, np.float32(1e-12))
        bad = ~np.isfinite(ln) | (ln < 0.5)
        if bad.any():
            ns[:, bad] = ng[:, bad]
        return ns

    def _mapped_normal(self, ctx, mat, ns, ng, d):
        """Normal Map and Bump nodes applied to ``ns`` (in place): the image-only forms (normal_tex, bump_tex) and
        node programs' "normal". Returns (ns, the hits they changed or None, those hits' smooth normals before
        mapping (3, k) or None)."""
        mats, geom = ctx.scene.materials, ctx.scene.geometry
        prim, u, v = self.prim, self.b1, self.b2
        none = np.empty(0, np.intp)
        nmap = np.flatnonzero(mats.normal_tex[mat] >= 0) if ctx.normal_maps and geom.tangents is not None else none
        bump = np.flatnonzero(mats.bump_tex[mat] >= 0) if ctx.bump_maps and geom.uvs is not None else none
        programs = self._program_normals(ctx, mat, ns, ng, d) if ctx.has_programs else None
        if not (len(nmap) or len(bump) or programs):
            return ns, None, None
        rows, normals = programs or (none, None)
        mapped = np.union1d(np.union1d(nmap, bump), rows)
        smooth_n = ns[:, mapped].copy()
        if len(nmap):
            ns[:, nmap] = normal_map(mats, geom, mat, prim, u, v, ns, nmap)
        if len(bump):  # about the normal facing the ray, as Cycles (then turned back like every normal)
            facing = np.where(dot(cols(ng, bump), cols(d, bump)) > 0, np.float32(-1.0), np.float32(1.0))
            ns[:, bump] = bump_map(mats, geom, mat, prim, u, v, ns[:, bump] * facing, bump) * facing
        if len(rows):
            ns[:, rows] = normals
        return ns, mapped, smooth_n

    def _program_normals(self, ctx, mat, ns, ng, d):
        """(hits, their normals (3, k)) where a node program computes the shading normal (Normal Map, Bump of any
        graph), in the orientation of ``ns`` (the program sees and returns normals facing the ray); None where
        no program does."""
        facing = np.where(dot(ng, d) > 0, np.float32(-1.0), np.float32(1.0))
        rows_all, normals = [], []
        for rows, out in run_programs(ctx.scene.materials, mat, lambda r: self._attributes(
                ctx, r, -cols(d, r), normal=cols(ns, r) * facing[r], true_normal=cols(ng, r) * facing[r]),
                ("normal",)):
            if "normal" in out:
                rows_all.append(rows)
                normals.append(out["normal"] * facing[rows])
        if not rows_all:
            return None
        return np.concatenate(rows_all), np.concatenate(normals, axis=1)

    def _material_params(self, ctx, mat, scale, tint=None) -> None:
        """The hits' BSDF parameters: a view of the material table, re-derived where a texture drives the base
        colour, scaled by the Mix weights and the picked components' colour factors (``tint`` (3, n) or None)."""
        mats, geom = ctx.scene.materials, ctx.scene.geometry
        self.params = ctx.material_params.gather(mat)
        if geom.uvs is not None:
            textured = np.flatnonzero(mats.base_tex[mat] >= 0)
            if textured.size:  # re-derive the parameters where a texture drives the base colour
                uv = self._uv(geom, textured)  # (k, 2)
                tm = mat[textured]
                base = apply_texture(mats.base_color[tm], mats.base_tex[tm], uv, mats.textures)
                self.params.assign(textured, SurfaceParams.of_table(mats, tm, base))
        self._aniso_given = None
        self._varying = self._node_params(ctx, mat) if ctx.has_programs else None
        if scale is not None:
            self.params.scale(scale)
        if tint is not None:
            self.params.tint(tint)

    def _node_params(self, ctx, mat):
        """BSDF parameters from the materials' node programs at their hits (core/materials/nodes): the hits'
        parameters re-derived with the fields the programs compute. Returns the hits whose α or F0 now vary
        (indices) or None."""
        mats, geom = ctx.scene.materials, ctx.scene.geometry
        varying = []
        for rows, out in run_programs(mats, mat, lambda r: self._attributes(
                ctx, r, cols(self.wo, r), normal=cols(self.ns, r), true_normal=cols(self.ng, r)),
                PARAM_FIELDS + ANISO_FIELDS + SHEEN_FIELDS):
            self._given_fields(rows, out, len(mat))
            if not any(f in out for f in PARAM_FIELDS):
                continue
            tm = mat[rows]
            base = out["base_color"].T if "base_color" in out else mats.base_color[tm]
            if "base_color" not in out and geom.uvs is not None and (mats.base_tex[tm] >= 0).any():
                base = apply_texture(base, mats.base_tex[tm], self._uv(geom, rows), mats.textures)
            dr = out.get("diffuse_roughness", mats.diffuse_roughness[tm])
            self.params.assign(rows, SurfaceParams.from_material(
                base, out.get("metallic", mats.metallic[tm]), out.get("roughness", mats.roughness[tm]),
                out.get("f0", mats.f0[tm]), out["specular_tint"].T if "specular_tint" in out else mats.specular_tint[tm],
                mats.metal_f90[tm], mats.multiscatter[tm], dr, out.get("subsurface", subsurface_of(mats, tm))))
            if "roughness" in out or "f0" in out:
                varying.append(rows)
        return np.concatenate(varying) if varying else None

    def _given_fields(self, rows, out: dict, n: int) -> None:
        """Keep the anisotropy and sheen fields a node program computed at hits ``rows`` (lobe_fields.keep_given)."""
        self._aniso_given = keep_given(self._aniso_given, rows, out, n, ANISO_FIELDS + SHEEN_FIELDS)

    def _anisotropy(self, ctx, mat) -> None:
        """``aniso``: the anisotropic hits' GGX frame, or None (lobe_fields.anisotropy_frame)."""
        self.aniso = anisotropy_frame(self, ctx, mat, self._aniso_given or {})

    def _sheen(self, ctx, mat) -> None:
        """``sheen``: the sheen rows among the hits, or None (lobe_fields.sheen_rows)."""
        self.sheen = sheen_rows(ctx, mat, self._aniso_given or {})

    def _per_hit_tables(self, rows) -> None:
        """The GGX albedo and the layer factor at hits ``rows`` from their own α and F0 (the per-material rows
        assume the material's constants)."""
        albedo, layer = self.albedo.copy(), self.layer.copy()
        p = self.params.take(rows)
        mu = self._mu[rows]
        albedo[rows] = microfacet_tables.albedo(p.alpha, mu)
        layer[rows] = microfacet_tables.layer_s(p.alpha, mu, p.f0r)
        self._albedo, self._layer = albedo, layer

    def _glass(self, ctx, mat, scale, tint, s_ng, lambert: bool = False) -> None:
        """Smooth glass (core/materials/glass.py): picked per point with the material's transmission share; black
        for every evaluation, sampled as a delta closure by pathtracer.sample_rays."""
        self.glass = self.glass_front = self.glass_ior = self.glass_reflect = self.glass_refract = None
        self.glass_alpha = self.glass_ms = self.glass_fresnel = self.glass_beckmann = None
        if not ctx.has_glass or lambert:
            return
        mats, prim, u, v = ctx.scene.materials, self.prim, self.b1, self.b2
        cand = np.flatnonzero(mats.transmission[mat] > 0)
        if not cand.size:
            return
        pick = hash_uniform(prim[cand] ^ GLASS_SALT, u[cand], v[cand]) < mats.transmission[mat[cand]]
        rows = cand[pick]
        if not rows.size:
            return
        n = len(prim)
        self.glass = np.zeros(n, bool)  # per surface: uses the glass closure
        self.glass[rows] = True
        self.glass_front = s_ng > 0  # the ray came from outside (against the outward normal)
        gm = mat[rows]
        w = np.ones(rows.size, np.float32) if scale is None else scale[rows]
        if tint is not None:
            w = w * tint[:, rows]
        self.glass_ior = np.ones(n, np.float32)
        self.glass_ior[rows] = mats.glass_ior[gm]
        self.glass_alpha = np.zeros(n, np.float32)
        self.glass_alpha[rows] = mats.glass_alpha[gm]
        self.glass_ms = np.zeros(n, bool)
        self.glass_ms[rows] = mats.glass_multiscatter[gm] > 0
        self.glass_fresnel = np.ones(n, bool)
        fresnel = getattr(mats, "glass_fresnel", None)
        if fresnel is not None:
            self.glass_fresnel[rows] = fresnel[gm] > 0
        self.glass_beckmann = np.zeros(n, bool)
        beckmann = getattr(mats, "glass_beckmann", None)
        if beckmann is not None:
            self.glass_beckmann[rows] = beckmann[gm] > 0
        self.glass_reflect = np.zeros((3, n), np.float32)
        self.glass_reflect[:, rows] = mats.glass_reflect[gm].T * w
        self.glass_refract = np.zeros((3, n), np.float32)
        self.glass_refract[:, rows] = mats.glass_refract[gm].T * w
        k = rows.size
        self.params.assign(rows, SurfaceParams.from_material(np.zeros((k, 3), np.float32), np.zeros(k), np.ones(k),
                                                             np.zeros(k)))

    def _translucent(self, ctx, mat):
        """Translucent BSDF hits (scene.MaterialTable.translucent): their frame (ng, ns) is turned away from the
        viewer, so that every stage (BSDF evaluation and sampling, next-event estimation, ReSTIR's targets) sees a
        Lambertian lobe on the far side of the surface and nothing on the viewer's. Sets ``translucent`` ((n,) bool, or
        None where no hit is translucent); returns the sign applied to each hit's normals ((n,) float32) or None."""
        flags = ctx.scene.materials.translucent
        tr = flags[mat] if flags is not None and flags.any() else None
        self.translucent = tr if tr is not None and tr.any() else None
        if self.translucent is None:
            return None
        away = np.where(tr, np.float32(-1.0), np.float32(1.0))
        self.ng = self.ng * away
        self.ns = self.ns * away
        return away

    def facing_normals(self):
        """(ng, ns) (3, n) facing the incoming ray (the frame of translucent hits turned back toward the viewer)."""
        if self.translucent is None:
            return self.ng, self.ns
        back = np.where(self.translucent, np.float32(-1.0), np.float32(1.0))
        return self.ng * back, self.ns * back

    def _bump_shadowing(self, mapped, smooth_n, s_ng) -> None:
        """The unmapped (smooth) normal in the local frame and its shadowing term, for Cycles' bump shadowing."""
        self.bump_n = self.bump_a2 = None
        if mapped is None:
            return
        sn = smooth_n * s_ng[mapped]
        self.bump_n = np.zeros((3, len(self.prim)), np.float32)
        self.bump_n[2] = 1.0
        self.bump_n[0, mapped] = dot(sn, cols(self.t, mapped))
        self.bump_n[1, mapped] = dot(sn, cols(self.bt, mapped))
        self.bump_n[2, mapped] = dot(sn, cols(self.ns, mapped))
        cos_d = np.clip(np.abs(self.bump_n[2]), 1e-6, 1.0)
        self.bump_a2 = np.clip(0.125 * (1.0 / (cos_d * cos_d) - 1.0), 0.0, 1.0).astype(np.float32)

    def _view_frame(self) -> None:
        """wo in the local frame (t, bt, ns); views below the shading hemisphere (a shading-normal artefact) bent
        to the horizon."""
        wo = self.wo
        wo_l = np.empty_like(wo)
        wo_l[0] = dot(wo, self.t)
        wo_l[1] = dot(wo, self.bt)
        wo_l[2] = np.maximum(dot(wo, self.ns), np.float32(1e-4))
        wo_l /= norm(wo_l)
        self.wo_l = wo_l

    def _specular_normal(self) -> np.ndarray:
        """Cycles' specular normal: where the mirror reflection of the view about the shading normal would leave
        below the geometric surface, the specular lobes use a normal bent toward ng just enough (the diffuse lobe
        keeps the shading normal); ``spec_n`` (3, n) in the local frame or None. Returns μo about it (n,)."""
        self.spec_n = None
        wo_l = self.wo_l
        mu = wo_l[2]
        bent = np.flatnonzero(dot(self.ns, self.ng) < np.float32(0.99999))
        if bent.size:
            n2, changed = valid_reflection_normal(cols(self.ng, bent), cols(self.wo, bent), cols(self.ns, bent))
            rows = bent[changed]
            if rows.size:
                n2 = n2[:, changed]
                self.spec_n = np.zeros((3, len(self.prim)), np.float32)
                self.spec_n[2] = 1.0
                self.spec_n[0, rows] = dot(n2, cols(self.t, rows))
                self.spec_n[1, rows] = dot(n2, cols(self.bt, rows))
                self.spec_n[2, rows] = dot(n2, cols(self.ns, rows))
                mu = dot(wo_l, self.spec_n)
        return mu

    def __len__(self) -> int:
        return len(self.prim)

    def _mu_at(self):
        """Where the hits' μo (about the specular normal) falls in per-material μ rows: (flat node (n,), fraction
        (n,)) (:func:`microfacet_tables.mu_index`, once)."""
        if self._at is None:
            self._at = mu_index(self.bsdf_mat, self._mu)
        return self._at

    def _table_at(self, which: int) -> np.ndarray:
        """Table ``which`` (0: GGX albedo E, 1: the layer's Fresnel factor S) at the hits' μo (n,)."""
        return lerp_rows(self._tables[which], *self._mu_at())

    @property
    def albedo(self) -> np.ndarray:
        """The specular lobes' GGX single-scattering albedo E(α, μo) (n,) (looked up on first use)."""
        if self._albedo is None:
            self._albedo = self._table_at(0)
        return self._albedo

    @property
    def layer(self) -> np.ndarray:
        """The dielectric layer's Fresnel interpolation factor S(α, μo, η) (n,) (looked up on first use)."""
        if self._layer is None:
            self._layer = self._table_at(1)
        return self._layer

    @property
    def view(self) -> ViewTerms:
        """The BSDF's view-dependent factors (bsdf.ViewTerms), computed on first use."""
        v = getattr(self, "_view", None)
        if v is None:
            v = self._view = ViewTerms.of(self.params, self.wo_l, lambda: self.albedo, lambda: self.layer,
                                          self._mu_at())
            v.bump_n, v.bump_a2 = self.bump_n, self.bump_a2
            if self.spec_n is not None:
                v.with_spec_normal(self.spec_n, self.wo_l)
            if self.aniso is not None:
                v.with_anisotropy(self.aniso, self.wo_l)
            if self.sheen is not None:
                v.with_sheen(self.sheen, self.wo_l)
        return v

    def take(self, idx) -> "Surface":
        """The surfaces ``idx`` (an index array or a slice) as a new Surface."""
        out = Surface.__new__(Surface)
        for name in ("prim", "b1", "b2", "mat", "bsdf_mat", "_mu"):
            setattr(out, name, getattr(self, name)[idx])
        out._tables = self._tables
        out._at = None if self._at is None else (self._at[0][idx], self._at[1][idx])
        out._albedo = None if self._albedo is None else self._albedo[idx]
        out._layer = None if self._layer is None else self._layer[idx]
        for name in ("glass", "glass_front", "glass_ior", "glass_alpha", "glass_ms", "glass_fresnel",
                     "glass_beckmann", "translucent"):
            a = getattr(self, name)
            setattr(out, name, None if a is None else a[idx])
        for name in ("p", "ng", "ns", "wo", "t", "bt", "wo_l", "bump_n", "spec_n", "glass_reflect", "glass_refract"):
            a = getattr(self, name)
            setattr(out, name, None if a is None else a[:, idx] if isinstance(idx, slice) else np.take(a, idx, axis=1))
        out.bump_a2 = None if self.bump_a2 is None else self.bump_a2[idx]
        out.aniso = None if self.aniso is None else self.aniso.take(idx, len(self))
        out.sheen = None if self.sheen is None else self.sheen.take(idx, len(self))
        out.params = self.params.take(idx)
        out.camera, out.reads_path = self.camera, self.reads_path
        out.path = None if self.path is None else {k: v[idx] for k, v in self.path.items()}
        return out


def valid_reflection_normal(ng: np.ndarray, wo: np.ndarray, n: np.ndarray):
    """Cycles' ensure_valid_specular_reflection, vectorized over (3, k) unit rows: where the mirror reflection
    R = 2 (n·wo) n - wo of the view direction wo about the shading normal n falls below min(0.9 wo·ng, 0.01) over
    the geometric normal ng, n is rotated toward ng (in their plane) just enough to lift R to that height.
    Returns (normals (3, k), changed (k,) bool)."""
    iz = dot(wo, ng)
    r_z = 2 * dot(n, wo) * dot(n, ng) - iz
    t = np.minimum(0.9 * iz, np.float32(0.01))
    changed = r_z < t
    if not changed.any():
        return n, changed
    x = n - dot(n, ng) * ng
    lx = norm(x)
    x = np.where(lx > 1e-12, x / np.maximum(lx, 1e-30), n)
    ix = dot(wo, x)
    a = ix * ix + iz * iz
    b = 2.0 * (a + iz * t)
    c = (t + iz) ** 2
    disc = np.sqrt(np.maximum(b * b - 4.0 * a * c, 0.0))
    nz2 = np.where(ix < 0, 0.25 * (b + disc), 0.25 * (b - disc)) / np.maximum(a, 1e-30)
    nx = np.sqrt(np.maximum(1.0 - nz2, 0.0))
    nz = np.sqrt(np.maximum(nz2, 0.0))
    out = np.where(changed, nx * x + nz * ng, n)
    return out.astype(np.float32), changed

