#!/usr/bin/env bash
# Print the path of a Python interpreter of version $1 (3.11 or 3.13): pythonX.Y on PATH, else the newest
# X.Y.* under pyenv's versions folder ($PYENV_ROOT, or ~/.pyenv). Exit status 1 (and no output) when there is none.
set -euo pipefail
want=${1:?usage: find_python.sh 3.11|3.13}
if command -v "python$want" >/dev/null 2>&1; then
  command -v "python$want"
  exit 0
fi
root=${PYENV_ROOT:-$HOME/.pyenv}
for dir in $(ls -d "$root"/versions/"$want".* 2>/dev/null | sort -V -r); do
  if [ -x "$dir/bin/python$want" ]; then
    echo "$dir/bin/python$want"
    exit 0
  fi
done
exit 1
