"""Mix and Add shaders: a weighted sum of BSDFs, f = Σ w_k f_k, estimated by picking one component per hit.

A hit on a mixed material picks component k with probability w_k / W (W = Σ w_k) and takes that component's BSDF
scaled by W: the expectation over the pick is f exactly (as pbrt-v4's MixMaterial does, with a hash of the hit so
every use of the same hit agrees). Weights are the Mix factors along the component's path in the node tree
(constant, or an image texture's value at the hit's UV, or a node program's value at the hit), Add shaders weigh
both sides by 1; components without a BSDF (Emission shaders, empty sockets) have been dropped from the sum by the
exporter. A component may also carry a colour factor per hit ("mix_tint:<k>", scene-linear RGB: the Coat Tint's
transmittance over a coated Principled BSDF's base) that multiplies its BSDF once it is picked, and an estimate of
its reflectance ("mix_pick:<k>"): where there are estimates, component k is picked with probability
p_k = ½ w_k/W + ½ w_k a_k/Σ w_j a_j (a defensive mix of picking by weight and by expected contribution) and scaled
by w_k/p_k, which keeps the expectation Σ w_k f_k and sends fewer samples to a faint coat over a bright base.
"""
from __future__ import annotations

import numpy as np

from .nodes import run_programs
from .textures import sample


def hash_uniform(prim: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """A uniform number in [0, 1) per hit from its triangle and barycentrics (float32 bits), well mixed."""
    with np.errstate(over="ignore"):
        h = prim.astype(np.uint32) * np.uint32(0x9E3779B1)
        h ^= np.ascontiguousarray(u, np.float32).view(np.uint32) * np.uint32(0x85EBCA77)
        h ^= np.ascontiguousarray(v, np.float32).view(np.uint32) * np.uint32(0xC2B2AE3D)
        h ^= h >> np.uint32(16)
        h *= np.uint32(0x7FEB352D)
        h ^= h >> np.uint32(15)
        h *= np.uint32(0x846CA68B)
        h ^= h >> np.uint32(16)
    return (h >> np.uint32(8)).astype(np.float32) * np.float32(1.0 / (1 << 24))


def pick_components(mats, mat: np.ndarray, rows: np.ndarray, xi: np.ndarray, uv: np.ndarray | None,
                    attrs_of=None):
    """For hits ``rows`` (k,) on mixed materials ``mat[rows]``: the picked component material (k,) and the BSDF scale
    W (k,) (0 where every weight is 0; 1 for renormalized mixes, whose transparent share is a cut-out). ``xi`` (k,)
    uniforms; ``uv`` (k, 2) the hits' UVs (None: no textures); ``attrs_of(sub)`` the HitAttributes of hits
    ``rows[sub]``, for mixes whose node program computes the weights ("mix:<j>" of component j, replacing its
    constant weight)."""
    m = mat[rows]
    first, count = mats.mix_first[m], mats.mix_count[m]
    width = int(count.max())
    slot = np.arange(width)[None, :]
    valid = slot < count[:, None]
    k = np.where(valid, first[:, None] + slot, 0)
    w = mats.mix_weight[k] * valid
    tex = np.where(valid, mats.mix_tex[k], -1)
    if uv is not None and (tex >= 0).any():
        for t in np.unique(tex[tex >= 0]):  # loop over textures, not hits
            r, c = np.nonzero(tex == t)
            val = np.clip(sample(mats.textures[t], uv[r])[:, 0], 0, 1)
            w[r, c] *= np.where(mats.mix_sign[k[r, c]] > 0, val, 1 - val)
    tints = {}  # component slot j -> (hits, their (3, k) colour factors)
    estimate = None  # (k, width) reflectance estimates of the components ("mix_pick:<k>"), where a program has them
    if attrs_of is not None:
        for sub, out in run_programs(mats, m, attrs_of):
            for j in range(width):
                got = out.get(f"mix:{j}")
                if got is not None:
                    w[sub, j] = np.maximum(got, 0) * valid[sub, j]
                colour = out.get(f"mix_tint:{j}")
                if colour is not None:
                    tints.setdefault(j, []).append((sub, colour))
                share = out.get(f"mix_pick:{j}")
                if share is not None:
                    if estimate is None:
                        estimate = np.ones(w.shape, np.float32)
                    estimate[sub, j] = np.maximum(share, np.float32(1e-4))
    total = w.sum(axis=1)
    if estimate is None:  # pick in proportion to the weights: the picked BSDF is scaled by their sum
        cdf = np.cumsum(w, axis=1)
        pick = np.minimum((cdf <= (xi * total)[:, None]).sum(axis=1), count - 1)
        scale = total
    else:  # half by the weights, half by weight x reflectance estimate: the picked BSDF scaled by w_k / p_k
        we = w * estimate
        p = 0.5 * w / np.maximum(total, 1e-30)[:, None] + 0.5 * we / np.maximum(we.sum(axis=1), 1e-30)[:, None]
        cdf = np.cumsum(p, axis=1)
        pick = np.minimum((cdf <= (xi * cdf[:, -1])[:, None]).sum(axis=1), count - 1)
        at = np.arange(len(rows))
        scale = np.where(total > 0, w[at, pick] / np.maximum(p[at, pick], 1e-30), 0.0)
    norm = getattr(mats, "mix_normalize", None)
    if norm is not None:
        scale = np.where(norm[m] & (total > 0), scale / np.maximum(total, 1e-30), scale)
    tint = None
    if tints:
        tint = np.ones((3, len(rows)), np.float32)
        for j, parts in tints.items():
            for sub, colour in parts:
                chosen = pick[sub] == j
                tint[:, sub[chosen]] = colour[:, chosen]
    return mats.mix_comp[first + pick], scale.astype(np.float32), tint
