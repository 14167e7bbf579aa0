#!/usr/bin/env bash
# Build installable Blender extension zips (one per platform) into dist/, for Blender 4.2 to 5.2 LTS: the embreex
# wheels for Python 3.11 (Blender 4.2-5.0) and 3.13 (Blender 5.1+) of every platform are bundled.
# Stages restir_engine/ with the root blender_manifest.toml (the source of truth) and the wheels, then runs
# Blender's own extension builder (blender_ext.py from the bpy wheel of the newest venv found).
# Wheels are taken from the cache folder $WHEEL_CACHE (default .cache/wheels); missing ones are downloaded with pip,
# and without a network the build stops, naming what is missing.
set -euo pipefail
cd "$(dirname "$0")/.."
if scripts/find_python.sh 3.13 >/dev/null; then ver=3.13; else ver=3.11; fi
venv=$(scripts/setup_venv.sh "$ver")
cache=${WHEEL_CACHE:-.cache/wheels}
mkdir -p "$cache"
stage=dist/stage/restir_engine
mkdir -p dist
if command -v flock >/dev/null; then  # one build at a time (the test suites of both Pythons may run at once)
  exec 9>dist/.build.lock
  flock 9
fi
rm -rf dist/stage && mkdir -p "$stage/wheels"
cp -r restir_engine/. "$stage/"
find "$stage" -name __pycache__ -prune -exec rm -rf {} +
cp blender_manifest.toml "$stage/"
# every wheel the manifest lists: from the cache, else downloaded into it (platform and Python from its name)
for whl in $(grep -o 'embreex-[^"]*\.whl' blender_manifest.toml); do
  if [ ! -f "$cache/$whl" ]; then
    IFS=- read -r _name version tag _abi plat <<< "${whl%.whl}"
    py="${tag:2:1}.${tag:3}"
    "$venv/bin/python" -m pip download --quiet --disable-pip-version-check --no-deps --only-binary=:all: \
      --python-version "$py" --platform "${plat##*.}" "embreex==$version" -d "$cache" >&2 || true
    [ -f "$cache/$whl" ] || { echo "build_extension.sh: $whl is neither in $cache nor downloadable" >&2; exit 1; }
  fi
  cp "$cache/$whl" "$stage/wheels/"
done
ext=$(find "$venv"/lib/python*/site-packages/bpy -name blender_ext.py | head -1)
"$venv/bin/python" "$ext" build --source-dir "$stage" --output-dir dist --split-platforms
ls -1 dist/*.zip
