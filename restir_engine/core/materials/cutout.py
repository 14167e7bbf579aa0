"""Alpha cut-outs: surfaces that rays pass through where they are transparent (Principled Alpha, a Mix with a
Transparent BSDF), for camera, shadow and bounce rays alike.

A hit on a cut-out material is opaque with probability α (the material's constant alpha, times an image texture's
value t or 1 - t at the hit's UV, times its node program's "alpha" at the hit) and otherwise the ray continues
behind it. The decision is a hash of the hit (triangle and barycentrics, salted apart from the Mix pick), so every
ray that reaches the same point agrees (a shadow ray is blocked exactly where a camera ray would stop), and over the
points of a pixel the surface covers a fraction α of them: Cycles' transparency of a white Transparent BSDF, on
average. A ray that passes a transparent point keeps the material's transparent tint there (a Transparent BSDF's
Color, constant or from its node program; white for an Alpha): rays carry the product of the tints they passed
(accel.Hits.tint), shadow rays return it as their transmittance (accel.Accel.transmittance). Objects whose Ray Visibility excludes a kind of ray are passed the same way by that kind: shadow rays pass
objects that cast no shadow, camera rays objects the camera does not see.
"""
from __future__ import annotations

import numpy as np

from ..sampling import barycentric, cols, norm
from .mix import hash_uniform
from .nodes import HitAttributes, run_programs
from .textures import sample

SALT = 0x5BD1E995


class Cutout:
    """Which hits of a triangle set are opaque. ``geometry`` (scene.TriangleSet), ``materials`` (MaterialTable with
    alpha, alpha_tex, alpha_sign, alpha_program)."""

    def __init__(self, geometry, materials):
        mat = geometry.material
        self.alpha = materials.alpha[mat].astype(np.float32)
        self.tex = materials.alpha_tex[mat]
        self.sign = materials.alpha_sign[mat]
        programs = getattr(materials, "alpha_program", None)
        self.program = programs[mat] if programs is not None else np.zeros(len(mat), bool)
        self.cut = (self.alpha < 1) | (self.tex >= 0) | self.program
        shadows = getattr(materials, "transparent_shadow", None)
        self.shadow_cut = self.cut & (shadows[mat] if shadows is not None else True)
        self.shadow_pass = _passed_by(geometry, "casts_shadow")  # (n,) bool or None: triangles shadow rays ignore
        self.camera_pass = _passed_by(geometry, "camera_visible")  # ... and camera rays
        tint = getattr(materials, "transparent_tint", None)
        self.tint_of = np.ones((len(materials.alpha), 3), np.float32) if tint is None else tint.astype(np.float32)
        self.tint_program = _programs_with(materials, "transparent_tint")  # (m,) bool
        coloured = (np.abs(self.tint_of - 1) > 1e-6).any(axis=1) | self.tint_program
        self.tinted = bool((self.cut & coloured[mat]).any())
        self.uvs = geometry.uvs
        self.textures = materials.textures
        self.geometry, self.materials = geometry, materials

    @staticmethod
    def of(geometry, materials) -> "Cutout | None":
        """The cut-out test of a scene's geometry, or None when no material is transparent anywhere."""
        a = getattr(materials, "alpha", None)
        if a is None or len(geometry) == 0:
            return None
        programs = getattr(materials, "alpha_program", None)
        if not ((a < 1).any() or (materials.alpha_tex >= 0).any() or (programs is not None and programs.any())
                or _passed_by(geometry, "casts_shadow") is not None
                or _passed_by(geometry, "camera_visible") is not None):
            return None
        c = Cutout(geometry, materials)
        return c if c.cut.any() or c.shadow_pass is not None or c.camera_pass is not None else None

    def with_geometry(self, geometry) -> "Cutout":
        """The same test on ``geometry``, the same triangles with moved corners (node programs read its positions
        and normals)."""
        import copy
        out = copy.copy(self)
        out.geometry = geometry
        return out

    def opaque(self, prim: np.ndarray, u: np.ndarray, v: np.ndarray, d: np.ndarray | None = None,
               shadow: bool = False, camera: bool = False) -> np.ndarray:
        """(n,) bool for hits (prim >= 0) at barycentrics (u, v) of rays along ``d`` (3, n) (node programs read
        the view from it: Backfacing, Incoming; None: unknown). For ``shadow`` rays a material whose Transparent
        Shadows setting is off is opaque everywhere, as in Cycles; ``camera`` rays pass objects the camera does
        not see, shadow rays those that cast no shadow."""
        out = np.ones(len(prim), bool)
        if shadow and self.shadow_pass is not None:
            out[self.shadow_pass[prim]] = False  # an object that casts no shadow: shadow rays pass it
        if camera and self.camera_pass is not None:
            out[self.camera_pass[prim]] = False
        sel = np.flatnonzero((self.shadow_cut if shadow else self.cut)[prim] & out)
        if sel.size == 0:
            return out
        p = prim[sel]
        a = self.alpha[p].copy()
        tex = self.tex[p]
        if self.uvs is not None and (tex >= 0).any():
            for t in np.unique(tex[tex >= 0]):  # loop over textures, not hits
                rows = np.flatnonzero(tex == t)
                c = np.take(self.uvs, p[rows], axis=0)
                uv = barycentric(c[:, 0], c[:, 1], c[:, 2], u[sel][rows][:, None], v[sel][rows][:, None])
                val = np.clip(sample(self.textures[t], uv)[:, 0], 0, 1)
                a[rows] *= np.where(self.sign[p[rows]] > 0, val, 1 - val)
        rows = np.flatnonzero(self.program[p])
        if rows.size:
            a[rows] *= self._program_alpha(p[rows], u[sel][rows], v[sel][rows],
                                           None if d is None else d[:, sel][:, rows], shadow, camera)
        xi = hash_uniform(p ^ SALT, u[sel], v[sel])
        out[sel] = xi < a
        return out

    def tint(self, prim: np.ndarray, u: np.ndarray, v: np.ndarray, d: np.ndarray | None = None,
             shadow: bool = False, camera: bool = False) -> np.ndarray:
        """(3, n) float32: the colour rays along ``d`` (3, n) keep where they pass the points (prim, u, v) that
        :meth:`opaque` let them through (white where an object's Ray Visibility let them pass)."""
        mat = self.geometry.material[prim]
        out = np.ascontiguousarray(self.tint_of[mat].T)
        rows = np.flatnonzero(self.tint_program[mat])
        if rows.size:
            wo = None if d is None else cols(d, rows)
            wo = None if wo is None else (-wo / np.maximum(norm(wo), np.float32(1e-30))).astype(np.float32)

            def attrs(r):
                return HitAttributes(self.geometry, prim[rows[r]], u[rows[r]], v[rows[r]], self.textures,
                                     wo=None if wo is None else wo[:, r], camera_ray=camera, shadow_ray=shadow)
            for r, got in run_programs(self.materials, mat[rows], attrs, ("transparent_tint",)):
                if "transparent_tint" in got:
                    out[:, rows[r]] = np.maximum(got["transparent_tint"], 0)
        free = np.zeros(len(prim), bool)
        if shadow and self.shadow_pass is not None:
            free |= self.shadow_pass[prim]
        if camera and self.camera_pass is not None:
            free |= self.camera_pass[prim]
        out[:, free] = 1.0
        return out

    def _program_alpha(self, prim, u, v, d, shadow: bool = False, camera: bool = False) -> np.ndarray:
        """The node programs' "alpha" (clamped to [0, 1]) at hits on materials that have one, as the rays that
        reach them see it (Light Path's Is Shadow Ray / Is Camera Ray: a surface may hide from either)."""
        wo = None if d is None else (-d / np.maximum(norm(d), np.float32(1e-30))).astype(np.float32)
        out = np.ones(len(prim), np.float32)

        def attrs(r):
            return HitAttributes(self.geometry, prim[r], u[r], v[r], self.textures,
                                 wo=None if wo is None else wo[:, r], camera_ray=camera, shadow_ray=shadow)
        for r, got in run_programs(self.materials, self.geometry.material[prim], attrs, ("alpha",)):
            if "alpha" in got:
                out[r] = np.clip(got["alpha"], 0, 1)
        return out


def _programs_with(materials, name: str) -> np.ndarray:
    """(m,) bool: the materials whose node program computes field ``name``."""
    m = len(materials.alpha)
    index, programs = getattr(materials, "program", None), getattr(materials, "programs", None)
    if index is None or not programs:
        return np.zeros(m, bool)
    has = np.array([p.has(name) for p in programs], bool)
    return (index >= 0) & has[np.maximum(index, 0)]


def _passed_by(geometry, flag: str):
    """(n,) bool of the triangles whose object's ``flag`` (ObjectTable.casts_shadow: Ray Visibility > Shadow,
    camera_visible: > Camera) is off, or None if none."""
    objects, inst = getattr(geometry, "objects", None), getattr(geometry, "instance", None)
    flags = getattr(objects, flag, None) if objects is not None else None
    if flags is None or inst is None or flags.all():
        return None
    return ~flags[inst]
