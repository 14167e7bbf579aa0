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


@pytest.mark.parametrize("integrator", [dict(integrator="PATH"), dict(integrator="PATH", sample_batch=4),
                                        dict(integrator="RESTIR", direct_method="RESTIR")])
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


@pytest.mark.parametrize("batch", [1, 4])
def test_occluder_shadow_is_the_light_it_blocks(batch):
    """Under the occluder (it hides the whole emitter from the floor's middle; a black world and max_bounces 0: only
    the emitter lights the floor) L_with = 0: the pass is 0 there, the transparent film's alpha 1, the opaque film's
    floor black; at the floor's corners, which see the whole emitter past the occluder, the pass stays 1 exactly."""
    scene = catcher_scene(occluder=True, world=0.0, width=64)  # the middle 2 x 2 pixels inside the umbra, |x| < 0.05
    p = render(scene, "PASS", sample_batch=batch)["Shadow Catcher"]
    h, w = p.shape[:2]
    mid = p[h // 2 - 1:h // 2 + 1, w // 2 - 1:w // 2 + 1]
    assert np.all(mid == 0.0)
    assert np.abs(p[:2, :2] - 1).max() < 1e-6
    t = render(scene, "TRANSPARENT", sample_batch=batch)["Combined"]
    assert np.allclose(t[h // 2 - 1:h // 2 + 1, w // 2 - 1:w // 2 + 1, 3], 1.0)
    o = render(scene, "OPAQUE", sample_batch=batch)["Combined"]
    assert np.allclose(o[h // 2 - 1:h // 2 + 1, w // 2 - 1:w // 2 + 1, :3], 0.0)
    assert 0.0 < p.mean() < 1.0


def test_a_batched_chunk_sums_each_pixels_samples():
    """A chunk of 3 samples of 4 pixels (pixel list repeated per sample), catchers met by some of its camera hits:
    each pixel's film sums are the sums over its own samples' catcher values, and its coverage the count of its
    samples that met a catcher (a scatter that dropped repeated pixels would keep one sample of each)."""
    from types import SimpleNamespace

    from restir_engine.core.parallel.tasks import Progress
    from restir_engine.core.pipeline.film import Film
    batch, n, w = 3, 4, 4
    pixels = np.tile(np.array([4, 5, 6, 7]), batch)  # the second row of a 4 x 2 film
    hit_rows = np.array([0, 1, 2, 4, 5, 6, 8, 9, 11])  # positions in the chunk's pixel list that met a surface
    catcher = np.array([0, 1, 3, 4, 6, 8])  # of those hits, the ones on a catcher
    rng = np.random.default_rng(5)
    values = {k: rng.random((3, len(catcher))).astype(np.float32) for k in ("sc_with", "sc_without", "sc_behind")}
    hits = SimpleNamespace(rows=hit_rows, emitted=np.zeros((3, batch * n), np.float32),
                           alpha=np.zeros(batch * n, np.float32), emitted_g=None, surf=None)
    c = SimpleNamespace(pixels=pixels, batch=batch, hits=hits, chain=None, direct=None, indirect=None, direct_g=None,
                        indirect_g=None, catcher=catcher, res=None, gi_res=None, **values)
    film = Film(w, 2, gi=False, denoise_data=False, catcher_mode="PASS")
    film.accumulate([c], False, np.eye(3, dtype=np.float32), Progress(None, None, 1))
    where = pixels[hit_rows[catcher]]
    for key, v in values.items():
        want = np.zeros((2 * w, 3))
        np.add.at(want, where, v.T)
        assert np.allclose(film.acc[key].reshape(-1, 3), want, atol=1e-6), key
    assert np.array_equal(film.acc["sc_cov"].reshape(-1), np.bincount(where, minlength=2 * w))
    film.release()
