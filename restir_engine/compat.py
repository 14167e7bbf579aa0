"""Differences between the Blender versions the add-on supports (4.2 LTS to 5.2 LTS), in one place.

Each function names what changed and in which version; callers never test ``bpy.app.version`` themselves.
- 5.0: materials and worlds always use their node tree (``use_nodes`` is gone).
- 5.0: image output settings gained ``media_type`` (image / multilayer EXR / video) beside ``file_format``.
"""
from __future__ import annotations

import bpy

NODES_ALWAYS = bpy.app.version >= (5, 0, 0)


def uses_nodes(idblock) -> bool:
    """Whether a material/world is defined by its node tree (always, from Blender 5.0 on)."""
    if idblock.node_tree is None:
        return False
    return True if NODES_ALWAYS else bool(idblock.use_nodes)


def enable_nodes(idblock) -> None:
    """Make a new material/world use its node tree (needed before Blender 5.0)."""
    if not NODES_ALWAYS:
        idblock.use_nodes = True


def set_output_format(settings, fmt: str) -> None:
    """Image output ``settings`` (scene.render.image_settings) to ``fmt``: a file format name, or
    "OPEN_EXR_MULTILAYER" (a media type of its own from Blender 5.0 on)."""
    has_media = hasattr(settings, "media_type")
    if fmt == "OPEN_EXR_MULTILAYER":
        if has_media:
            settings.media_type = "MULTI_LAYER_IMAGE"
        else:
            settings.file_format = "OPEN_EXR_MULTILAYER"
        return
    if has_media:
        settings.media_type = "IMAGE"
    settings.file_format = fmt
