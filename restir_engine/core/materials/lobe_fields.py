"""What a batch of hits (materials/surface.Surface) needs for its optional lobes, from the material table and the
node programs' per-hit fields: the anisotropic GGX frame (anisotropy.py) and the sheen rows (sheen.py).

``given``: field -> (hits given (n,) bool, values (n,) or (3, n)), what the node programs computed per hit
(:func:`keep_given`); where a hit's field was not given the material table's value holds."""
from __future__ import annotations

import numpy as np

from ..sampling import cols, dot
from .anisotropy import AnisoFrame
from .sheen import SheenRows


def keep_given(given: dict | None, rows, out: dict, n: int, fields) -> dict | None:
    """``given`` with the ``fields`` a node program computed at hits ``rows`` (of ``n``) added."""
    for name in fields:
        if name not in out:
            continue
        if given is None:
            given = {}
        hit, values = given.get(name) or (np.zeros(n, bool), np.ones((3, n) if name == "tangent" else n, np.float32))
        hit[rows] = True
        values[..., rows] = np.broadcast_to(out[name], values[..., rows].shape)
        given[name] = (hit, values)
    return given


def anisotropy_frame(surf, ctx, mat, given: dict) -> AnisoFrame | None:
    """The anisotropic hits' GGX frame of Surface ``surf`` (None where no hit is): the material's aspect and
    Rotation (or its node program's), the tangent from the program (a Tangent input) or the radial tangent about the
    object's Z axis (Cycles' default), turned about the shading normal by Rotation · 2π, in the local frame about
    the specular lobes' normal."""
    mats = ctx.scene.materials
    table = getattr(mats, "aniso_aspect", None)
    if table is None and "aniso_aspect" not in given:
        return None
    a = np.ones(len(mat), np.float32) if table is None else table[mat].astype(np.float32)
    if "aniso_aspect" in given:
        a = np.where(given["aniso_aspect"][0], given["aniso_aspect"][1], a)
    rows = np.flatnonzero((np.abs(a - np.float32(1.0)) > np.float32(1e-6)) & (surf.params.spec_on > 0))
    if rows.size == 0:
        return None
    rot_table = getattr(mats, "aniso_rotation", None)
    rot = np.zeros(rows.size, np.float32) if rot_table is None else rot_table[mat[rows]].astype(np.float32)
    if "aniso_rotation" in given:
        rot = np.where(given["aniso_rotation"][0][rows], given["aniso_rotation"][1][rows], rot)
    tangent = np.empty((3, rows.size), np.float32)
    own = np.zeros(rows.size, bool) if "tangent" not in given else given["tangent"][0][rows]
    if own.any():
        tangent[:, own] = given["tangent"][1][:, rows[own]]
    if not own.all():
        r = rows[~own]
        attrs = surf._attributes(ctx, r, cols(surf.wo, r), normal=cols(surf.ns, r), true_normal=cols(surf.ng, r))
        tangent[:, ~own] = attrs.get("tangent")
    n = cols(surf.ns, rows)
    theta = np.float32(2.0 * np.pi) * rot
    tangent = tangent * np.cos(theta) + np.cross(n.T, tangent.T).T * np.sin(theta) + \
        n * (dot(n, tangent) * (1.0 - np.cos(theta)))
    t_l = np.stack([dot(tangent, cols(surf.t, rows)), dot(tangent, cols(surf.bt, rows)), dot(tangent, n)])
    if surf.spec_n is not None:
        n_l = cols(surf.spec_n, rows)
    else:
        n_l = np.zeros((3, rows.size), np.float32)
        n_l[2] = 1.0
    return AnisoFrame.of(rows, surf.params.alpha[rows], a[rows], t_l.astype(np.float32), n_l)


def sheen_rows(ctx, mat, given: dict) -> SheenRows | None:
    """The sheen rows among hits on materials ``mat`` (None where there are none): their material's sheen roughness,
    or its node program's."""
    rough = getattr(ctx.scene.materials, "sheen_roughness", None)
    if rough is None or not rough.any():
        return None
    rows = np.flatnonzero(rough[mat] > 0)
    if rows.size == 0:
        return None
    r = rough[mat[rows]].astype(np.float32)
    got = given.get("sheen_roughness")
    if got is not None:
        r = np.where(got[0][rows], np.clip(got[1][rows], 0.0, 1.0), r).astype(np.float32)
    return SheenRows(rows, r)
