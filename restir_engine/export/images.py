"""Image files for textures: whether a file can be opened, and the cache that keeps textures read from unchanged
files across exports."""
from __future__ import annotations

import os
import stat

import numpy as np

from ..core.materials.textures import texture_bytes


class TextureCache:
    """Textures read from image files, kept across exports (frames of an animation, viewport edits) while the file
    is unchanged: keyed by its path, modification time and size and by how the pixels are used. Packed, generated
    and edited (unsaved) images are read afresh each time. Holds at most ``max_bytes``, least recently used out."""

    def __init__(self, max_bytes: int = 2 << 30):
        self.max_bytes = max_bytes
        self.items: dict = {}

    @staticmethod
    def key(image, use: tuple):
        if image.source != "FILE" or image.packed_file is not None or image.is_dirty:
            return None
        import bpy
        path = bpy.path.abspath(image.filepath, library=image.library)
        try:
            st = os.stat(path)
        except OSError:
            return None
        return (path, st.st_mtime_ns, st.st_size, image.colorspace_settings.name, image.alpha_mode, use[1:])

    def get(self, key):
        if key is None or key not in self.items:
            return None
        self.items[key] = self.items.pop(key)  # most recently used last
        return self.items[key]

    def put(self, key, data: np.ndarray) -> None:
        if key is None or texture_bytes(data) > self.max_bytes:
            return
        self.items[key] = data
        while sum(texture_bytes(a) for a in self.items.values()) > self.max_bytes:
            del self.items[next(iter(self.items))]


TEXTURES = TextureCache()  # the process-wide cache the exports share


def unreadable_file(image) -> str:
    """Why the file an image would be loaded from is not one to open ('' when it is, or when the image is packed,
    generated or a sequence/UDIM set whose files Blender resolves itself)."""
    if image.source != "FILE" or image.packed_file is not None:
        return ""
    import bpy
    path = bpy.path.abspath(image.filepath, library=image.library)
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return ""  # missing: Blender's own load fails and says so (the magenta warning below)
    if stat.S_ISDIR(mode):
        return f"'{path}' is a folder"
    if not stat.S_ISREG(mode):
        return f"'{path}' is not a regular file (a pipe or device)"
    return ""
