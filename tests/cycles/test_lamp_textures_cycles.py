"""Lamps coloured by node graphs that vary over them, against Cycles (same bpy, CPU): bpy_scenes.textured_lamp_scene,
a white floor seen from above lit by one lamp: a point lamp patterned by its Normal (Checker colour, Strength along
X), a spot projecting an image through its UV (a gobo), an area lamp coloured by its UV with a Checker of Object
coordinates as Strength, a turned and scaled point lamp with a Gradient of its Normal through a Color Ramp and its
UV as Strength, a point lamp coloured by an Object attribute (a property of the lamp object) through a Checker and
with a View Layer attribute as Strength. Direct light only (each floor pixel sees the pattern where the lamp shines on it).

Per 8 x 8 cells of 8 x 8 pixels and colour channel, from 4 seeds a side: a cell agrees when
|ours - Cycles| <= 5 SE + 0.5 % of Cycles + 1e-3 (as the node pattern tests); lit cells, with ours scaled by 1.03,
must fail somewhere (power). The path tracer and ReSTIR DI unbiased (the lamp's pattern in its target and shading).
Before, these lamps rendered with their sockets' own values (one flat colour) and a warning.

IES Texture (bpy_scenes.ies_lamp_scene): a point lamp whose Strength is an LM-63 profile (internal text, the
node's default vector), lopsided over 0-360°, a one-quadrant downlight Cycles mirrors, and the lopsided one on a
turned lamp; the same cells and bounds. Before, the node was unsupported (its socket value, a flat lamp).
"""
import numpy as np
import pytest
from bpy_scenes import IES_LAMPS, TEXTURED_LAMPS, ies_lamp_scene, textured_lamp_scene
from cycles_compare import cycles_reference, ours_cells
from stats import MARGIN, POWER_ERROR, Z_MAX

SIZE, CELL = (64, 64), 8
REPS = 4
FLOAT_TOL = 1e-3
RESTIR = dict(integrator="RESTIR", direct_method="RESTIR", bias_correction="UNBIASED", temporal_reuse=True,
              spatial_neighbors=5)
#: samples per seed: the area lamp is sampled by area (Cycles samples its solid angle), so it needs more
SAMPLES = {("PATH", "area"): 64, ("RESTIR", "area"): 16}


def cells(images):
    """(k, h, w, 3) -> (k, cells x 3 channels)."""
    a = np.asarray(images, np.float64)
    k, h, w, _ = a.shape
    return a.reshape(k, h // CELL, CELL, w // CELL, CELL, 3).mean(axis=(2, 4)).reshape(k, -1)


def within(ours, ref):
    ma, mb = ours.mean(axis=0), ref.mean(axis=0)
    se = np.sqrt(ours.var(axis=0, ddof=1) / len(ours) + ref.var(axis=0, ddof=1) / len(ref))
    return np.abs(ma - mb) <= Z_MAX * se + MARGIN * np.abs(mb) + FLOAT_TOL


def _compare(case, build, samples, settings):
    ours = ours_cells(build, 0, samples, cells, reps=REPS, **settings)
    ref = cycles_reference(case, build, 0, 64, cells, reps=REPS)
    return ours, ref


@pytest.mark.parametrize("method", ["PATH", "RESTIR"])
@pytest.mark.parametrize("kind", TEXTURED_LAMPS)
def test_textured_lamps_match_cycles(addon, kind, method):
    settings = {"integrator": "PATH"} if method == "PATH" else RESTIR
    samples = SAMPLES.get((method, kind), 16 if method == "PATH" else 4)
    ours, ref = _compare(f"lamp_texture_{kind}", lambda: textured_lamp_scene(kind, SIZE), samples, settings)
    _assert_agree(kind, ours, ref)


@pytest.mark.parametrize("method", ["PATH", "RESTIR"])
@pytest.mark.parametrize("kind", IES_LAMPS)
def test_ies_lamps_match_cycles(addon, kind, method):
    settings = {"integrator": "PATH"} if method == "PATH" else RESTIR
    ours, ref = _compare(f"lamp_ies_{kind}", lambda: ies_lamp_scene(kind, SIZE), 16 if method == "PATH" else 4,
                         settings)
    _assert_agree(f"IES {kind}", ours, ref)


def _assert_agree(kind, ours, ref):
    ok = within(ours, ref)
    worst = int(np.argmin(ok))
    assert ok.all(), (f"{kind}: {int((~ok).sum())} of {ok.size} cells disagree; cell {worst // 3} channel "
                      f"{worst % 3}: ours {ours.mean(0)[worst]:.4f} Cycles {ref.mean(0)[worst]:.4f}")
    lit = ref.mean(0) > 0.05
    assert lit.sum() >= 24
    assert not within(ours * (1 + POWER_ERROR), ref)[lit].all(), f"{kind}: cannot see a 3 % error"
