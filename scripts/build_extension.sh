#!/usr/bin/env bash
# Build installable Blender extension zips (one per platform) into dist/.
# Stages restir_engine/ with the root blender_manifest.toml (the source of truth) and the embreex
# wheels from PyPI, then runs Blender's own extension builder (blender_ext.py from the bpy wheel).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup_venv.sh
stage=dist/stage/restir_engine
rm -rf dist/stage && mkdir -p "$stage/wheels"
cp -r restir_engine/. "$stage/"
find "$stage" -name __pycache__ -prune -exec rm -rf {} +
cp blender_manifest.toml "$stage/"
for plat in manylinux_2_28_x86_64 win_amd64 macosx_13_0_arm64 macosx_13_0_x86_64; do
  .venv/bin/python -m pip download --quiet --disable-pip-version-check --no-deps --only-binary=:all: \
    --python-version 3.11 --platform "$plat" embreex==4.4.0.post1 -d "$stage/wheels"
done
ext=$(find .venv/lib/python3.11/site-packages/bpy -name blender_ext.py | head -1)
.venv/bin/python "$ext" build --source-dir "$stage" --output-dir dist --split-platforms
ls -1 dist/*.zip
