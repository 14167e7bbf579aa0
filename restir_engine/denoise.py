"""Denoising with Blender's compositor: our Combined through the Denoise node (Intel Open Image Denoise) with the
Denoising Albedo and Denoising Normal passes, set up by the scene option "Denoise" (Render Properties > Sampling >
Denoising) or the operator "Set Up Denoising" for an existing scene. F12 and `-a` then write denoised frames."""
from __future__ import annotations

import bpy

from .compat import compositor_output, compositor_tree

NODE_PREFIX = "ReSTIR Denoise"


def set_up(scene) -> None:
    """Enable the denoising passes on every view layer and wire Render Layers -> Denoise -> the compositor's output
    (idempotent: the nodes are found again by name)."""
    for layer in scene.view_layers:
        layer.restir.use_pass_denoising_data = True
    scene.render.use_compositing = True
    tree = compositor_tree(scene)
    nodes = tree.nodes

    def node(kind, name, location):
        n = nodes.get(name) or nodes.new(kind)
        n.name = n.label = name
        n.location = location
        return n

    layers = node("CompositorNodeRLayers", f"{NODE_PREFIX} Layers", (-400, 0))
    layers.scene = scene
    den = node("CompositorNodeDenoise", NODE_PREFIX, (0, 0))
    out, socket = compositor_output(tree)
    out.location = (300, 0)
    links = tree.links
    links.new(layers.outputs["Image"], den.inputs["Image"])
    links.new(layers.outputs["Denoising Albedo"], den.inputs["Albedo"])
    links.new(layers.outputs["Denoising Normal"], den.inputs["Normal"])
    links.new(den.outputs["Image"], socket)


def remove(scene) -> None:
    """Take the Denoise node out of the compositor: the Render Layers image goes straight to the output again (an
    output left unconnected would make Blender write black frames). The passes stay as they are."""
    tree = compositor_tree(scene, create=False)
    if tree is None:
        return
    den = tree.nodes.get(NODE_PREFIX)
    if den is not None:
        tree.nodes.remove(den)
    layers = tree.nodes.get(f"{NODE_PREFIX} Layers")
    if layers is not None:
        _out, socket = compositor_output(tree)
        tree.links.new(layers.outputs["Image"], socket)


def update_option(settings, context) -> None:
    """The "Denoise" option's update: set up or remove the compositor's denoising."""
    scene = settings.id_data
    if settings.use_denoising:
        set_up(scene)
    else:
        remove(scene)


class RESTIR_OT_set_up_denoising(bpy.types.Operator):
    """Wire the compositor's Denoise node to the ReSTIR passes of this scene (and enable them)"""

    bl_idname = "restir.set_up_denoising"
    bl_label = "Set Up Denoising"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        set_up(context.scene)
        context.scene.restir["use_denoising"] = True
        return {"FINISHED"}


CLASSES = (RESTIR_OT_set_up_denoising,)
