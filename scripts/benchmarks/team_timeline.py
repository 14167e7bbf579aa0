"""Where a team of worker processes waits: read the events one multi-process run recorded (``scaling.py run
--timeline DIR``; restir_engine/core/parallel/timeline.py) and print, per steady frame (frames after the first) and
per worker, the time spent waiting at each barrier site and for the rendering process's next message, which site's
barrier each worker reached last (the one the team waited for), what the rendering process did between its messages,
and per barrier site how long the last arriver and the others spent off the CPU since the barrier before (wall minus
CPU time: waiting for a lock or a message, or not scheduled). Writes ``timeline.json`` beside the events.
Run: ``scripts/bench.py team_timeline FOLDER``.
"""
from __future__ import annotations

import argparse
import glob
import json
import os
from collections import defaultdict

import numpy as np


def _load(folder: str):
    main = json.load(open(os.path.join(folder, "main.json")))
    workers = {}
    for path in glob.glob(os.path.join(folder, "worker*.json")):
        workers[int(os.path.basename(path)[6:-5])] = json.load(open(path))
    return main, dict(sorted(workers.items()))


def _barriers(events, lo: float, hi: float) -> list:
    """(arrive, leave, site, wall, cpu) of each barrier passed within [lo, hi): ``wall`` and ``cpu`` the seconds
    from the barrier before (its leaving) to this one's arrival, by the clock and in this process's CPU time."""
    out, arrive, left = [], None, None
    for t, kind, label, cpu in events:
        if kind == "arrive":
            arrive = (t, label, cpu)
        elif kind == "leave" and arrive is not None:
            if lo <= arrive[0] < hi and left is not None:
                out.append((arrive[0], t, arrive[1], arrive[0] - left[0], arrive[2] - left[1]))
            arrive, left = None, (t, cpu)
    return out


def _message_waits(events, lo: float, hi: float) -> dict:
    """Seconds between a worker's reply and its next message within [lo, hi), by 'reply -> message' kinds."""
    waits, last = defaultdict(float), None
    for t, kind, label, _cpu in events:
        if kind == "sent":
            last = (t, label)
        elif kind == "recv" and last is not None:
            if lo <= last[0] and t < hi:
                waits[f"{last[1]} -> {label}"] += t - last[0]
            last = None
    return dict(waits)


def _main_gaps(events, lo: float, hi: float) -> dict:
    """The rendering process's seconds between its marks within [lo, hi): from each event to the next, named by
    both (answered X -> main Y -> ask Z)."""
    gaps = defaultdict(float)
    inside = [(t, k if k == "frame" else f"{k} {lab}".strip()) for t, k, lab, _cpu in events if lo <= t < hi]
    for (t0, a), (t1, b) in zip(inside, inside[1:]):
        if not a.startswith("ask"):  # from an ask to its answer the workers work
            gaps[f"{a} -> {b}"] += t1 - t0
    return dict(gaps)


def report(folder: str) -> dict:
    main, workers = _load(folder)
    frames = [e[0] for e in main if e[1] == "frame"]
    end = next(e[0] for e in main if e[1] == "end")
    lo = frames[1] if len(frames) > 1 else frames[0]
    steady = len(frames) - 1 if len(frames) > 1 else 1
    wall = (end - lo) / steady
    size = len(workers)
    per = {r: _barriers(ev, lo, end) for r, ev in workers.items()}
    n = min(len(b) for b in per.values())
    site_wait, site_count, last_at, spread = defaultdict(float), defaultdict(int), defaultdict(lambda: defaultdict(int)), \
        defaultdict(float)
    unscheduled = defaultdict(lambda: np.zeros(2))  # wall - cpu before the barrier: the last arriver's, the others' mean
    for k in range(n):
        arrivals = np.array([per[r][k][0] for r in workers])
        site = per[0][k][2]
        site_count[site] += 1
        spread[site] += arrivals.max() - arrivals.min()
        last = int(arrivals.argmax())
        last_at[site][list(workers)[last]] += 1
        lost = np.array([per[r][k][3] - per[r][k][4] for r in workers])
        unscheduled[site] += (lost[last], np.delete(lost, last).mean())
        for r in workers:
            site_wait[site] += per[r][k][1] - per[r][k][0]
    msg = defaultdict(float)
    for r, ev in workers.items():
        for key, v in _message_waits(ev, lo, end).items():
            msg[key] += v
    out = {
        "frame_s": wall, "workers": size, "barriers_per_frame": n / steady,
        "barrier_wait_per_worker_s": sum(site_wait.values()) / size / steady,
        "message_wait_per_worker_s": sum(msg.values()) / size / steady,
        "sites": {s: {"per_frame": site_count[s] / steady, "wait_per_worker_s": site_wait[s] / size / steady,
                      "mean_spread_s": spread[s] / site_count[s],
                      "last_not_computing_s": float(unscheduled[s][0] / site_count[s]),
                      "others_not_computing_s": float(unscheduled[s][1] / site_count[s]),
                      "last": dict(sorted(last_at[s].items(), key=lambda kv: -kv[1])[:4])}
                  for s in sorted(site_wait, key=lambda s: -site_wait[s])},
        "message_waits_per_worker_s": {k: v / size / steady for k, v in sorted(msg.items(), key=lambda kv: -kv[1])},
        "main_gaps_s": {k: v / steady for k, v in sorted(_main_gaps(main, lo, end).items(), key=lambda kv: -kv[1])},
    }
    with open(os.path.join(folder, "timeline.json"), "w") as fh:
        json.dump(out, fh, indent=1)
    print(f"{folder}: frame {wall:.3f} s, {size} workers, {out['barriers_per_frame']:.0f} barriers a frame; "
          f"a worker waits {out['barrier_wait_per_worker_s']:.3f} s at barriers and "
          f"{out['message_wait_per_worker_s']:.3f} s for messages a frame")
    for s, rec in list(out["sites"].items())[:12]:
        print(f"  {rec['wait_per_worker_s']:.3f} s  x{rec['per_frame']:.1f}  spread {rec['mean_spread_s'] * 1e3:6.1f} ms"
              f"  off-CPU last/others {rec['last_not_computing_s'] * 1e3:5.1f}/{rec['others_not_computing_s'] * 1e3:5.1f}"
              f" ms  last: {rec['last']}  {s}")
    for k, v in list(out["message_waits_per_worker_s"].items())[:6]:
        print(f"  message wait {v:.3f} s  {k}")
    for k, v in list(out["main_gaps_s"].items())[:10]:
        print(f"  rendering process {v:.3f} s  {k}")
    return out


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder", help="one run's events (a folder under scaling.py run --timeline DIR)")
    report(ap.parse_args(argv).folder)


if __name__ == "__main__":
    main()
