"""Cryptomatte passes (object, material, asset): per pixel, the names its camera rays meet first, ranked by the
share of the pixel's samples each covers, as the Cryptomatte specification stores them (and Blender's
Cryptomatte node reads them): each name as the float32 whose bits are its MurmurHash3 (x86, 32 bit, seed 0; an
exponent of 0 or 255 flipped in its lowest bit), two (id, coverage) ranks per RGBA pass, ``depth`` ranks in all,
and a manifest {name: "%08x" hash} for the render's metadata.

The coverage comes from ``samples`` camera rays per pixel of their own (the pixel filter's offsets, the lens's
aperture, transparent cut-outs passed as every camera ray passes them), independent of the frame's shading.
Nothing hit covers no rank; a pixel's coverages sum to the share of its rays that hit something."""
from __future__ import annotations

import numpy as np

from ..sampling import STREAM_CRYPTO_RAYS
from .own_rays import camera_ray_sets

KINDS = ("object", "material", "asset")
PASS_PREFIX = {"object": "CryptoObject", "material": "CryptoMaterial", "asset": "CryptoAsset"}
#: pixels whose rays are ranked at once (k rays x this many int32 hit indices in memory)
BLOCK_PIXELS = 1 << 16


def murmur3_32(data: bytes, seed: int = 0) -> int:
    """MurmurHash3 x86 32-bit of ``data``."""
    c1, c2, m = 0xCC9E2D51, 0x1B873593, 0xFFFFFFFF
    h = seed & m
    n = len(data) // 4 * 4
    for i in range(0, n, 4):
        k = int.from_bytes(data[i:i + 4], "little")
        k = (k * c1) & m
        k = ((k << 15) | (k >> 17)) & m
        k = (k * c2) & m
        h ^= k
        h = ((h << 13) | (h >> 19)) & m
        h = (h * 5 + 0xE6546B64) & m
    tail = data[n:]
    if tail:
        k = int.from_bytes(tail, "little")
        k = (k * c1) & m
        k = ((k << 15) | (k >> 17)) & m
        k = (k * c2) & m
        h ^= k
    h ^= len(data)
    h ^= h >> 16
    h = (h * 0x85EBCA6B) & m
    h ^= h >> 13
    h = (h * 0xC2B2AE35) & m
    h ^= h >> 16
    return h


def name_hash(name: str) -> int:
    """A name's Cryptomatte hash (uint32), its exponent kept off 0 and 255 (the float is finite and normal)."""
    h = murmur3_32(name.encode("utf-8"))
    exp = (h >> 23) & 0xFF
    if exp in (0, 255):
        h ^= 1 << 23
    return h


def hash_float(h: int) -> float:
    return float(np.array([h], np.uint32).view(np.float32)[0])


def names_of(scene, kind: str) -> tuple[list, np.ndarray]:
    """(the names of ``kind``, each triangle's index into them (n,) int64, -1 for none)."""
    geom = scene.geometry
    if kind == "material":
        names = list(scene.materials.names)
        return names, geom.material.astype(np.int64)
    objs = getattr(geom, "objects", None)
    per_instance = list(getattr(objs, "names" if kind == "object" else "assets", ()) or ())
    if geom.instance is None or not per_instance:
        return [], np.full(len(geom), -1, np.int64)
    names = sorted(set(per_instance))
    index = {n: i for i, n in enumerate(names)}
    inst_to_name = np.array([index[n] for n in per_instance], np.int64)
    return names, inst_to_name[geom.instance.astype(np.int64)]


def render_cryptomatte(ctx, kinds, depth: int, samples: int, seed: int = 0, frame: int = 0):
    """{pass name: (h, w, 4) float32, row 0 at the bottom} for each kind in ``kinds`` with ceil(depth / 2)
    passes, and {kind: manifest dict}."""
    cam = ctx.scene.camera
    _x0, _y0, w, h = cam.window
    n_pix, k = w * h, max(1, int(samples))
    ranks = max(1, int(depth))
    tables = {kind: names_of(ctx.scene, kind) for kind in kinds}
    tops = {kind: (np.full((n_pix, ranks), -1, np.int64), np.zeros((n_pix, ranks), np.float32)) for kind in kinds}
    for lo in range(0, n_pix, BLOCK_PIXELS):
        block = np.arange(lo, min(lo + BLOCK_PIXELS, n_pix))
        prims = np.empty((k, len(block)), np.int32)
        for s, (o, d, tmax) in enumerate(camera_ray_sets(cam, k, seed, frame, STREAM_CRYPTO_RAYS, block)):
            prims[s] = ctx.geom_accel.intersect(o, d, tmax, camera=True).prim
        for kind in kinds:
            names, tri_name = tables[kind]
            ids = np.where(prims >= 0, tri_name[np.maximum(prims, 0)], -1)  # (k, block pixels)
            top_id, top_w = _ranked(ids, len(names), len(block), ranks, k)
            tops[kind][0][block], tops[kind][1][block] = top_id, top_w
    out, manifests = {}, {}
    for kind in kinds:
        names, tri_name = tables[kind]
        used = np.unique(tri_name[tri_name >= 0])  # names on the geometry (not the lamps' own material rows)
        manifests[kind] = {names[i]: f"{name_hash(names[i]):08x}" for i in used}
        top_id, top_w = tops[kind]
        floats = np.array([hash_float(name_hash(nm)) for nm in names] + [0.0], np.float32)
        id_f = floats[np.where(top_id >= 0, top_id, len(names))]
        for p in range((ranks + 1) // 2):
            img = np.zeros((n_pix, 4), np.float32)
            for r in range(2):
                rank = 2 * p + r
                if rank < ranks:
                    img[:, 2 * r] = id_f[:, rank]
                    img[:, 2 * r + 1] = top_w[:, rank]
            out[f"{PASS_PREFIX[kind]}{p:02d}"] = img.reshape(h, w, 4)
    return out, manifests


def _ranked(ids: np.ndarray, n_names: int, n_pix: int, ranks: int, k: int):
    """Per pixel the ``ranks`` most covering name indices (-1 for none) and their coverages, most first."""
    top_id = np.full((n_pix, ranks), -1, np.int64)
    top_w = np.zeros((n_pix, ranks), np.float32)
    pix = np.broadcast_to(np.arange(n_pix), ids.shape)
    hit = ids >= 0
    if not hit.any() or n_names == 0:
        return top_id, top_w
    key = pix[hit] * n_names + ids[hit]
    uniq, counts = np.unique(key, return_counts=True)
    p, nm = uniq // n_names, uniq % n_names
    order = np.lexsort((nm, -counts, p))  # per pixel: most covering first (ties: by name index)
    p, nm, counts = p[order], nm[order], counts[order]
    first = np.searchsorted(p, p, side="left")
    rank = np.arange(len(p)) - first
    keep = rank < ranks
    top_id[p[keep], rank[keep]] = nm[keep]
    top_w[p[keep], rank[keep]] = counts[keep] / np.float32(k)
    return top_id, top_w


def metadata(view_layer: str, kind: str, manifest: dict) -> dict:
    """The render result's metadata fields of one Cryptomatte layer (Blender's and the specification's keys)."""
    import json
    layer = f"{view_layer}.{PASS_PREFIX[kind]}"
    prefix = f"cryptomatte/{murmur3_32(layer.encode('utf-8')):08x}"[:len("cryptomatte/") + 7] + "/"
    return {prefix + "name": layer, prefix + "hash": "MurmurHash3_32", prefix + "conversion": "uint32_to_float32",
            prefix + "manifest": json.dumps(manifest, separators=(",", ":"))}
