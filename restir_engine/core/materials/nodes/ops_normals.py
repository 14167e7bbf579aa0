"""Nodes that make a shading normal, as vectorized operations: Normal Map (tangent, object and world space, and
Blender's own object / world conventions) and Bump (the height sub-graph evaluated at the point and at two points
shifted along the surface, Cycles' finite-difference bump). Normals are world-space (3, n) float32 unit vectors
that face the viewer, as every normal a node program reads."""
from __future__ import annotations

import numpy as np

from .ops_math import _cross, _dot, _normalize, f32

_F = np.float32
#: Cycles' default Bump Filter Width: the height is differenced over this fraction of a pixel's footprint
FILTER_WIDTH = _F(0.1)


def _unit_or(v, fallback):
    ln = np.sqrt(_dot(v, v))
    ok = ln > _F(1e-20)
    return np.where(ok, v / np.where(ok, ln, _F(1)), fallback).astype(np.float32)


def normal_map(attrs, params, strength, color):
    """Normal Map node: the colour c as the normal 2c - 1 in the node's space. Tangent space: along the UV
    tangent T, B = sign · N x T and the interpolated normal N, the strength s scaling the tangent part
    (xy · s, z → mix(1, z, s)); T and its sign from the node's UV map (``params["uv_map"]``: the attribute
    "tangent@<map>", where the hit's mesh has that map) or the render UV map; other spaces: mixed with the normal
    by s. Turned to face the viewer."""
    n = attrs.get("normal")
    s = f32(strength)
    c = f32(color) * _F(2) - _F(1)
    c = np.broadcast_to(c, n.shape).astype(np.float32)
    space = params.get("space", "TANGENT")
    if space == "TANGENT":
        tangent, sign, has = _uv_tangent(attrs, params.get("uv_map"))
        if tangent is None:
            return n
        back = attrs.get("backfacing") > 0
        raw_n = np.where(back, -n, n)  # the interpolated normal as the mesh has it
        x, y = c[0] * s, c[1] * s
        z = _F(1) + (c[2] - _F(1)) * np.clip(s, 0, 1)
        b = _cross(raw_n, tangent) * sign
        out = _unit_or(x * tangent + y * b + z * raw_n, raw_n)
        if has is not None:  # hits on meshes without the named map keep their normal (as Cycles)
            out = np.where(has, out, raw_n)
        return np.where(back, -out, out).astype(np.float32)
    if space in {"BLENDER_OBJECT", "BLENDER_WORLD"}:
        c = np.stack([c[0], -c[1], -c[2]])
    if space in {"OBJECT", "BLENDER_OBJECT"}:
        c = attrs.object_normal_to_world(c)
    out = _unit_or(c, n)
    out = np.where(attrs.get("backfacing") > 0, -out, out)
    mixed = _unit_or(n + (out - n) * np.maximum(s, 0), n)
    return mixed


def _uv_tangent(attrs, uv_map):
    """(tangent (3, n), bitangent sign (n,), where the tangent exists (n,) bool or None for everywhere): of the UV
    map ``uv_map`` where it is given (a hit whose mesh lacks that map has none), else of the render UV map;
    (None, None, None) where no hit has one."""
    if not uv_map:
        return attrs.get("tangent_uv"), attrs.get("tangent_sign"), None
    named = attrs.get(f"attr:tangent@{uv_map}")
    length = np.sqrt(_dot(named, named))
    has = length > _F(1e-12)
    if not has.any():
        return None, None, None
    named = (named / np.maximum(length, _F(1e-30))).astype(np.float32)
    sign = np.where(attrs.get(f"attr_alpha:tangent@{uv_map}") < 0, _F(-1), _F(1)).astype(np.float32)
    return named, sign, has


def bump(attrs, params, strength, distance, normal):
    """Bump node: the height program ``params["height"]`` at the point and at points shifted by a tenth of the
    pixel footprint along two surface directions a, b (Cycles' directions from the true normal); with
    R_a = d_b x N, R_b = N x d_a, det = d_a · R_a, the bumped normal is normalize(|det| N - s sign(det)
    ((h_a - h) R_a + (h_b - h) R_b)) (≈ N - s ∇h; s = Distance, negated when inverted), mixed with N by the
    strength."""
    n = _normalize(np.broadcast_to(f32(normal), (3, len(attrs))).astype(np.float32))
    program = params["height"]
    ng = attrs.get("true_normal")
    a = _normalize(np.stack([ng[2] - ng[1], ng[0] - ng[2], ng[1] - ng[0]]))
    b = _cross(ng, a)
    step = FILTER_WIDTH * attrs.get("footprint")
    da, db = a * step, b * step
    h = program.run(attrs, ("height",))["height"]
    ha = program.run(attrs.shifted(da), ("height",))["height"]
    hb = program.run(attrs.shifted(db), ("height",))["height"]
    ra, rb = _cross(db, n), _cross(n, da)
    det = _dot(da, ra)
    s = f32(distance) * _F(-1 if params.get("invert") else 1)
    grad = (ha - h) * ra + (hb - h) * rb
    bumped = _unit_or(np.abs(det) * n - s * np.sign(det) * grad, n)
    sigma = np.maximum(f32(strength), 0)
    return _unit_or(sigma * bumped + (1 - sigma) * n, n)


OPERATIONS = {"normal_map": normal_map, "bump": bump}
#: operations that read the hits: never folded into constants at export
READS_HITS = frozenset({"normal_map", "bump"})
