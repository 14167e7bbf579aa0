"""Shading data at ray hits, shared by the path tracer and the ReSTIR stages.

Vectors are (3, n) float32 rows (x, y, z) in world space unless named ``*_l`` (local shading frame,
z = shading normal). Normals face the incoming ray; ``wo`` points back along it (towards the viewer).
"""
from __future__ import annotations

import numpy as np

from .bsdf import SurfaceParams, ViewTerms
from .microfacet_tables import rows_at
from .mix import hash_uniform, pick_components
from .sampling import barycentric, cols, dot, norm, orthonormal_basis
from .textures import apply_texture


class Surface:
    """Hits of rays o + t·d on scene triangles ``prim`` at barycentrics (u, v): p, ng, ns (facing the ray),
    wo, the tangent frame (t, bt), wo_l, material index and BSDF params (textures applied)."""

    def __init__(self, ctx, prim, u, v, o, d, t):
        geom = ctx.scene.geometry
        mats = ctx.scene.materials
        prim = prim.astype(np.intp)  # one index conversion for every gather below
        self.prim = prim
        self.b1, self.b2 = u, v
        self.p = (o + d * t).astype(np.float32, copy=False)
        ng = cols(ctx.geom_ng_rows, prim)
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
        # shading normal on the geometric normal's side, both facing the incoming ray
        s_ng = np.where(dot(ng, d) > 0, np.float32(-1.0), np.float32(1.0))
        s_ns = np.where(dot(ns, ng) < 0, -s_ng, s_ng)
        self.ng = ng * s_ng
        self.ns = ns * s_ns
        self.wo = -d
        mat = geom.material[prim].astype(np.intp)
        self.mat = mat  # the triangle's material (a Mix/Add shader stays itself here)
        scale = None
        if ctx.has_mix:  # Mix/Add shaders: one component per hit, scaled by the weights' sum (core/mix.py)
            mixed = np.flatnonzero(mats.mix_first[mat] >= 0)
            if mixed.size:
                uv = None
                if geom.uvs is not None:
                    c = np.take(geom.uvs, prim[mixed], axis=0)
                    uv = barycentric(c[:, 0], c[:, 1], c[:, 2], u[mixed][:, None], v[mixed][:, None])
                comp, w = pick_components(mats, mat, mixed, hash_uniform(prim[mixed], u[mixed], v[mixed]), uv)
                mat = mat.copy()
                mat[mixed] = comp
                scale = np.ones(len(mat), np.float32)
                scale[mixed] = w
        self.bsdf_mat = mat  # the material whose BSDF the hit uses
        self.params = ctx.material_params.take(mat)
        if geom.uvs is not None:
            textured = np.flatnonzero(mats.base_tex[mat] >= 0)
            if textured.size:  # re-derive the parameters where a texture drives the base colour
                c = np.take(geom.uvs, prim[textured], axis=0)
                uv = barycentric(c[:, 0], c[:, 1], c[:, 2], u[textured][:, None], v[textured][:, None])  # (k, 2)
                tm = mat[textured]
                base = apply_texture(mats.base_color[tm], mats.base_tex[tm], uv, mats.textures)
                self.params.assign(textured, SurfaceParams.of_table(mats, tm, base))
        if scale is not None:
            self.params.scale(scale)
        self.t, self.bt = orthonormal_basis(self.ns)
        wo = self.wo
        wo_l = np.empty_like(wo)
        wo_l[0] = dot(wo, self.t)
        wo_l[1] = dot(wo, self.bt)
        # view vectors below the shading hemisphere (shading-normal artefact): bend to the horizon
        wo_l[2] = np.maximum(dot(wo, self.ns), np.float32(1e-4))
        wo_l /= norm(wo_l)
        self.wo_l = wo_l
        # GGX albedo and the dielectric layer's Fresnel factor toward the viewer, once per hit (α and η are
        # constant per material: one interpolation in μo)
        self.albedo = rows_at(ctx.material_albedo, mat, wo_l[2])
        self.layer = rows_at(ctx.material_layer, mat, wo_l[2])

    def __len__(self) -> int:
        return len(self.prim)

    @property
    def view(self) -> ViewTerms:
        """The BSDF's view-dependent factors (bsdf.ViewTerms), computed on first use."""
        v = getattr(self, "_view", None)
        if v is None:
            v = self._view = ViewTerms.of(self.params, self.wo_l, self.albedo, self.layer)
        return v

    def take(self, idx) -> "Surface":
        """The surfaces ``idx`` (an index array or a slice) as a new Surface."""
        out = Surface.__new__(Surface)
        for name in ("prim", "b1", "b2", "mat", "bsdf_mat", "albedo", "layer"):
            setattr(out, name, getattr(self, name)[idx])
        for name in ("p", "ng", "ns", "wo", "t", "bt", "wo_l"):
            a = getattr(self, name)
            setattr(out, name, a[:, idx] if isinstance(idx, slice) else np.take(a, idx, axis=1))
        out.params = self.params.take(idx)
        return out
