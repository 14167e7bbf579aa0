"""World background -> constant environment radiance (W·sr⁻¹·m⁻², scene-linear)."""
from __future__ import annotations

import numpy as np

from .materials import uses_nodes


def export_world(scene, warnings: list) -> np.ndarray:
    world = scene.world
    if world is None:
        return np.zeros(3, np.float32)
    if not uses_nodes(world):
        return np.array(world.color[:3], np.float32)
    tree = world.node_tree
    outputs = [n for n in tree.nodes if n.type == "OUTPUT_WORLD" and n.is_active_output] or \
              [n for n in tree.nodes if n.type == "OUTPUT_WORLD"]
    if not outputs or not outputs[0].inputs["Surface"].is_linked:
        return np.zeros(3, np.float32)
    node = outputs[0].inputs["Surface"].links[0].from_node
    if node.type != "BACKGROUND":
        warnings.append(f"World '{world.name}': '{node.name}' is not a Background node; using the world colour")
        return np.array(world.color[:3], np.float32)
    color_in, strength_in = node.inputs["Color"], node.inputs["Strength"]
    if color_in.is_linked or strength_in.is_linked:
        warnings.append(f"World '{world.name}': textured background approximated by its constant colour "
                        "(only constant world colours are supported)")
    return (np.array(color_in.default_value[:3], np.float32) * float(strength_in.default_value)).astype(np.float32)
