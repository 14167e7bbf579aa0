"""Light groups (core/lights/groups.py): each group's pass holds the light its lamps, emitters and world sent to the
camera by every path, so the passes split Combined exactly, and each one converges to the image of its lights alone
(no bpy here; tests/cycles/test_light_groups_cycles.py compares the passes with Cycles')."""
import copy

import numpy as np
import pytest
from scenes_core import regression_room
from stats import welch_se

from restir_engine.core.lights.groups import LightGroups
from restir_engine.core.renderer import RenderSettings, render_frame

PANEL, STRIP, TINY = 3, 4, 5  # regression_room's emissive materials
NAMES = ("panel", "strips", "sky")

METHODS = {"path tracer": dict(integrator="PATH"),
           "ReSTIR DI unbiased": dict(integrator="RESTIR", direct_method="RESTIR", bias_correction="UNBIASED",
                                      indirect_method="PATH"),
           "RIS": dict(integrator="RESTIR", direct_method="RIS", indirect_method="PATH"),
           "ReSTIR DI + GI unbiased": dict(integrator="RESTIR", direct_method="RESTIR", bias_correction="UNBIASED",
                                           indirect_method="RESTIR_GI")}


def grouped_room():
    """regression_room with its textured ceiling panel and the sun in "panel", the blue strip and the tiny bright
    light in "strips", the world in "sky"."""
    scene = regression_room()
    mat = scene.materials.emission[scene.geometry.material]
    group = np.full(len(scene.geometry), -1, np.int16)
    group[scene.geometry.material == PANEL] = 0
    group[np.isin(scene.geometry.material, (STRIP, TINY))] = 1
    assert (np.abs(mat).sum(axis=1)[group < 0] == 0).all()  # every emitter has a group
    scene.light_groups = LightGroups(NAMES, tri_group=group, world_group=2)
    scene.lamps.sun_group = np.zeros(len(scene.lamps.sun_dir), np.int16)
    return scene


def panel_alone():
    """regression_room lit by the panel and the sun only (the strips dark, a black world)."""
    scene = copy.deepcopy(regression_room())
    scene.materials.emission[[STRIP, TINY]] = 0.0
    scene.world_radiance = np.zeros(3, np.float32)
    return scene


@pytest.mark.parametrize("method", list(METHODS))
def test_group_passes_split_combined_exactly(method):
    """Over two frames (the second reusing the first's history) the groups' passes add up to Combined to float
    rounding (every light is in a group), and Combined is bit for bit the image rendered without groups."""
    grouped, plain = grouped_room(), regression_room()
    hist = {True: None, False: None}
    for frame in (0, 1):
        out = {}
        for with_groups, scene in ((True, grouped), (False, plain)):
            st = RenderSettings(samples=2, max_bounces=2, frame=frame, temporal_reuse=True, **METHODS[method])
            r = render_frame(scene, st, history=hist[with_groups])
            hist[with_groups], out[with_groups] = r.history, r.passes
        p = out[True]
        total = sum(p[f"Combined_{n}"] for n in NAMES)
        assert all(p[f"Combined_{n}"].shape == p["Combined"].shape[:2] + (3,) for n in NAMES)
        assert np.abs(total - p["Combined"][..., :3]).max() <= 1e-5 * max(1.0, float(p["Combined"].max()))
        assert np.array_equal(p["Combined"], out[False]["Combined"])
        assert min(p[f"Combined_{n}"].mean() for n in NAMES) > 0.01  # each group lights the room


@pytest.mark.slow_case  # statistical: dealt out between the Blenders in CI (tests/conftest.py)
@pytest.mark.parametrize("method", ["path tracer", "ReSTIR DI + GI unbiased"])
def test_group_pass_converges_to_its_lights_alone(method):
    """The "panel" pass (emission seen, direct and bounce light of the panel and the sun) against the room rendered
    with only those lights: image means over 8 seeds each within 5 standard errors, each side precise enough to see
    a 3 % error. Attributing a contribution to the wrong group fails it."""
    st = dict(samples=16, max_bounces=2, **METHODS[method])
    grouped, alone = grouped_room(), panel_alone()
    a = [render_frame(grouped, RenderSettings(seed=s, **st)).passes["Combined_panel"].mean() for s in range(8)]
    b = [render_frame(alone, RenderSettings(seed=100 + s, **st)).passes["Combined"][..., :3].mean()
         for s in range(8)]
    se = welch_se(a, b)
    assert se < 0.006 * np.mean(b), se / np.mean(b)
    assert abs(np.mean(a) - np.mean(b)) < 5 * se, (np.mean(a), np.mean(b), se)


def test_light_groups_with_worker_processes_match_one_process():
    """Two worker processes render the same group passes as one (shared film accumulators per group)."""
    st = RenderSettings(samples=2, max_bounces=2, **METHODS["ReSTIR DI + GI unbiased"])
    one = render_frame(grouped_room(), st, processes=1).passes
    two = render_frame(grouped_room(), st, processes=2).passes
    for name in ("Combined",) + tuple(f"Combined_{n}" for n in NAMES):
        assert np.array_equal(one[name], two[name]), name
