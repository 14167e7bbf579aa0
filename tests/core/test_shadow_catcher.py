"""Shadow catchers in the core (pipeline/shadow_catcher.py), against closed forms (no bpy; Cycles comparisons:
tests/cycles/test_shadow_catcher_cycles.py): a floor that is a shadow catcher under an emissive square, a small
occluder (not a catcher) between them, a grey world behind the view's edge."""
import numpy as np
import pytest
from scenes_core import concat, quad, top_down_camera, tris

from restir_engine.core.renderer import RenderSettings, render_frame
from restir_engine.core.scene import Lamps, MaterialTable, ObjectTable, Scene

WORLD = 0.25


def catcher_scene(occluder: bool = True, width: int = 32, world: float = WORLD) -> Scene:
    """Floor (instance 0, the catcher, 2 x 2) at z = 0 seen from above; the emitter (instance 1) at z = 1 facing
    down, 0.5 x 0.5; with ``occluder`` a 0.3 x 0.3 quad (instance 2) at z = 0.5 over the middle."""
    mats = MaterialTable.build([{"base_color": (0.5, 0.5, 0.5), "f0": 0.0},
                                {"base_color": (0, 0, 0), "f0": 0.0, "emission": (4.0,) * 3,
                                 "two_sided_emission": False}])
    parts = [tris(quad((0, 0, 0), (1, 0, 0), (0, 1, 0)), 0), tris(quad((0, 0, 1), (0, 0.25, 0), (0.25, 0, 0)), 1)]
    if occluder:
        parts.append(tris(quad((0, 0, 0.5), (0.15, 0, 0), (0, 0.15, 0)), 0))
    geom = concat(parts)
    geom.instance = np.repeat(np.arange(len(parts), dtype=np.int32), 2)
    k = len(parts)
    geom.objects = ObjectTable(world_to_object=np.tile(np.eye(4)[:3], (k, 1, 1)), texspace_lo=np.zeros((k, 3)),
                               texspace_size=np.ones((k, 3)), location=np.zeros((k, 3)), color=np.ones((k, 4)),
                               random=np.zeros(k), shadow_catcher=np.arange(k) == 0)
    cam = top_down_camera(width, width, height_above=0.3, half_extent=1.4)  # the floor's edge in view: the world
    return Scene(geom, mats, Lamps.empty(), cam, world_radiance=np.full(3, world, np.float32))


def render(scene, mode, **st):
    settings = RenderSettings(samples=8, max_bounces=0, film_transparent=mode == "TRANSPARENT",
                              shadow_catcher_pass=mode == "PASS", **st)
    return render_frame(scene, settings).passes


@pytest.mark.parametrize("integrator", [dict(integrator="PATH"), dict(integrator="RESTIR", direct_method="RESTIR")])
def test_no_occluder_means_no_shadow_exactly(integrator):
    """With nothing but catchers the two estimates share their random numbers and agree sample by sample: the
    Shadow Catcher pass is exactly 1, Combined is the matte (black and transparent over the floor), the transparent
    film's alpha 0 there, and the opaque film shows the world where the floor is."""
    scene = catcher_scene(occluder=False)
    p = render(scene, "PASS", **integrator)
    floor = p["Combined"][..., 3] == 0
    assert 0.3 < floor.mean() < 1  # the floor and the world beyond its edge
    assert np.allclose(p["Shadow Catcher"], 1.0, atol=1e-6)
    assert np.all(p["Combined"][floor] == 0)
    t = render(scene, "TRANSPARENT", **integrator)["Combined"]
    assert np.abs(t[floor]).max() < 1e-6
    o = render(scene, "OPAQUE", **integrator)["Combined"]
    assert np.allclose(o[..., :3], WORLD, atol=1e-5) and np.allclose(o[..., 3], 1.0)


def test_occluder_shadow_is_the_light_it_blocks():
    """Under the occluder (it hides the whole emitter from the floor's middle; a black world and max_bounces 0: only
    the emitter lights the floor) L_with = 0: the pass is 0 there, the transparent film's alpha 1, the opaque film's
    floor black; at the floor's corners, which see the whole emitter past the occluder, the pass stays 1 exactly."""
    scene = catcher_scene(occluder=True, world=0.0)
    p = render(scene, "PASS")["Shadow Catcher"]
    h, w = p.shape[:2]
    mid = p[h // 2 - 1:h // 2 + 1, w // 2 - 1:w // 2 + 1]
    assert np.all(mid == 0.0)
    assert np.abs(p[:2, :2] - 1).max() < 1e-6
    t = render(scene, "TRANSPARENT")["Combined"]
    assert np.allclose(t[h // 2 - 1:h // 2 + 1, w // 2 - 1:w // 2 + 1, 3], 1.0)
    o = render(scene, "OPAQUE")["Combined"]
    assert np.allclose(o[h // 2 - 1:h // 2 + 1, w // 2 - 1:w // 2 + 1, :3], 0.0)
    assert 0.0 < p.mean() < 1.0
