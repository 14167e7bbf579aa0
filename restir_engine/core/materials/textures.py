"""Texture lookups (repeat wrap), vectorized over hits: bilinear, or nearest for images marked
:class:`NearestImage` (an Image Texture node's "Closest" interpolation); UDIM sets (:class:`UdimImage`) per tile.

Images are (h, w, 3) float32 scene-linear, row 0 at the bottom as Blender stores them,
so uv (0, 0) is the bottom-left corner and texel (i, j) is centred at ((j+0.5)/w, (i+0.5)/h). An 8-bit sRGB image
(:class:`SrgbImage`) keeps its sRGB-encoded texels and is decoded after interpolation, as Cycles keeps and samples
such images (so a magnified edge between two texels blends their sRGB values).
"""
from __future__ import annotations

import numpy as np


MISSING_TILE = (1.0, 0.0, 1.0)  # the colour Cycles gives UVs outside every tile of a UDIM set (magenta)


class NearestImage(np.ndarray):
    """An image sampled with nearest-texel lookups (``array.view(NearestImage)``)."""


class SrgbImage(np.ndarray):
    """An image whose texels are sRGB-encoded values in [0, 1] (an 8-bit image in the sRGB colour space): every
    lookup interpolates them and then decodes the result to scene-linear RGB (:func:`decoded`)."""


class SrgbLuminanceImage(SrgbImage):
    """An :class:`SrgbImage` read as a float (a Color output wired into a float socket): the luminance of the decoded
    colour, replicated to three channels."""


def srgb_to_linear(c: np.ndarray) -> np.ndarray:
    """The sRGB transfer function decoded: sRGB-encoded values -> scene-linear, float32 (negative values -> 0)."""
    c = np.asarray(c, np.float32)
    return np.where(c < np.float32(0.04045), np.maximum(c, np.float32(0)) * np.float32(1 / 12.92),
                    ((np.maximum(c, np.float32(0.04045)) + np.float32(0.055)) * np.float32(1 / 1.055))
                    ** np.float32(2.4)).astype(np.float32)


def _srgb_slope(c: np.ndarray) -> np.ndarray:
    """d srgb_to_linear / dc."""
    c = np.asarray(c, np.float32)
    return np.where(c < np.float32(0.04045), np.float32(1 / 12.92),
                    np.float32(2.4 / 1.055) * ((np.maximum(c, np.float32(0.04045)) + np.float32(0.055))
                                              * np.float32(1 / 1.055)) ** np.float32(1.4)).astype(np.float32)


_LUMINANCE = np.array([0.2126, 0.7152, 0.0722], np.float32)


def decoded(image: np.ndarray, texels: np.ndarray) -> np.ndarray:
    """(n, c) interpolated ``texels`` of ``image`` as scene-linear values: sRGB-decoded for an :class:`SrgbImage`
    (the luminance replicated for an :class:`SrgbLuminanceImage`), unchanged for any other image."""
    if not isinstance(image, SrgbImage):
        return texels
    rgb = srgb_to_linear(np.asarray(texels))
    if isinstance(image, SrgbLuminanceImage):
        return np.repeat((rgb[:, :3] @ _LUMINANCE)[:, None], rgb.shape[1], axis=1).astype(np.float32)
    return rgb


def linear_texels(image: np.ndarray) -> np.ndarray:
    """The image's texels as scene-linear float32 (h, w, c) (decoded per texel for an :class:`SrgbImage`)."""
    if not isinstance(image, SrgbImage):
        return image
    h, w, c = image.shape
    return decoded(image, np.asarray(image).reshape(-1, c)).reshape(h, w, c)


class MissingImage(np.ndarray):
    """An image that could not be read: every lookup, at any coordinates, with any interpolation and extension,
    reads its one texel (magenta), with alpha 1, as Cycles shows a missing image."""

    def __new__(cls, color=MISSING_TILE):
        return np.array(color, np.float32).reshape(1, 1, 3).view(cls)


def missing_lookup(image: np.ndarray, n: int) -> np.ndarray:
    """(n, c) texels of a :class:`MissingImage`."""
    return np.repeat(np.asarray(image).reshape(1, -1), n, axis=0).astype(np.float32)


class UdimImage(np.ndarray):
    """A UDIM image set: ``tiles`` ((number, (h, w, c) image) per tile; each tile an ordinary image, a NearestImage
    where sampled so). The array itself is the first tile, what code that knows no tiles reads (its size).

    As Cycles maps UVs to tiles: tile 1001 + 10 int(v) + int(u) (int: truncated toward zero; columns 0-9), sampled at
    (u - int(u), v - int(v)); a UV on no tile of the set reads :data:`MISSING_TILE`."""

    def __new__(cls, tiles):
        tiles = tuple((int(n), t) for n, t in tiles)
        obj = np.asarray(tiles[0][1]).view(cls)
        obj.tiles = tiles
        return obj

    def __array_finalize__(self, obj):
        self.tiles = getattr(obj, "tiles", ())

    def __reduce__(self):
        return (_udim_image, (self.tiles,))


def _udim_image(tiles):
    return UdimImage(tiles)


def per_tile(image: UdimImage, u: np.ndarray, v: np.ndarray, lookup, channels: int, missing=MISSING_TILE
             ) -> np.ndarray:
    """(n, channels) float32: ``lookup(tile, u_tile, v_tile)`` of the tile each (u, v) falls on (see UdimImage),
    ``missing`` where it falls on none."""
    u = np.where(np.isfinite(u), u, 0.0)
    v = np.where(np.isfinite(v), v, 0.0)
    tu, tv = np.trunc(u), np.trunc(v)
    number = np.where((tu >= 0) & (tv >= 0) & (tu < 10), 1001 + 10 * tv + tu, -1).astype(np.int64)
    out = np.empty((len(u), channels), np.float32)
    out[:] = np.asarray(missing, np.float32)[:channels]
    for n, tile in image.tiles:
        sel = np.flatnonzero(number == n)
        if sel.size:
            out[sel] = lookup(tile, u[sel] - tu[sel], v[sel] - tv[sel])
    return out


def sample(image: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """(n, 3) texels of ``image`` at ``uv`` (n, 2), by the image's interpolation."""
    if isinstance(image, UdimImage):
        return per_tile(image, uv[:, 0], uv[:, 1], lambda t, u, v: sample(t, np.stack([u, v], axis=1)),
                        image.shape[2])
    if isinstance(image, MissingImage):
        return missing_lookup(image, len(uv))
    if isinstance(image, NearestImage):
        return sample_nearest(np.asarray(image), uv)
    return decoded(image, sample_bilinear(np.asarray(image), uv))


def sample_nearest(image: np.ndarray, uv: np.ndarray) -> np.ndarray:
    h, w = image.shape[:2]
    x = np.where(np.isfinite(uv[:, 0]), uv[:, 0] * w, 0.0)
    y = np.where(np.isfinite(uv[:, 1]), uv[:, 1] * h, 0.0)
    return image[np.floor(y).astype(np.int64) % h, np.floor(x).astype(np.int64) % w].astype(np.float32)


def _bilinear_cell(image: np.ndarray, uv: np.ndarray):
    """The texel cell bilinear interpolation reads at ``uv`` (repeat wrap): its column and row indices x0, x1,
    y0, y1 (n,) and the fractions fx, fy (n,) float32 of the position inside it."""
    h, w = image.shape[:2]
    x = uv[:, 0] * w - 0.5
    y = uv[:, 1] * h - 0.5
    x = np.where(np.isfinite(x), x, 0.0)
    y = np.where(np.isfinite(y), y, 0.0)
    x0 = np.floor(x)
    y0 = np.floor(y)
    fx = (x - x0).astype(np.float32)
    fy = (y - y0).astype(np.float32)
    x0 = x0.astype(np.int64) % w
    y0 = y0.astype(np.int64) % h
    return x0, (x0 + 1) % w, y0, (y0 + 1) % h, fx, fy


def sample_bilinear(image: np.ndarray, uv: np.ndarray) -> np.ndarray:
    x0, x1, y0, y1, fx, fy = _bilinear_cell(image, uv)
    fx, fy = fx[:, None], fy[:, None]
    top = image[y0, x0] * (1 - fx) + image[y0, x1] * fx
    bot = image[y1, x0] * (1 - fx) + image[y1, x1] * fx
    return (top * (1 - fy) + bot * fy).astype(np.float32)


def gradient(image: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """(n, 2) derivatives d/du, d/dv of the first channel of ``image`` as :func:`sample` interpolates it at ``uv``
    (bilinear: the exact derivative inside the texel cell; nearest: zero, the image being constant there)."""
    if isinstance(image, UdimImage):
        return per_tile(image, uv[:, 0], uv[:, 1], lambda t, u, v: gradient(t, np.stack([u, v], axis=1)), 2,
                        (0.0, 0.0))
    if isinstance(image, NearestImage):
        return np.zeros((len(uv), 2), np.float32)
    h, w = image.shape[:2]
    x0, x1, y0, y1, fx, fy = _bilinear_cell(image, uv)
    channels = 3 if isinstance(image, SrgbLuminanceImage) else 1
    grads = []
    for k in range(channels):
        c = np.asarray(image)[..., k]
        a, b, cc, d = c[y0, x0], c[y0, x1], c[y1, x0], c[y1, x1]
        du = ((b - a) * (1 - fy) + (d - cc) * fy) * w
        dv = ((cc - a) * (1 - fx) + (d - b) * fx) * h
        if isinstance(image, SrgbImage):  # the chain rule through the decoding at the interpolated value
            top, bot = a + (b - a) * fx, cc + (d - cc) * fx
            slope = _srgb_slope(top + (bot - top) * fy)
            du, dv = du * slope, dv * slope
        grads.append(np.stack([du, dv], axis=1))
    if channels == 3:
        return sum(g * wk for g, wk in zip(grads, _LUMINANCE)).astype(np.float32)
    return grads[0].astype(np.float32)


def apply_texture(values: np.ndarray, tex_index: np.ndarray, uv: np.ndarray | None, textures: list) -> np.ndarray:
    """Multiply ``values`` (n, 3) by the texture each row names (-1 = none)."""
    if uv is None or not textures:
        return values
    out = values.copy()
    for t, image in enumerate(textures):  # loop over textures, not over hits
        sel = np.flatnonzero(tex_index == t)
        if sel.size:
            out[sel] *= sample(image, uv[sel])
    return out


def mean_color(image: np.ndarray) -> np.ndarray:
    """The mean texel (c,) over the image's UV area (a UDIM set: each tile's mean, equally weighted)."""
    if isinstance(image, UdimImage):
        return np.mean([mean_color(t) for _n, t in image.tiles], axis=0).astype(np.float32)
    return np.asarray(linear_texels(image)).reshape(-1, image.shape[-1]).mean(axis=0).astype(np.float32)


def texture_bytes(image: np.ndarray) -> int:
    """Bytes an image holds (every tile of a UDIM set)."""
    if isinstance(image, UdimImage):
        return sum(np.asarray(t).nbytes for _n, t in image.tiles)
    return image.nbytes
