"""Light group passes against Cycles' (same bpy, CPU): a Cornell box whose emissive ceiling quad is in group
"ceiling" and a blue point lamp in group "fill" (View Layer > Light Groups), each group's "Combined_<group>" pass
per image cell against Cycles' (stored reference, tests/cycles_reference.py) with the bound of the materials tests
(5 SE + 0.5 %), the path tracer and ReSTIR DI + GI unbiased; the cells each lamp lights able to see a 3 % error."""
import numpy as np
import pytest
from bpy_scenes import configure_cycles, configure_restir, cornell_box, light, render_passes
from cycles_compare import REPS
from cycles_reference import cycles_cells
from stats import assert_cells_match, cell_means, image_cells

import bpy

SIZE = (48, 48)
GROUPS = ("ceiling", "fill")


def grouped_box():
    scene = cornell_box("EMISSIVE", SIZE)
    layer = scene.view_layers[0]
    for name in GROUPS:
        layer.lightgroups.add(name=name)
    bpy.data.objects["Lamp"].lightgroup = "ceiling"
    light("POINT", (0.4, 0.0, 0.6), energy=20.0, color=(0.3, 0.5, 1.0), shadow_soft_size=0.1).lightgroup = "fill"
    return scene


def groups_side_by_side(scene) -> np.ndarray:
    """(h, 2w, 3): the groups' passes next to each other."""
    passes = render_passes(scene)
    return np.concatenate([passes[f"Combined_{g}"][..., :3] for g in GROUPS], axis=1)


CELLS = image_cells((2 * SIZE[0], SIZE[1]), 2)  # top and bottom halves: cells 0, 2 the ceiling's pass, 1, 3 the fill's


def reduce(images):
    return cell_means(np.asarray(images), CELLS)


@pytest.mark.parametrize("method", ["PATH", "RESTIR"])
def test_light_group_passes_match_cycles(addon, method):
    ref = cycles_cells("light_groups", grouped_box, lambda sc, seed: configure_cycles(sc, 64, 2, seed),
                       groups_side_by_side, reduce, REPS, 64, 2)
    settings = dict(integrator="PATH") if method == "PATH" else \
        dict(integrator="RESTIR", direct_method="RESTIR", indirect_method="RESTIR_GI", bias_correction="UNBIASED")
    scene, images = grouped_box(), []
    for seed in range(REPS):
        configure_restir(scene, 32 if method == "PATH" else 64, 2, seed, **settings)
        images.append(groups_side_by_side(scene))
    names = [f"{GROUPS[k % 2]} {('top', 'bottom')[k // 2]}" for k in range(4)]
    assert_cells_match(reduce(images), ref, names, power=range(4))
