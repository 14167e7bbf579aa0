"""The methods every chart compares. Adding a method or an option is one entry in METHODS.

Each Method renders at the sample counts of its ladder; every (method, samples) pair is one point
of relMSE versus time. ``settings`` are written to ``scene.restir`` (ignored for Cycles).
"""
from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class Method:
    key: str
    label: str
    engine: str  # "RESTIR" (this add-on) or "CYCLES"
    settings: dict = field(default_factory=dict)
    ladder_quick: tuple = (1, 2, 4, 8)
    ladder_full: tuple = (1, 2, 4, 8, 16, 32, 64)
    color: str = "C0"


METHODS = [
    Method("cycles", "Cycles (CPU, outside reference)", "CYCLES", {}, (1, 2, 4, 8, 16), (1, 2, 4, 8, 16, 32, 64, 128),
           "C7"),
    Method("path", "Path tracer (NEE + MIS)", "RESTIR", {"integrator": "PATH"}, (1, 2, 4, 8), (1, 2, 4, 8, 16, 32, 64),
           "C0"),
]


def by_key(keys=None):
    return [m for m in METHODS if keys is None or m.key in keys]
