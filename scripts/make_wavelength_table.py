"""Writes restir_engine/core/materials/data/wavelength.json: the colour Blender's Wavelength node gives (scene-linear
Rec.709) at every whole nanometre from 360 to 800, the table core/materials/nodes/ops_math.wavelength interpolates.

Cycles renders one row of pixels of an orthographic camera looking at an emissive plane whose Emission colour is the
Wavelength node of 360 + i nm at pixel i's centre (Generated X through a Math node), with a pixel filter of 0.01
pixel (every sample at the pixel's centre: the value itself, no noise). Run with a bpy Python:
    .venv313/bin/python scripts/make_wavelength_table.py
"""
from __future__ import annotations

import json
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [os.path.join(ROOT, "tests"), ROOT, os.path.join(ROOT, "scripts")]
OUT = os.path.join(ROOT, "restir_engine", "core", "materials", "data", "wavelength.json")
LOW, HIGH = 360, 800  # nm: the table's first and last node, one per nanometre


def measure() -> list:
    import bpy
    from bpy_scenes import camera, configure_cycles, emission, plane, render_passes, reset
    scene = reset()
    count = HIGH - LOW + 1
    mat = emission("Wavelength", (1, 1, 1), 1.0)
    tree = mat.node_tree
    coords = tree.nodes.new("ShaderNodeTexCoord")
    sep = tree.nodes.new("ShaderNodeSeparateXYZ")
    nm = tree.nodes.new("ShaderNodeMath")
    nm.operation = "MULTIPLY_ADD"
    nm.inputs[1].default_value = float(count)
    nm.inputs[2].default_value = LOW - 0.5
    wave = tree.nodes.new("ShaderNodeWavelength")
    tree.links.new(coords.outputs["Generated"], sep.inputs[0])
    tree.links.new(sep.outputs["X"], nm.inputs[0])
    tree.links.new(nm.outputs[0], wave.inputs[0])
    tree.links.new(wave.outputs[0], tree.nodes["Emission"].inputs["Color"])
    plane("Strip", 2.0, (0, 0, 0), material=mat)
    camera((0, 0, 5), (0, 0, 0), ortho_scale=2.0)
    scene.render.resolution_x, scene.render.resolution_y = count, 1
    configure_cycles(scene, 1, 0, 0)
    scene.cycles.filter_width = 0.01
    img = render_passes(scene)["Combined"][0, :, :3]
    return [[round(float(c), 7) for c in px] for px in img]


def main() -> None:
    import bpy
    rows = measure()
    with open(OUT, "w") as f:
        json.dump({"source": f"Blender {bpy.app.version_string}, Cycles rendering the Wavelength node",
                   "nanometres": list(range(LOW, HIGH + 1)), "rgb": rows}, f)
    print("wrote", OUT, len(rows), "rows")


if __name__ == "__main__":
    main()
