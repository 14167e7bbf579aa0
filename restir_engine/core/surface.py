"""Shading data at ray hits, shared by the path tracer and the ReSTIR stages.

Vectors are (n, 3) float32 rows in world space unless named ``*_l`` (local shading frame, z = shading
normal). Normals face the incoming ray; ``wo`` points back along it (towards the viewer).
"""
from __future__ import annotations

import numpy as np

from .bsdf import SurfaceParams, ViewTerms, ggx_albedo_at
from .lights import emitted_radiance
from .sampling import barycentric, dot, orthonormal_basis, take_rows
from .textures import apply_texture

PARAM_FIELDS = ("diffuse", "f0", "f0_dielectric", "alpha", "p_spec", "spec_on")


class Surface:
    """Hits of rays o + t·d on scene triangles ``prim`` at barycentrics (u, v): p, ng, ns (facing the ray),
    wo, the tangent frame (t, bt), wo_l, material index and BSDF params (textures applied)."""

    def __init__(self, ctx, prim, u, v, o, d, t):
        geom = ctx.scene.geometry
        mats = ctx.scene.materials
        prim = prim.astype(np.intp)  # one index conversion for every gather below
        self.prim = prim
        self.b1, self.b2 = u, v
        self.p = (o + d * t[:, None]).astype(np.float32)
        ng = take_rows(ctx.geom_ng, prim)
        smooth = np.flatnonzero(~ctx.geom_flat[prim])
        if smooth.size == len(prim):
            ns = barycentric(take_rows(geom.normals, prim), u, v)
        else:  # flat-shaded triangles: the corner normal as it is
            ns = take_rows(geom.normals, prim)[:, 0]
            if smooth.size:
                ns[smooth] = barycentric(take_rows(geom.normals, prim[smooth]), u[smooth], v[smooth])
        ln = np.sqrt(dot(ns, ns))
        ns /= np.maximum(ln, 1e-12)[:, None]
        bad = ~np.isfinite(ln) | (ln < 0.5)
        if bad.any():
            ns[bad] = ng[bad]
        # shading normal on the geometric normal's side, both facing the incoming ray
        s_ns = np.where(dot(ns, ng) < 0, -1.0, 1.0).astype(np.float32)
        s_ng = np.where(dot(ng, d) > 0, -1.0, 1.0).astype(np.float32)
        self.ng = ng * s_ng[:, None]
        self.ns = ns * (s_ns * s_ng)[:, None]
        self.wo = -d
        mat = geom.material[prim].astype(np.intp)
        self.mat = mat
        self.params = ctx.material_params.take(mat)
        if geom.uvs is not None:
            textured = np.flatnonzero(mats.base_tex[mat] >= 0)
            if textured.size:  # re-derive the parameters where a texture drives the base colour
                uv = barycentric(geom.uvs[prim[textured]], u[textured], v[textured])
                tm = mat[textured]
                base = apply_texture(mats.base_color[tm], mats.base_tex[tm], uv, mats.textures)
                sub = SurfaceParams.from_material(base, mats.metallic[tm], mats.roughness[tm], mats.f0[tm])
                for field in PARAM_FIELDS:
                    getattr(self.params, field)[textured] = getattr(sub, field)
        self.t, self.bt = orthonormal_basis(self.ns)
        wo = self.wo
        wo_l = np.empty_like(wo)
        wo_l[:, 0] = dot(wo, self.t)
        wo_l[:, 1] = dot(wo, self.bt)
        # view vectors below the shading hemisphere (shading-normal artefact): bend to the horizon
        wo_l[:, 2] = np.maximum(dot(wo, self.ns), 1e-4)
        wo_l /= np.sqrt(dot(wo_l, wo_l))[:, None]
        self.wo_l = wo_l
        # GGX directional albedo toward the viewer, once per hit (α is constant per material)
        self.albedo = ggx_albedo_at(ctx.material_albedo, mat, wo_l[:, 2])

    def __len__(self) -> int:
        return len(self.p)

    @property
    def view(self) -> ViewTerms:
        """The BSDF's view-dependent factors (bsdf.ViewTerms), computed on first use."""
        v = getattr(self, "_view", None)
        if v is None:
            v = self._view = ViewTerms.of(self.params, self.wo_l, self.albedo)
        return v

    def emission(self, ctx) -> np.ndarray:
        """Emitted radiance (n, 3) towards the incoming ray (mesh emission is two-sided by default)."""
        return emitted_radiance(ctx.scene.geometry, ctx.scene.materials, self.prim, self.b1, self.b2)

    def take(self, rows) -> "Surface":
        """The surfaces ``rows`` (an index array or a slice) as a new Surface."""
        out = Surface.__new__(Surface)
        for name in ("prim", "b1", "b2", "p", "ng", "ns", "wo", "mat", "t", "bt", "wo_l", "albedo"):
            a = getattr(self, name)
            setattr(out, name, take_rows(a, rows) if a.ndim > 1 and not isinstance(rows, slice) else a[rows])
        out.params = self.params.take(rows)
        return out
