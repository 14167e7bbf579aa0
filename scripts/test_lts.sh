#!/usr/bin/env bash
# Smoke test on the older Blender LTS releases the manifest names (blender_version_min 4.2.0): for each of
# bpy 4.2 LTS and 4.5 LTS (Python 3.11; pinned venvs .venv-bpy42 / .venv-bpy45, created on first use, about
# 400 MB each) tests/lts_smoke.py registers the add-on, renders the demo with F12 (finite passes), renders with
# the CLI (-a and -f, each must exit) and installs the built extension. Fails if any check fails.
set -euo pipefail
cd "$(dirname "$0")/.."
status=0
for lts in bpy42 bpy45; do
  venv=$(scripts/setup_venv.sh "$lts")
  start=$SECONDS
  rc=0
  timeout 900 "$venv/bin/python" tests/lts_smoke.py > "$venv/smoke.log" 2>&1 || rc=$?
  grep -E '^(ok  |FAIL|bpy |[0-9]+ of [0-9]+ checks)' "$venv/smoke.log" || true
  echo "== $lts smoke: exit $rc after $((SECONDS - start)) s"
  [ "$rc" -eq 0 ] || { tail -40 "$venv/smoke.log"; status=1; }
done
exit $status
