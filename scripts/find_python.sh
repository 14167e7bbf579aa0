#!/usr/bin/env bash
# Print the path of a working Python interpreter of version $1 (3.11 or 3.13): pythonX.Y on PATH, else the newest
# X.Y.* under pyenv's versions folder ($PYENV_ROOT, or ~/.pyenv). A candidate must run and report that version (a
# pyenv shim for a version that is not selected does not). Exit status 1 (and no output) when there is none.
set -euo pipefail
want=${1:?usage: find_python.sh 3.11|3.13}
works() {
  "$1" -c "import sys; sys.exit(0 if '%d.%d' % sys.version_info[:2] == '$want' else 1)" >/dev/null 2>&1
}
candidates=()
if command -v "python$want" >/dev/null 2>&1; then
  candidates+=("$(command -v "python$want")")
fi
root=${PYENV_ROOT:-$HOME/.pyenv}
for dir in $(ls -d "$root"/versions/"$want".* 2>/dev/null | sort -V -r); do
  candidates+=("$dir/bin/python$want")
done
for py in "${candidates[@]}"; do
  if [ -x "$py" ] && works "$py"; then
    echo "$py"
    exit 0
  fi
done
exit 1
