"""Differences between the Blender versions the add-on supports (4.2 LTS to 5.2 LTS), in one place.

Each function names what changed and in which version; callers never test ``bpy.app.version`` themselves.
- 5.0: materials and worlds always use their node tree (``use_nodes`` is gone).
- 5.0: image output settings gained ``media_type`` (image / multilayer EXR / video) beside ``file_format``.
- 5.2: the Principled BSDF's Random Walk subsurface takes Radius x Scale as the mean free path (van de Hulst's
  albedo mapping; default Scale 0.005); the earlier walk (radius / 4π) became Random Walk (Legacy).
"""
from __future__ import annotations

import bpy

NODES_ALWAYS = bpy.app.version >= (5, 0, 0)
RANDOM_WALK_MFP = bpy.app.version >= (5, 2, 0)


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


def compositor_tree(scene, create: bool = True):
    """The scene's compositor node tree (a node group assigned to the scene from Blender 5.0 on, the scene's own
    tree with ``use_nodes`` before), created when missing and ``create``; None otherwise."""
    if hasattr(scene, "compositing_node_group"):
        tree = scene.compositing_node_group
        if tree is None and create:
            tree = bpy.data.node_groups.new(f"{scene.name} Compositing", "CompositorNodeTree")
            scene.compositing_node_group = tree
        return tree
    if create:
        scene.use_nodes = True
    return scene.node_tree


def compositor_output(tree):
    """The node whose input is the composited image: the Composite node (Blender 4.x) or the tree's Group Output
    with an "Image" socket (Blender 5.x), created when missing. Returns (node, its image input socket)."""
    if hasattr(bpy.types, "CompositorNodeComposite"):
        node = next((n for n in tree.nodes if n.bl_idname == "CompositorNodeComposite"), None) or \
            tree.nodes.new("CompositorNodeComposite")
        return node, node.inputs[0]
    if not any(i.in_out == "OUTPUT" and i.name == "Image" for i in tree.interface.items_tree
               if getattr(i, "item_type", "SOCKET") == "SOCKET"):
        tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
    node = next((n for n in tree.nodes if n.bl_idname == "NodeGroupOutput"), None) or tree.nodes.new("NodeGroupOutput")
    return node, node.inputs["Image"]
