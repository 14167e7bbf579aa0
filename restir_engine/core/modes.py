"""The enumerated settings of a render, one StrEnum each: a member equals its string, so settings may hold either
(the Blender glue passes the enum items' identifiers, which are these values)."""
from __future__ import annotations

from enum import StrEnum


class Integrator(StrEnum):
    PATH = "PATH"  # the reference path tracer
    RESTIR = "RESTIR"  # resampled direct light (DirectMethod) and indirect light (IndirectMethod)


class DirectMethod(StrEnum):
    AUTO = "AUTO"  # chosen per frame (integrators/method_choice.py)
    LIGHT_SAMPLING = "LIGHT_SAMPLING"  # one light sample and one BSDF sample, MIS
    RIS = "RIS"  # resampled importance sampling of many candidates
    RESTIR = "RESTIR"  # RIS with temporal and spatial reuse


class IndirectMethod(StrEnum):
    AUTO = "AUTO"  # ReSTIR GI or path tracing, measured (pipeline/indirect_choice.py)
    OFF = "OFF"  # no bounces
    PATH = "PATH"  # path-traced bounces
    RESTIR_GI = "RESTIR_GI"  # resampled first bounce with reuse


class WorldMethod(StrEnum):
    AUTO = "AUTO"
    RESAMPLED = "RESAMPLED"  # the world's points in the DI reservoirs
    LIGHT_SAMPLED = "LIGHT_SAMPLED"  # one world light sample beside the reservoirs


class LightTiles(StrEnum):
    AUTO = "AUTO"
    ON = "ON"
    OFF = "OFF"


class LightSampler(StrEnum):
    SPATIAL = "SPATIAL"  # per-block tiles by power over distance (lights/blocks.py)
    POWER = "POWER"  # tiles by power alone (lights/tiles.py)


class BiasCorrection(StrEnum):
    NONE = "NONE"  # 1/M
    UNBIASED = "UNBIASED"  # pairwise MIS


def values(mode) -> tuple[str, ...]:
    """The mode's values as plain strings, in declaration order."""
    return tuple(m.value for m in mode)
