"""Writes restir_engine/core/lights/data/blackbody.json: Blender's blackbody colour (scene-linear Rec.709,
luminance 1, as a light's Temperature gives it, ``Light.temperature_color``) at log-spaced temperatures, the table
core/lights/blackbody.py interpolates for the Blackbody node and light temperatures. Run with a bpy Python:
    .venv313/bin/python scripts/make_blackbody_table.py"""
import json
import os

import bpy
import numpy as np

OUT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "restir_engine", "core", "lights",
                   "data", "blackbody.json")
temps = np.geomspace(800.0, 40000.0, 160)
light = bpy.data.lights.new("blackbody table", "POINT")
light.use_temperature = True
rows = []
for t in temps:
    light.temperature = float(t)
    rows.append([round(float(c), 6) for c in light.temperature_color])
bpy.data.lights.remove(light)
with open(OUT, "w") as f:
    json.dump({"source": f"Blender {bpy.app.version_string} Light.temperature_color", "kelvin": [round(float(t), 3)
               for t in temps], "rgb": rows}, f)
print("wrote", OUT)
