#!/usr/bin/env bash
# Render the Cycles side of the comparisons with Cycles again and store it (tests/data/cycles/bpy-<series>/), for
# every Blender the tests run on (scripts/test.sh's venvs): the comparison tests run with RESTIR_CYCLES_REFS=update,
# so our side is rendered and checked too. Extra arguments go to pytest (e.g. -k glass for some cases only).
set -euo pipefail
cd "$(dirname "$0")/.."
versions=()
if scripts/find_python.sh 3.13 >/dev/null; then versions+=(3.13); fi
versions+=(3.11)
status=0
for ver in "${versions[@]}"; do
  venv=$(scripts/setup_venv.sh "$ver")
  RESTIR_CYCLES_REFS=update "$venv/bin/python" -m pytest -q -m cycles tests "$@" || status=1
  # tests outside tests/cycles that compare with a stored Cycles image
  RESTIR_CYCLES_REFS=update "$venv/bin/python" -m pytest -q tests/blender/test_denoise.py "$@" || status=1
done
exit $status
