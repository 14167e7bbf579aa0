"""Shading normals from image textures at hits: a tangent-space Normal Map and a Bump node whose Height is an image
(the forms export writes into MaterialTable.normal_tex / bump_tex; node programs give their own "normal"). Vectors are
(3, k) float32 rows in world space."""
from __future__ import annotations

import numpy as np

from ..sampling import barycentric, dot, norm
from .textures import gradient, sample


def normal_map(mats, geom, mat, prim, u, v, ns, rows) -> np.ndarray:
    """Shading normals (3, k) of hits ``rows`` whose material has a tangent-space Normal Map (Cycles' node): the
    texel c in [0, 1]³ becomes m = 2c - 1, scaled by the strength s (m_xy · s, m_z → mix(1, m_z, s)), and the
    normal is normalize(m_x T + m_y B + m_z N) with T the interpolated UV tangent, B = sign · N x T and N the
    interpolated normal ``ns`` (unit, not yet turned to face the ray)."""
    p = prim[rows]
    m = mat[rows]
    c = np.take(geom.uvs, p, axis=0)
    uv = barycentric(c[:, 0], c[:, 1], c[:, 2], u[rows][:, None], v[rows][:, None])
    tex = np.empty((len(rows), 3), np.float32)
    for t in np.unique(mats.normal_tex[m]):  # loop over textures, not hits
        sel = np.flatnonzero(mats.normal_tex[m] == t)
        tex[sel] = sample(mats.textures[t], uv[sel])
    col = (2.0 * tex - 1.0).T                                  # (3, k)
    strength = mats.normal_strength[m]
    col[0] *= strength
    col[1] *= strength
    col[2] = 1.0 + (col[2] - 1.0) * np.clip(strength, 0, 1)
    tg = np.take(geom.tangents, p, axis=0)                     # (k, 3 corners, 4): xyz, sign
    tan = barycentric(tg[:, 0, :3].T, tg[:, 1, :3].T, tg[:, 2, :3].T, u[rows], v[rows])
    n = ns[:, rows]
    b = np.cross(n.T, tan.T).T * tg[:, 0, 3]
    return _unit_or(col[0] * tan + col[1] * b + col[2] * n, n)


def bump_map(mats, geom, mat, prim, u, v, n, rows) -> np.ndarray:
    """Shading normals (3, k) of hits ``rows`` under Cycles' Bump node: with the height's differentials along two
    surface directions, N' = normalize(|det| N - d sign(det) (dH_1 R_1 + dH_2 R_2)), R_1 = t_2 x N, R_2 = N x t_1,
    det = t_1 · R_1, then mixed with N by the strength (d: Distance, negative when inverted). Cycles takes the
    screen-space differentials of the position; the triangle's UV differentials dP/du, dP/dv serve here (the
    formula gives the same surface gradient for any two directions where the height is linear across them),
    with the exact UV derivatives of the interpolated height (Cycles' default Filter Width, 0.1 pixel, is close to
    that limit). ``n``: (3, k) unit normals facing the ray."""
    p = prim[rows]
    m = mat[rows]
    c = np.take(geom.uvs, p, axis=0)                                   # (k, 3 corners, 2)
    uv = barycentric(c[:, 0], c[:, 1], c[:, 2], u[rows][:, None], v[rows][:, None])
    tri = np.take(geom.verts, p, axis=0)                               # (k, 3 corners, 3)
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    d1, d2 = c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]
    det_uv = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    ok = np.abs(det_uv) > 1e-12
    inv = np.where(ok, 1.0 / np.where(ok, det_uv, 1.0), 0.0)[:, None]
    dpdu = ((e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) * inv).T              # (3, k)
    dpdv = ((e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) * inv).T
    dh = np.zeros((2, len(rows)), np.float32)                          # dH/du, dH/dv
    for t in np.unique(mats.bump_tex[m]):  # loop over textures, not hits
        sel = np.flatnonzero(mats.bump_tex[m] == t)
        dh[:, sel] = gradient(mats.textures[t], uv[sel]).T
    r1 = np.cross(dpdv.T, n.T).T
    r2 = np.cross(n.T, dpdu.T).T
    det = dot(dpdu, r1)
    dist = mats.bump_distance[m]
    strength = mats.bump_strength[m]
    out = _unit_or(np.abs(det) * n - (dist * np.sign(det)) * (dh[0] * r1 + dh[1] * r2), n, ok, eps=1e-20)
    return _unit_or(strength * out + (1.0 - strength) * n, n)


def _unit_or(v: np.ndarray, fallback: np.ndarray, valid: np.ndarray | None = None, eps: float = 1e-12
             ) -> np.ndarray:
    """(3, k) ``v`` normalized, ``fallback`` where it has no direction (length not finite or <= ``eps``) or
    ``valid`` is False."""
    ln = norm(v)
    ok = np.isfinite(ln) & (ln > eps)
    if valid is not None:
        ok &= valid
    return np.where(ok, v / np.where(ok, ln, 1.0), fallback).astype(np.float32)
