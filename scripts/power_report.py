"""How much precision each comparison with a reference has beyond what its power check needs.

Run the statistical tests with ``RESTIR_POWER_LOG=FILE`` (tests/stats.py appends a record per comparison), then
``python scripts/power_report.py FILE``: per test, the worst power cell's relative standard error of the difference
as a share of what the check allows (``use``: 1.0 is the edge), and ``cut``, the factor by which our side's variance
per repetition may grow (fewer samples) before that cell reaches ``--target`` of the allowance, with the reference
side as stored. A cut below 1 means the test has less headroom than the target.

The other half of the check: ``RESTIR_SCALE_OURS=1.03`` scales our side of every comparison (tests/stats.py) by a
3 % error, and each comparison with a reference must then fail:
    RESTIR_SCALE_OURS=1.03 .venv313/bin/python -m pytest -q tests/cycles   # every test fails
"""
from __future__ import annotations

import argparse
import json
from collections import defaultdict

import numpy as np

GROWTH = 1.03 ** 2  # the power check scales our side by 1 + 3 %


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log")
    parser.add_argument("--target", type=float, default=0.8, help="share of the allowed SE to keep (default 0.8)")
    args = parser.parse_args()
    worst: dict = defaultdict(lambda: (0.0, np.inf))
    for line in open(args.log):
        r = json.loads(line)
        if not r["var_ours"]:  # a comparison without power cells
            continue
        vo = np.asarray(r["var_ours"]) * GROWTH / r["n_ours"]
        vr = np.asarray(r["var_ref"]) / r["n_ref"]
        use = float(np.sqrt(vo + vr).max() / r["limit"])
        cut = float(np.min((args.target ** 2 * r["limit"] ** 2 - vr) / np.maximum(vo, 1e-30)))
        u, c = worst[r["test"]]
        worst[r["test"]] = (max(u, use), min(c, cut))
    for test, (use, cut) in sorted(worst.items(), key=lambda kv: -kv[1][1]):
        print(f"{use:6.2f} {cut:7.2f}  {test}")


if __name__ == "__main__":
    main()
