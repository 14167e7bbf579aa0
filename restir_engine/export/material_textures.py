"""Blender images -> the material table's textures: read once into float32, scene-linear or (8-bit sRGB images)
sRGB-encoded and decoded after interpolation (core/materials/textures.SrgbImage), alpha or luminance replicated to
three channels, kept across renders while unchanged (export/images.py), magenta where a
file cannot be read. A mixin of MaterialRegistry (export/materials.py)."""
from __future__ import annotations

import numpy as np

from ..core.materials.textures import (MissingImage, NearestImage, SrgbImage, SrgbLuminanceImage, UdimImage,
                                       linear_texels)
from .images import TEXTURES, unreadable_file
from .udim import read_tile, tile_path, unreadable_set

MAGENTA = (1.0, 0.0, 1.0)


class TextureReader:
    """MaterialRegistry's image readers (``self.textures``, ``self.texture_index``, ``self._warn``)."""

    def _plain_image(self, material, socket) -> int | None:
        """The texture index of an Image Texture's Color wired straight into ``socket`` (see
        :meth:`_plain_image_node`), else None."""
        node = self._plain_image_node(socket)
        if node is None or socket.links[0].from_socket.name != "Color":
            return None
        return self._texture(material, node.image, closest=node.interpolation == "Closest")

    @staticmethod
    def _plain_image_node(socket):
        """The Image Texture wired straight into ``socket`` and sampled as the fixed texture path samples (the render
        UV map, Linear or Closest, Repeat, flat projection), else None."""
        link = socket.links[0] if socket.is_linked else None
        node = link.from_node if link is not None else None
        if (node is None or node.type != "TEX_IMAGE" or node.image is None or node.mute or link.is_muted
                or node.inputs["Vector"].is_linked or node.interpolation not in {"Linear", "Closest"}
                or node.extension != "REPEAT" or node.projection != "FLAT"):
            return None
        return node

    def _factor_texture(self, material, socket) -> int:
        """Texture index of an Image Texture driving a float socket (its Color as luminance, or its Alpha), or -1."""
        if not socket.is_linked:
            return -1
        link = socket.links[0]
        node = link.from_node
        if node.type != "TEX_IMAGE" or node.image is None:
            return -1
        if node.inputs["Vector"].is_linked:
            self._warn(material, f"'{node.name}' has a mapped vector input; the active UV map is used instead")
        closest = node.interpolation == "Closest"
        if link.from_socket.name == "Alpha":
            return self._texture(material, node.image, alpha=True, closest=closest)
        return self._texture(material, node.image, luminance=True, closest=closest)

    def _texture(self, material, image, alpha: bool = False, luminance: bool = False, closest: bool = False) -> int:
        """Index of an image in the texture list: its RGB (scene-linear), or its alpha / luminance replicated to
        three channels; sampled bilinearly, or by the nearest texel with ``closest`` (other interpolations:
        bilinear)."""
        key = (image.name_full, "alpha" if alpha else "luminance" if luminance else "rgb", closest)
        if key in self.texture_index:
            return self.texture_index[key]
        if getattr(image, "source", "FILE") == "TILED" and len(getattr(image, "tiles", ())) > 1:
            data = self._read_udim(material, image, alpha, luminance, closest)
            if data is not None:
                self.texture_index[key] = len(self.textures)
                self.textures.append(data)
                return self.texture_index[key]
        kept = TEXTURES.key(image, key)
        data = TEXTURES.get(kept)
        if data is None:
            data = self._read_texture(material, image, alpha, luminance)
            TEXTURES.put(kept, data)
        self.texture_index[key] = len(self.textures)
        self.textures.append(linear_texels(data).view(NearestImage) if closest and not isinstance(data, MissingImage)
                             else data)
        return self.texture_index[key]

    def _read_udim(self, material, image, alpha: bool, luminance: bool, closest: bool) -> UdimImage | None:
        """A UDIM set's tiles as one :class:`UdimImage` (a tile whose file is missing or unreadable: magenta, as
        Cycles shows it), or None (warned) where the tiles cannot be read one by one."""
        import bpy
        why = unreadable_set(image)
        if why:
            self._warn(material, f"image '{image.name}' has UDIM tiles, which cannot be read here ({why}): its "
                       "first tile is repeated over every tile")
            return None
        base = bpy.path.abspath(image.filepath, library=image.library)
        kept = _udim_key(image, base, (alpha, luminance, closest))
        cached = TEXTURES.get(kept)
        if cached is not None:
            return cached
        tiles = []
        for tile in image.tiles:
            path = tile_path(base, int(tile.number))
            got = read_tile(path, image.colorspace_settings.name)
            if got is None:
                self._warn(material, f"image '{image.name}': tile {tile.number} ('{path}') could not be read; "
                           "rendered magenta")
                data = np.array(MAGENTA, np.float32).reshape(1, 1, 3)
            else:
                data = self._converted(material, image, got[0], alpha, luminance, got[1])
            tiles.append((int(tile.number), linear_texels(data).view(NearestImage) if closest else data))
        out = UdimImage(tiles)
        TEXTURES.put(kept, out)
        return out

    def _read_texture(self, material, image, alpha: bool, luminance: bool) -> np.ndarray:
        """The image's pixels as (h, w, 3) float32, scene-linear (magenta where it cannot be read)."""
        unreadable = unreadable_file(image)
        if unreadable:  # asking Blender for its size would open it (a FIFO blocks the export for ever)
            self._warn(material, f"image '{image.name}': {unreadable}; rendered magenta")
            w = h = 0
        else:
            w, h = image.size[:]
        data = None
        if w > 0 and h > 0:
            try:
                buf = np.empty(w * h * image.channels, np.float32)
                image.pixels.foreach_get(buf)
                data = buf.reshape(h, w, image.channels)
            except (RuntimeError, ValueError):
                data = None
        if unreadable:
            return MissingImage(MAGENTA)
        if data is None or data.size == 0:
            self._warn(material, f"image '{image.name}' could not be loaded; rendered magenta")
            return MissingImage(MAGENTA)
        return self._converted(material, image, data, alpha, luminance, image.is_float)

    def _converted(self, material, image, data: np.ndarray, alpha: bool, luminance: bool, is_float: bool
                   ) -> np.ndarray:
        """(h, w, c) pixels in [0, 1] of ``image``'s colour space (float images: as stored) -> (h, w, 3) float32
        scene-linear RGB, or the alpha / luminance replicated to three channels."""
        if alpha:
            a = data[..., 3:4] if data.shape[2] == 4 else np.ones(data.shape[:2] + (1,), np.float32)
            data = np.ascontiguousarray(np.repeat(a, 3, axis=2), dtype=np.float32)
        else:
            ch = data.shape[2]
            rgb = data[..., :3] if ch >= 3 else np.repeat(data[..., :1], 3, axis=2)
            space = image.colorspace_settings.name
            srgb = not is_float and space in {"sRGB", "sRGB EOTF"}
            if not is_float and not srgb and space not in {"Linear Rec.709", "Linear", "Non-Color", "Raw",
                                                           "Linear CIE-XYZ E"}:
                self._warn(material, f"image '{image.name}' colour space '{space}' treated as sRGB")
                srgb = True
            if srgb:  # kept sRGB-encoded (the bytes), decoded after each lookup's interpolation, as Cycles does
                data = np.ascontiguousarray(np.rint(np.clip(rgb, 0.0, 1.0) * 255.0) / 255.0, dtype=np.float32)
                return data.view(SrgbLuminanceImage if luminance else SrgbImage)
            if luminance:  # Blender's implicit colour -> float conversion
                rgb = np.repeat((rgb @ np.array([0.2126, 0.7152, 0.0722], np.float32))[..., None], 3, axis=2)
            data = np.ascontiguousarray(rgb, dtype=np.float32)
        return data


def _udim_key(image, base: str, use: tuple):
    """The texture cache's key of a UDIM set's tiles (their files' paths, modification times and sizes), or None
    (not cached) where a tile's file is missing."""
    import os
    files = []
    for tile in image.tiles:
        path = tile_path(base, int(tile.number))
        try:
            st = os.stat(path)
        except OSError:
            return None
        files.append((path, st.st_mtime_ns, st.st_size))
    return ("udim", tuple(files), image.colorspace_settings.name, image.alpha_mode, use)
