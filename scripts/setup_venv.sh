#!/usr/bin/env bash
# Create or reuse a pinned virtualenv (re-installed when its requirements change) and print its folder:
#   scripts/setup_venv.sh 3.11   -> .venv     from requirements.txt        (bpy 5.0.1, numpy 1.26.4)
#   scripts/setup_venv.sh 3.13   -> .venv313  from requirements-py313.txt  (bpy 5.2.3 LTS, numpy 2.x)
#   scripts/setup_venv.sh bpy45  -> .venv-bpy45 from requirements-bpy45.txt (bpy 4.5 LTS on Python 3.11: smoke test)
#   scripts/setup_venv.sh bpy42  -> .venv-bpy42 from requirements-bpy42.txt (bpy 4.2 LTS on Python 3.11: smoke test)
# The Python comes from scripts/find_python.sh ($PYTHON overrides it). Default: 3.11. The venv itself lives in
# $RESTIR_VENV_CACHE (default ~/.cache/restir_engine/venvs), one per requirements file content, linked here.
set -euo pipefail
cd "$(dirname "$0")/.."
ver=${1:-3.11}
case "$ver" in
  3.11) venv=.venv; req=requirements.txt ;;
  3.13) venv=.venv313; req=requirements-py313.txt ;;
  bpy45) venv=.venv-bpy45; req=requirements-bpy45.txt; ver=3.11 ;;
  bpy42) venv=.venv-bpy42; req=requirements-bpy42.txt; ver=3.11 ;;
  *) echo "setup_venv.sh: unknown version '$ver' (3.11, 3.13, bpy45 or bpy42)" >&2; exit 2 ;;
esac
want=$(sha256sum "$req" | cut -d' ' -f1)
fresh() { [ -x "$1/bin/python" ] && [ -f "$1/.requirements.sha256" ] && [ "$(cat "$1/.requirements.sha256")" = "$want" ]; }
if fresh "$venv"; then
  echo "$venv"
  exit 0
fi
# A venv is built once per requirements file content in the user's cache (outside the checkout, so a fresh clone
# reuses it) and linked here; where the cache cannot be written it is built here.
cache=${RESTIR_VENV_CACHE:-${XDG_CACHE_HOME:-$HOME/.cache}/restir_engine/venvs}
target=$venv
if mkdir -p "$cache" 2>/dev/null && [ -w "$cache" ]; then
  target=$cache/${venv#.}-${want:0:16}
fi
if ! fresh "$target"; then
  py=${PYTHON:-$(scripts/find_python.sh "$ver" || true)}
  if [ -z "$py" ]; then
    echo "setup_venv.sh: Python $ver not found (PATH or pyenv's versions folder)" >&2
    exit 1
  fi
  "$py" -c "import sys; sys.exit(0 if sys.version_info[:2] == tuple(map(int, '$ver'.split('.'))) else 'Python $ver is required')" >&2
  [ -x "$target/bin/python" ] || "$py" -m venv "$target" >&2
  "$target/bin/python" -m pip install --quiet --disable-pip-version-check -r "$req" >&2
  echo "$want" > "$target/.requirements.sha256"
fi
if [ "$target" != "$venv" ]; then
  rm -rf "$venv"
  ln -s "$target" "$venv"
fi
echo "$venv"
