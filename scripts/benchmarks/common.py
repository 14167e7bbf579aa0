"""What every benchmark case shares: the repository's paths (``scripts/bench.py`` puts the repository, scripts/ and
tests/ on sys.path before a case is imported) and the JSON writer of their results."""
from __future__ import annotations

import json
import os

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
RESULTS = os.path.join(ROOT, "docs", "results")


def write_json(path: str, data, indent: int = 1) -> None:
    """Write ``data`` as JSON to ``path`` (its folder made if missing), ending with a newline."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w") as f:
        json.dump(data, f, indent=indent)
        f.write("\n")
