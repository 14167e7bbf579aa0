#!/usr/bin/env bash
# Run the test suite (headless, through the bpy module) on every supported Blender found here: Blender 5.2 LTS
# (Python 3.13, .venv313) when a Python 3.13 exists (PATH or pyenv's versions folder), and Blender 5.0
# (Python 3.11, .venv). Each venv is pinned and cached. Extra arguments go to pytest. Fails if either run fails.
set -euo pipefail
cd "$(dirname "$0")/.."
versions=()
if scripts/find_python.sh 3.13 >/dev/null; then
  versions+=(3.13)
else
  echo "Python 3.13 not found: Blender 5.2 LTS (bpy 5.2.3) is not tested here, only Blender 5.0 (Python 3.11)"
fi
versions+=(3.11)
status=0
for ver in "${versions[@]}"; do
  venv=$(scripts/setup_venv.sh "$ver")
  echo "== Python $ver, bpy $("$venv/bin/python" -c 'import importlib.metadata as m; print(m.version("bpy"))')"
  "$venv/bin/python" -m pytest -q tests "$@" || status=1
done
exit $status
