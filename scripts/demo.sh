#!/usr/bin/env bash
# Build the built-in demo scene and render its first frames with the ReSTIR engine into out/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup_venv.sh
.venv/bin/python scripts/make_demo_scene.py --output out/demo.blend --frames 8
.venv/bin/python -m restir_engine out/demo.blend -o "$PWD/out/demo_####" -F PNG -s 1 -e "${DEMO_FRAMES:-3}" -a
echo "Images are in $PWD/out/ (demo_0001.png ...)"
