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


# The spatial radius is not set here: the engine's automatic radius scales with the resolution.
METHODS = [
    Method("cycles", "Cycles (CPU, outside reference)", "CYCLES", {}, (1, 2, 4, 8, 16), (1, 2, 4, 8, 16, 32, 64, 128),
           "C7"),
    Method("path", "Path tracer (NEE + MIS)", "RESTIR", {"integrator": "PATH"}, (1, 2, 4, 8), (1, 2, 4, 8, 16, 32, 64),
           "C0"),
    Method("ris", "RIS (32 light + 1 BSDF candidates)", "RESTIR",
           {"integrator": "RESTIR", "direct_method": "RIS", "indirect_method": "PATH"}, (1, 2, 4), (1, 2, 4, 8, 16, 32), "C1"),
    Method("restir_spatial", "ReSTIR DI spatial only, unbiased", "RESTIR",
           {"integrator": "RESTIR", "direct_method": "RESTIR", "bias_correction": "UNBIASED",
            "temporal_reuse": False, "indirect_method": "PATH"}, (1, 2, 4), (1, 2, 4, 8, 16, 32), "C2"),
    Method("restir_temporal", "ReSTIR DI temporal only, unbiased", "RESTIR",
           {"integrator": "RESTIR", "direct_method": "RESTIR", "bias_correction": "UNBIASED",
            "spatial_neighbors": 0, "indirect_method": "PATH"}, (1, 2, 4), (1, 2, 4, 8, 16, 32), "C9"),
    Method("restir", "ReSTIR DI temporal + spatial, unbiased", "RESTIR",
           {"integrator": "RESTIR", "direct_method": "RESTIR", "bias_correction": "UNBIASED", "indirect_method": "PATH"},
           (1, 2, 4), (1, 2, 4, 8, 16, 32), "C4"),
    Method("restir_tuned", "ReSTIR DI unbiased, radius 10 px, 2 spatial passes", "RESTIR",
           {"integrator": "RESTIR", "direct_method": "RESTIR", "bias_correction": "UNBIASED", "spatial_radius": 10.0,
            "spatial_passes": 2, "indirect_method": "PATH"}, (1, 2, 4), (1, 2, 4, 8, 16, 32), "C6"),
    Method("restir_biased", "ReSTIR DI temporal + spatial, biased (1/M)", "RESTIR",
           {"integrator": "RESTIR", "direct_method": "RESTIR", "bias_correction": "NONE", "indirect_method": "PATH"},
           (1, 2, 4), (1, 2, 4, 8, 16, 32), "C3"),
    # candidate-count sweep (M_light) for ReSTIR DI temporal + spatial, unbiased
    *[Method(f"restir_m{m}", f"ReSTIR DI, M_light = {m}", "RESTIR",
             {"integrator": "RESTIR", "direct_method": "RESTIR", "bias_correction": "UNBIASED",
              "light_candidates": m, "indirect_method": "PATH"}, (1, 2), (1, 2, 4, 8, 16), colour)
      for m, colour in zip((1, 4, 16, 64), ("C5", "m", "C8", "k"))],
]

# ReSTIR GI (Auto direct light); each also in the biased mode and with one reuse alone
METHODS += [
    Method("gi", "ReSTIR GI temporal + spatial, unbiased", "RESTIR",
           {"integrator": "RESTIR", "direct_method": "AUTO", "indirect_method": "RESTIR_GI",
            "bias_correction": "UNBIASED"}, (1, 2, 4), (1, 2, 4, 8, 16, 32), "C5"),
    Method("gi_spatial", "ReSTIR GI spatial only, unbiased", "RESTIR",
           {"integrator": "RESTIR", "direct_method": "AUTO", "indirect_method": "RESTIR_GI",
            "bias_correction": "UNBIASED", "temporal_reuse": False}, (1, 2, 4), (1, 2, 4, 8, 16, 32), "m"),
    Method("gi_temporal", "ReSTIR GI temporal only, unbiased", "RESTIR",
           {"integrator": "RESTIR", "direct_method": "AUTO", "indirect_method": "RESTIR_GI",
            "bias_correction": "UNBIASED", "gi_spatial_neighbors": 0}, (1, 2, 4), (1, 2, 4, 8, 16, 32), "C8"),
    Method("gi_biased", "ReSTIR GI temporal + spatial, biased (1/M)", "RESTIR",
           {"integrator": "RESTIR", "direct_method": "AUTO", "indirect_method": "RESTIR_GI",
            "bias_correction": "NONE"}, (1, 2, 4), (1, 2, 4, 8, 16, 32), "k"),
]

# the default evaluation runs these; the sweep entries are picked with --methods
DEFAULT_KEYS = ("cycles", "path", "ris", "restir_spatial", "restir_temporal", "restir", "restir_biased", "gi",
                "gi_biased")


def by_key(keys=None):
    keys = DEFAULT_KEYS if keys is None else keys
    return [m for m in METHODS if m.key in keys]


def settings_for(method: Method, width: int) -> dict:
    """The scene.restir settings of ``method`` for an image ``width`` pixels wide (the spatial radius is the
    engine's automatic one, scaled with the resolution, unless the method sets it)."""
    return dict(method.settings)
