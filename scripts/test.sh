#!/usr/bin/env bash
# Run the test suite (headless, through the bpy module) on every supported Blender found here: Blender 5.2 LTS
# (Python 3.13, .venv313) when a Python 3.13 exists (PATH or pyenv's versions folder), and Blender 5.0
# (Python 3.11, .venv). Each venv is pinned and cached. The two suites run at the same time (each is mostly one
# interpreter's work; together they use the cores); their outputs are printed one after the other. Every test runs
# on both, except the slow suite (-m slow: the comparisons with Cycles and the long convergence tests): it is dealt
# out between them (pytest --slow-shard, tests/conftest.dealt), so each runs once, on one Blender, at its full
# power; RESTIR_SLOW_SHARDS=off runs it whole on both. Extra arguments go to pytest (e.g. -m "not slow",
# -m cycles; then the whole suite runs on both). Then the smoke test on Blender 4.2 LTS and 4.5 LTS
# (scripts/test_lts.sh; skipped when pytest arguments are given). Fails if any run fails.
set -euo pipefail
cd "$(dirname "$0")/.."
versions=()
if scripts/find_python.sh 3.13 >/dev/null; then
  versions+=(3.13)
else
  echo "Python 3.13 not found: Blender 5.2 LTS (bpy 5.2.3) is not tested here, only Blender 5.0 (Python 3.11)"
fi
versions+=(3.11)
venvs=()
for ver in "${versions[@]}"; do
  venvs+=("$(scripts/setup_venv.sh "$ver")")  # one at a time: the first set-up downloads
done
# the suites run at once: each renders with its share of the cores (tests/conftest.py, harness configure_restir),
# not with every core as Blender's Auto would (two suites of worker processes and thread pools on the same cores
# spend their time switching between each other)
if [ -z "${RESTIR_TEST_THREADS:-}" ]; then
  cores=$(getconf _NPROCESSORS_ONLN 2>/dev/null || echo 2)
  export RESTIR_TEST_THREADS=$(( cores / ${#versions[@]} > 0 ? cores / ${#versions[@]} : 1 ))
fi
# numpy's BLAS likewise (its threads spin while they wait, against the other suite's work; the core's worker
# processes set theirs to 1 themselves)
export OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-$RESTIR_TEST_THREADS} OMP_NUM_THREADS=${OMP_NUM_THREADS:-$RESTIR_TEST_THREADS}
logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT
pids=()
for i in "${!versions[@]}"; do
  venv=${venvs[$i]}
  share=()
  if [ "$#" -eq 0 ] && [ "${RESTIR_SLOW_SHARDS:-on}" != off ] && [ "${#versions[@]}" -gt 1 ]; then
    share=(--slow-shard "$i/${#versions[@]}")
  fi
  ( echo "== Python ${versions[$i]}, bpy $("$venv/bin/python" -c 'import importlib.metadata as m; print(m.version("bpy"))')"
    start=$SECONDS
    rc=0
    "$venv/bin/python" -m pytest -q -p no:cacheprovider --durations=15 ${share[@]+"${share[@]}"} tests "$@" || rc=$?
    echo "== Python ${versions[$i]}: exit $rc after $((SECONDS - start)) s"
    exit $rc ) > "$logs/$i.log" 2>&1 &
  pids+=($!)
done
status=0
for i in "${!versions[@]}"; do
  wait "${pids[$i]}" || status=1
  cat "$logs/$i.log"
done
if [ "$#" -eq 0 ]; then
  scripts/test_lts.sh || status=1
fi
exit $status
