"""UDIM image sets (an Image of source "Tiled") -> their tiles' pixels, read from the tiles' own files.

Blender's Python API reads only one tile of a tiled image through ``Image.pixels``; each tile's file is read here
with Blender's ``imbuf`` module instead (its pixel buffer, Blender 5.2 and later), which touches no data-block, so
it is safe from the render thread. A tile's file is the image's path with ``<UDIM>`` replaced by the tile number
(1001, 1002, ...) or ``<UVTILE>`` by ``u<column + 1>_v<row + 1>``. Packed or generated tile sets have no such files.
"""
from __future__ import annotations

import os

import numpy as np


def tile_path(path: str, number: int) -> str:
    """The file of tile ``number`` of a UDIM set whose path holds the ``<UDIM>`` or ``<UVTILE>`` token."""
    column, row = (number - 1001) % 10, (number - 1001) // 10
    return path.replace("<UDIM>", str(number)).replace("<UVTILE>", f"u{column + 1}_v{row + 1}")


def unreadable_set(image) -> str:
    """Why the tiles of ``image`` cannot be read one by one ('' when they can)."""
    try:
        import imbuf
    except ImportError:
        return "this Blender has no imbuf module"
    if not hasattr(getattr(imbuf.types, "ImBuf", object), "with_buffer"):
        return "this Blender's imbuf module gives no pixel access (Blender 5.2 and later do)"
    if image.packed_file is not None or len(getattr(image, "packed_files", ())) > 0:
        return "its tiles are packed into the .blend file"
    if "<UDIM>" not in image.filepath and "<UVTILE>" not in image.filepath:
        return "its path names no <UDIM> or <UVTILE> token"
    return ""


LINEAR_FILES = (".exr", ".hdr")  # float files stored linear; imbuf turns other float files (16-bit PNG, TIFF) from
#                                  sRGB to linear as it loads them


def read_tile(path: str, colorspace: str):
    """(pixels (h, w, c) with row 0 at the bottom, whether they are float) of an image file whose Blender image has
    colour space ``colorspace``, as ``Image.pixels`` gives them: byte images as float32 in [0, 1] of the file's colour
    space; float images scene-linear for sRGB and their stored values otherwise (imbuf decodes a 16-bit PNG from
    sRGB, which a Non-Color image must not be). None when the file cannot be read."""
    import imbuf
    if not os.path.isfile(path):
        return None
    try:
        ib = imbuf.load(path)
    except (OSError, ValueError, RuntimeError):
        return None
    try:
        is_float = ib.buffer_type == "FLOAT" if hasattr(ib, "buffer_type") else False
        with ib.with_buffer() as buf:
            data = np.array(buf, copy=True)
    finally:
        ib.free()
    if data.ndim == 2:
        data = data[..., None]
    data = data.astype(np.float32)
    if not is_float:
        data /= np.float32(255.0)
    elif not path.lower().endswith(LINEAR_FILES) and colorspace not in {"sRGB", "sRGB EOTF"}:
        data[..., :3] = linear_to_srgb(data[..., :3])
    return data, is_float


def linear_to_srgb(c: np.ndarray) -> np.ndarray:
    """The sRGB encoding of linear values (the inverse of the decoding imbuf applied)."""
    c = np.maximum(c, 0.0)
    return np.where(c <= 0.0031308, c * 12.92, 1.055 * np.power(c, 1 / 2.4) - 0.055).astype(np.float32)
