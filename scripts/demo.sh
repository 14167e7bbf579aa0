#!/usr/bin/env bash
# Build the built-in demo scene and render its first frames with the ReSTIR engine into out/, on Blender 5.2 LTS
# (Python 3.13) when a Python 3.13 is found, else on Blender 5.0 (Python 3.11).
set -euo pipefail
cd "$(dirname "$0")/.."
if scripts/find_python.sh 3.13 >/dev/null; then ver=3.13; else ver=3.11; fi
venv=$(scripts/setup_venv.sh "$ver")
echo "Rendering with Python $ver, bpy $("$venv/bin/python" -c 'import importlib.metadata as m; print(m.version("bpy"))')"
"$venv/bin/python" scripts/make_demo_scene.py --output out/demo.blend --frames 8
"$venv/bin/python" -m restir_engine out/demo.blend -o "$PWD/out/demo_####" -F PNG -s 1 -e "${DEMO_FRAMES:-3}" -a
echo "Images are in $PWD/out/ (demo_0001.png ...)"
