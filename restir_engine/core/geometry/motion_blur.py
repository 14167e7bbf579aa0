"""Motion blur: the scene as it stands at a moment of the shutter, and the moment each sample pass sees.

Shutter time τ runs over [0, 1] from the shutter's opening to its closing. The exporter evaluates the instances'
and the camera's world matrices at ``steps`` moments spread evenly over it (Cycles' motion steps: 2^steps + 1); in
between, a matrix is interpolated as Cycles does it: decomposed into translation, rotation and scale (polar
decomposition), the translation and scale linear, the rotation by quaternion slerp, within the step segment τ
falls in. An object that moves is moved rigidly from where the frame exported it: its triangles at τ are
M(τ) · M(frame)⁻¹ times the exported ones; one that deforms takes its vertices from the steps, linearly (as Cycles
interpolates deformation).

Each sample pass of a frame renders the whole image at one τ (every ray of the pass at that time): the passes' times
are stratified over the shutter (one stratum each, in an order and with jitter keyed by seed and frame) and
distributed by the shutter curve, so the frame's average converges to the motion-blurred image.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..scene import Scene, affine_inverse

CURVE_SAMPLES = 256  # points the shutter curve is tabulated at (as Cycles)
MOVE_EPSILON = 1e-6  # relative matrix change below which an instance counts as still


@dataclass
class ShutterMotion:
    """Where things are during the shutter (τ in [0, 1]; ``steps`` evenly spaced moments, the first at 0).

    instance_steps (s, k, 4, 4) float64: each instance's world matrix at each step (index: TriangleSet.instance)
    current (k, 4, 4) float64: the matrices the exported triangles were placed with (the frame's own time)
    camera_steps (s, 4, 4) float64: the camera's (orthonormal) matrix at each step, or None when it does not move
    curve (CURVE_SAMPLES,) float64: the shutter curve's values over τ (None: a flat curve, uniform times)
    deform_rows (d,) int64: the triangles whose vertices deform; deform_steps (s, d, 3, 3) float32 their world
    corners at each step (None: nothing deforms)
    """

    instance_steps: np.ndarray
    current: np.ndarray
    camera_steps: np.ndarray | None = None
    curve: np.ndarray | None = None
    deform_rows: np.ndarray | None = None
    deform_steps: np.ndarray | None = None

    def __post_init__(self):
        steps = np.asarray(self.instance_steps, np.float64)
        if len(steps) >= 2 and steps.shape[1]:
            scale = np.maximum(np.abs(self.current).max(axis=(1, 2)), 1.0)
            change = np.abs(steps - self.current[None]).max(axis=(0, 2, 3))
            self.moving = change > MOVE_EPSILON * scale  # (k,) bool
        else:
            self.moving = np.zeros(steps.shape[1] if steps.ndim == 4 else 0, bool)
        self._inverse_current = affine_inverse(self.current) if len(self.current) else self.current
        self._cdf = _inverse_cdf_table(self.curve)

    @property
    def steps(self) -> int:
        return len(self.instance_steps)

    @property
    def moves(self) -> bool:
        """Whether anything moves during the shutter (otherwise motion blur changes nothing)."""
        return bool(self.moving.any()) or self.camera_steps is not None or self.deform_rows is not None

    def moving_rows(self, instance: np.ndarray | None) -> np.ndarray:
        """The triangle rows (int64) that move or deform, given the triangles' instances."""
        rows = np.zeros(0, np.int64)
        if instance is not None and len(instance) and self.moving.any():
            rows = np.flatnonzero(self.moving[np.clip(instance, 0, len(self.moving) - 1)])
        if self.deform_rows is not None:
            rows = np.union1d(rows, self.deform_rows)
        return rows.astype(np.int64)

    # -- times --------------------------------------------------------------------------------------------
    def time_of(self, u: float) -> float:
        """The shutter time τ of a uniform number u in [0, 1): the shutter curve's inverse CDF."""
        if self._cdf is None:
            return float(u)
        return float(np.interp(u, self._cdf, np.linspace(0.0, 1.0, len(self._cdf))))

    def pass_time(self, seed: int, frame: int, sample: int, samples: int) -> float:
        """τ of sample pass ``sample`` of ``samples``: stratum π(sample) of a permutation keyed by (seed, frame),
        jittered within it, through the shutter curve. The same seed and frame give the same times."""
        samples = max(int(samples), 1)
        rng = np.random.default_rng([int(seed) & 0xFFFFFFFF, int(frame) & 0xFFFFFFFF, 0x6D62])
        order = rng.permutation(samples)
        jitter = rng.random(samples)
        s = int(sample) % samples
        return self.time_of((order[s] + jitter[s]) / samples)

    # -- poses ------------------------------------------------------------------------------------------------
    def _segment(self, tau: float) -> tuple[int, float]:
        x = min(max(float(tau), 0.0), 1.0) * (self.steps - 1)
        j = min(int(np.floor(x)), self.steps - 2)
        return j, x - j

    def instance_matrices(self, tau: float) -> np.ndarray:
        """(k, 4, 4) float64: every instance's world matrix at τ."""
        if self.steps < 2:
            return self.instance_steps[0].copy()
        j, f = self._segment(tau)
        return interpolate(self.instance_steps[j], self.instance_steps[j + 1], f)

    def camera_matrix(self, tau: float) -> np.ndarray | None:
        """(4, 4) the camera's matrix at τ, or None when the camera does not move."""
        if self.camera_steps is None:
            return None
        j, f = self._segment(tau)
        m = interpolate(self.camera_steps[j][None], self.camera_steps[j + 1][None], f)[0]
        return m

    def deformed(self, tau: float) -> np.ndarray | None:
        """(d, 3, 3) float32: the deforming triangles' corners at τ (linear between steps), or None."""
        if self.deform_rows is None:
            return None
        j, f = self._segment(tau)
        a, b = self.deform_steps[j], self.deform_steps[j + 1]
        return (a + np.float32(f) * (b - a)).astype(np.float32)

    def scene_at(self, scene: Scene, tau: float, into: Scene | None = None) -> Scene:
        """``scene`` as it stands at shutter time τ: moving instances' triangles (corners, shading normals, UV
        tangents) moved, deforming ones taken from the steps, the objects' matrices and the camera at τ. The
        arrays of what does not move are shared with ``scene``. ``into``: an earlier result of this call for the
        same ``scene``, whose geometry arrays are overwritten in the moving rows only (no copy of the others;
        that earlier scene then stands at τ too)."""
        geom = scene.geometry
        rows = self.moving_rows(geom.instance)
        if rows.size:
            geom = self._geometry_at(geom, rows, tau, None if into is None else into.geometry)
        camera = scene.camera
        c2w = self.camera_matrix(tau)
        if c2w is not None:
            camera = dataclasses.replace(camera, cam_to_world=c2w)
        return dataclasses.replace(scene, geometry=geom, camera=camera)

    def _geometry_at(self, geom, rows: np.ndarray, tau: float, into=None):
        mats = self.instance_matrices(tau)
        rel = np.einsum("kij,kjl->kil", mats, self._inverse_current)  # M(τ) · M(frame)⁻¹ per instance
        inst = np.clip(geom.instance[rows], 0, len(rel) - 1) if geom.instance is not None else np.zeros(len(rows),
                                                                                                       np.intp)
        lin = rel[inst, :3, :3]
        verts = geom.verts.copy() if into is None else into.verts
        v = geom.verts[rows].astype(np.float64)
        verts[rows] = (np.einsum("nij,ncj->nci", lin, v) + rel[inst, None, :3, 3]).astype(np.float32)
        normal_lin = np.swapaxes(affine_inverse(rel)[:, :3, :3], 1, 2)[inst]  # inverse transpose
        normals = geom.normals.copy() if into is None else into.normals
        normals[rows] = _unit(np.einsum("nij,ncj->nci", normal_lin, geom.normals[rows].astype(np.float64)))
        tangents = geom.tangents
        if tangents is not None:
            tangents = tangents.copy() if into is None else into.tangents
            tangents[rows, :, :3] = _unit(np.einsum("nij,ncj->nci", lin, geom.tangents[rows, :, :3]
                                                    .astype(np.float64)))
        deformed = self.deformed(tau)
        if deformed is not None:
            verts[self.deform_rows] = deformed
            normals[self.deform_rows] = _deformed_normals(geom, self.deform_rows, deformed)
        objects = geom.objects
        if objects is not None and self.moving.any():
            w2o = objects.world_to_object.copy()
            loc = objects.location.copy()
            k = np.flatnonzero(self.moving[:len(w2o)])
            w2o[k] = affine_inverse(mats[k])[:, :3, :4]
            loc[k] = mats[k, :3, 3]
            objects = dataclasses.replace(objects, world_to_object=w2o, location=loc.astype(objects.location.dtype))
        return dataclasses.replace(geom, verts=verts, normals=normals, tangents=tangents, objects=objects)


def _unit(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return (v / np.maximum(n, 1e-30)).astype(np.float32)


def _deformed_normals(geom, rows: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """Shading normals of deformed triangles: the exported normals turned by the rotation that takes each
    triangle's exported face normal to its deformed one (smooth shading keeps its variation across the face)."""
    def face(v):
        n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]).astype(np.float64)
        return n / np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-30)
    a, b = face(geom.verts[rows]), face(corners)
    axis = np.cross(a, b)
    s = np.linalg.norm(axis, axis=1)
    c = np.einsum("ni,ni->n", a, b)
    k = axis / np.maximum(s, 1e-30)[:, None]
    nrm = geom.normals[rows].astype(np.float64)
    # Rodrigues' rotation of each corner normal about k by the angle between the face normals
    kxn = np.cross(k[:, None, :], nrm)
    kdn = np.einsum("ni,nci->nc", k, nrm)[..., None]
    out = nrm * c[:, None, None] + kxn * s[:, None, None] + k[:, None, :] * kdn * (1.0 - c)[:, None, None]
    return _unit(out)


# -- decomposed interpolation ----------------------------------------------------------------------------------
def interpolate(a: np.ndarray, b: np.ndarray, f: float) -> np.ndarray:
    """Affine matrices (k, 4, 4) between ``a`` (f = 0) and ``b`` (f = 1): translation and the symmetric scale
    factor linearly, the rotation by slerp of unit quaternions along the shorter arc."""
    a = np.asarray(a, np.float64)
    b = np.asarray(b, np.float64)
    ra, sa = _polar(a[:, :3, :3])
    rb, sb = _polar(b[:, :3, :3])
    qa, qb = _quaternion(ra), _quaternion(rb)
    q = _slerp(qa, qb, float(f))
    out = np.zeros_like(a)
    out[:, :3, :3] = np.einsum("kij,kjl->kil", _rotation(q), sa + f * (sb - sa))
    out[:, :3, 3] = a[:, :3, 3] + f * (b[:, :3, 3] - a[:, :3, 3])
    out[:, 3, 3] = 1.0
    return out


def _polar(m: np.ndarray):
    """(R, S) with m = R · S, R a rotation and S symmetric. A mirroring m (negative determinant) is taken as
    R · (-S') from the polar decomposition of -m, so two mirrored matrices interpolate through mirrored ones."""
    sign = np.where(np.linalg.det(m) < 0, -1.0, 1.0)
    u, sig, vt = np.linalg.svd(m * sign[:, None, None])
    det = np.sign(np.linalg.det(u @ vt))
    det[det == 0] = 1.0
    d = np.ones_like(sig)
    d[:, 2] = det
    r = np.einsum("kij,kj,kjl->kil", u, d, vt)
    s = np.einsum("kji,kj,kjl->kil", vt, sig * d, vt) * sign[:, None, None]
    return r, s


def _quaternion(r: np.ndarray) -> np.ndarray:
    """Unit quaternions (k, 4) as (w, x, y, z) of rotation matrices (k, 3, 3) (the largest of the four
    candidates' denominators, for accuracy)."""
    tr = np.trace(r, axis1=1, axis2=2)
    cand = np.stack([1 + tr, 1 + r[:, 0, 0] - r[:, 1, 1] - r[:, 2, 2], 1 - r[:, 0, 0] + r[:, 1, 1] - r[:, 2, 2],
                     1 - r[:, 0, 0] - r[:, 1, 1] + r[:, 2, 2]], axis=1)
    pick = np.argmax(cand, axis=1)
    q = np.zeros((len(r), 4))
    for i in range(4):  # four formulas (not a loop over data)
        sel = pick == i
        if not sel.any():
            continue
        m = r[sel]
        s = np.sqrt(np.maximum(cand[sel, i], 1e-300)) * 2.0
        if i == 0:
            q[sel] = np.stack([s / 4, (m[:, 2, 1] - m[:, 1, 2]) / s, (m[:, 0, 2] - m[:, 2, 0]) / s,
                               (m[:, 1, 0] - m[:, 0, 1]) / s], axis=1)
        elif i == 1:
            q[sel] = np.stack([(m[:, 2, 1] - m[:, 1, 2]) / s, s / 4, (m[:, 0, 1] + m[:, 1, 0]) / s,
                               (m[:, 0, 2] + m[:, 2, 0]) / s], axis=1)
        elif i == 2:
            q[sel] = np.stack([(m[:, 0, 2] - m[:, 2, 0]) / s, (m[:, 0, 1] + m[:, 1, 0]) / s, s / 4,
                               (m[:, 1, 2] + m[:, 2, 1]) / s], axis=1)
        else:
            q[sel] = np.stack([(m[:, 1, 0] - m[:, 0, 1]) / s, (m[:, 0, 2] + m[:, 2, 0]) / s,
                               (m[:, 1, 2] + m[:, 2, 1]) / s, s / 4], axis=1)
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def _slerp(qa: np.ndarray, qb: np.ndarray, f: float) -> np.ndarray:
    dot = np.einsum("ki,ki->k", qa, qb)
    qb = np.where(dot[:, None] < 0, -qb, qb)
    dot = np.abs(dot)
    theta = np.arccos(np.clip(dot, -1.0, 1.0))
    sin = np.sin(theta)
    near = sin < 1e-9
    wa = np.where(near, 1.0 - f, np.sin((1.0 - f) * theta) / np.where(near, 1.0, sin))
    wb = np.where(near, f, np.sin(f * theta) / np.where(near, 1.0, sin))
    q = wa[:, None] * qa + wb[:, None] * qb
    return q / np.linalg.norm(q, axis=1, keepdims=True)


def _rotation(q: np.ndarray) -> np.ndarray:
    w, x, y, z = q.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=1)], axis=1)


def _inverse_cdf_table(curve: np.ndarray | None) -> np.ndarray | None:
    """The CDF (CURVE_SAMPLES,) over τ of a shutter curve's tabulated values (negative values read as 0), for
    inverting by interpolation; None for a flat curve or one with no area (uniform times)."""
    if curve is None:
        return None
    c = np.maximum(np.asarray(curve, np.float64), 0.0)
    if len(c) < 2 or c.max() <= 0 or np.allclose(c, c[0]):
        return None
    seg = 0.5 * (c[1:] + c[:-1])
    cdf = np.concatenate([[0.0], np.cumsum(seg)])
    cdf /= cdf[-1]
    return cdf
