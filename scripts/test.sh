#!/usr/bin/env bash
# Run the test suite (headless, through the bpy module) in the pinned .venv.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup_venv.sh
exec .venv/bin/python -m pytest -q tests "$@"
