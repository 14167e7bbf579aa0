"""Shader-node handlers for the view and space nodes: Camera Data, Vector Transform and Normal (each returns its
outputs as registers of the graph compiler, export/node_graph.py; the vector operations are core/materials/nodes/)."""
from __future__ import annotations

import numpy as np


def camera_data(g, node, f):
    """Camera Data: the hit in the camera's frame (Texture Coordinate > Camera: x right, y up, +z forward) as a unit
    View Vector, its View Z Depth (z) and View Distance (length), as Cycles computes them."""
    if g.camera is None:
        g.warn(f"'{node.name}' (Camera Data) has no camera here; its outputs are 0")
        zero = g.constant(0.0, "float")
        return {"View Vector": g.constant(0.0, "vector"), "View Z Depth": zero, "View Distance": zero}
    cam = g.emit("camera_coords", {"camera": g.camera}, [g.attribute("position", "vector")], ("vector",))[0]
    zero_v, zero_f = g.constant(0.0, "vector"), g.constant(0.0, "float")
    unit = g.emit("vector_math", {"op": "NORMALIZE"}, [cam, zero_v, zero_v, zero_f], ("vector", "float"))[0]
    length = g.emit("vector_math", {"op": "LENGTH"}, [cam, zero_v, zero_v, zero_f], ("vector", "float"))[1]
    depth = g.emit("separate", {"mode": "RGB"}, [cam], ("float", "float", "float"))[2]
    return {"View Vector": unit, "View Z Depth": depth, "View Distance": length}


def vector_transform(g, node, f):
    """Vector Transform: a point, direction or normal between world, object and camera space (core ops_spaces)."""
    spaces = {node.convert_from, node.convert_to}
    if "CAMERA" in spaces and g.camera is None:
        g.warn(f"'{node.name}' (Vector Transform) has no camera here; camera space is taken as world space")
    params = {"type": node.vector_type, "from": node.convert_from, "to": node.convert_to, "camera": g.camera}
    return {"Vector": g.emit("vector_transform", params, [g.inp(node, "Vector", "vector", f)], ("vector",))[0]}


def normal(g, node, f):
    """Normal node: its own unit direction, and Dot, that direction against the unit input Normal (as Cycles)."""
    d = np.array(node.outputs["Normal"].default_value[:3], np.float64)
    d = d / max(np.linalg.norm(d), 1e-30)
    direction = g.constant(tuple(float(x) for x in d), "vector")
    inp = g.inp(node, "Normal", "vector", f)
    zero_v, zero_f = g.constant(0.0, "vector"), g.constant(0.0, "float")
    unit = g.emit("vector_math", {"op": "NORMALIZE"}, [inp, zero_v, zero_v, zero_f], ("vector", "float"))[0]
    dot = g.emit("vector_math", {"op": "DOT_PRODUCT"}, [direction, unit, zero_v, zero_f], ("vector", "float"))[1]
    return {"Normal": direction, "Dot": dot}
