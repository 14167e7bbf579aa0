"""Objects that move between frames update the last trace context (integrators/context_update.py) instead of a
rebuild: the result equals a context built from scratch (derived arrays, boxes, light table, nearest hits, images),
the still triangles' Embree scene is reused while the same objects move, and a change that is not a move (or too
large a one) rebuilds."""
import dataclasses

import numpy as np
import pytest
from scenes_core import perspective_camera, quad

from restir_engine.core.geometry.accel import Accel, SplitAccel
from restir_engine.core.integrators import context_cache
from restir_engine.core.integrators.trace_context import build_context
from restir_engine.core.renderer import RenderSettings, render_frame
from restir_engine.core.scene import Lamps, MaterialTable, Scene, TriangleSet

ST = dict(samples=2, max_bounces=2, seed=5)


def _box(center, half):
    c = np.asarray(center, np.float32)
    h = np.float32(half)
    faces = [quad(c + (0, 0, h), (h, 0, 0), (0, h, 0)), quad(c - (0, 0, h), (0, h, 0), (h, 0, 0)),
             quad(c + (h, 0, 0), (0, h, 0), (0, 0, h)), quad(c - (h, 0, 0), (0, 0, h), (0, h, 0)),
             quad(c + (0, h, 0), (0, 0, h), (h, 0, 0)), quad(c - (0, h, 0), (h, 0, 0), (0, 0, h))]
    return np.concatenate(faces)


def _scene(offsets=None, boxes=12):
    """A floor of 800 triangles (instance 0), ``boxes`` small boxes (instances 1..) and a ceiling emitter (the last
    instance), seen in perspective; ``offsets`` {instance: (dx, dy, dz)} moves instances."""
    offsets = offsets or {}
    cells = (np.arange(20) - 9.5) * 0.4  # a 20 x 20 floor: 800 triangles, so that a box is 1.5 % of the scene
    parts = [np.concatenate([quad((x, y, 0), (0.2, 0, 0), (0, 0.2, 0)) for x in cells for y in cells])]
    parts += [_box(((i % 4) - 1.5, (i // 4) - 1.0, 0.3), 0.25) for i in range(boxes)]
    parts.append(quad((0, 0, 2.5), (0, 0.6, 0), (0.6, 0, 0)))
    inst = np.concatenate([np.full(len(p), k, np.int32) for k, p in enumerate(parts)])
    verts = np.concatenate(parts).astype(np.float32)
    for k, d in offsets.items():
        verts[inst == k] += np.asarray(d, np.float32)
    ng = np.cross(verts[:, 1] - verts[:, 0], verts[:, 2] - verts[:, 0])
    ng /= np.linalg.norm(ng, axis=1)[:, None]
    material = np.where(inst == len(parts) - 1, 2, np.where(inst == 0, 0, 1)).astype(np.int32)
    geom = TriangleSet(verts, np.repeat(ng[:, None], 3, axis=1).astype(np.float32), material, instance=inst)
    mats = MaterialTable.build([{"base_color": (0.6, 0.6, 0.6), "f0": 0.04},
                                {"base_color": (0.7, 0.3, 0.2), "f0": 0.04},
                                {"base_color": (0, 0, 0), "f0": 0.0, "emission": (6.0, 6.0, 6.0)}])
    cam = perspective_camera((0.0, -5.0, 3.5), (0.0, 0.0, 0.3), 40, 30)
    return Scene(geom, mats, Lamps.empty(), cam)


def _ctx(scene):
    return context_cache.context_for(scene, 2, False, build_context)[0]


def _same_context(a, b):
    da, db = a.geom_derived, b.geom_derived
    for name in ("ng", "ng_rows", "flat", "normal_rows", "box_ids"):
        assert np.array_equal(getattr(da, name), getattr(db, name)), name
    for x, y in zip(da.boxes + da.bounds, db.boxes + db.bounds):
        assert np.array_equal(x, y)
    assert np.array_equal(a.lights.tri_verts, b.lights.tri_verts) and np.array_equal(a.lights.power, b.lights.power)
    rng = np.random.default_rng(1)
    o = rng.uniform(-3, 3, (3, 20000)).astype(np.float32)
    o[2] = rng.uniform(0.05, 2.4, 20000)
    target = rng.uniform((-2.2, -1.6, 0.0), (2.2, 1.6, 0.7), (20000, 3)).T  # toward the boxes
    d = (target - o).astype(np.float32)
    ha, hb = a.geom_accel.intersect(o, d), b.geom_accel.intersect(o, d)
    assert (ha.prim >= 0).mean() > 0.5 and (ha.prim > 1).mean() > 0.1
    assert np.array_equal(ha.prim, hb.prim)
    np.testing.assert_allclose(ha.t[ha.prim >= 0], hb.t[hb.prim >= 0], rtol=1e-6)
    tmax = np.full(20000, 2.0, np.float32)
    assert np.array_equal(a.geom_accel.occluded(o, d, tmax), b.geom_accel.occluded(o, d, tmax))


def test_a_moved_object_updates_the_context_as_a_rebuild_would():
    context_cache.clear()
    _ctx(_scene())
    moved = _scene({3: (0.4, 0.1, 0.0)})
    ctx = _ctx(moved)
    assert isinstance(ctx.geom_accel, SplitAccel) and len(ctx.geom_accel.moving_rows) == 12  # one box
    _same_context(ctx, build_context(moved, 2))
    still = ctx.geom_accel.still
    again = _scene({3: (0.8, 0.3, 0.1)})  # the same box moves on: its Embree scene alone is rebuilt
    ctx2 = _ctx(again)
    assert ctx2.geom_accel.still is still
    _same_context(ctx2, build_context(again, 2))
    other = _scene({3: (0.8, 0.3, 0.1), 6: (0.0, 0.0, 0.5)})  # another box moves too: it joins the moving set
    ctx3 = _ctx(other)
    assert len(ctx3.geom_accel.moving_rows) == 24 and ctx3.geom_accel.still is not still
    _same_context(ctx3, build_context(other, 2))


def test_a_moved_emitter_and_grown_bounds_rebuild_the_light_table():
    context_cache.clear()
    first = _ctx(_scene())
    moved = _scene({13: (0.5, 0.0, 0.0)})  # the ceiling emitter
    ctx = _ctx(moved)
    assert isinstance(ctx.geom_accel, SplitAccel) and ctx.lights is not first.lights
    _same_context(ctx, build_context(moved, 2))
    far = _scene({13: (0.5, 0.0, 0.0), 2: (0.0, 0.0, 6.0)})  # a box rises above everything: the bounds grow
    ctx2 = _ctx(far)
    assert ctx2.lights is not ctx.lights and ctx2.lights.scene_radius > ctx.lights.scene_radius
    _same_context(ctx2, build_context(far, 2))


@pytest.mark.parametrize("integrator", ["PATH", "RESTIR"])
def test_an_updated_context_renders_the_image_of_a_rebuilt_one(integrator):
    """Frames 1 and 2 (a box moved) rendered in sequence (frame 2 on the updated context, with the history of
    frame 1) equal frame 2 rendered after frame 1 on a context built from scratch, bit for bit."""
    st = RenderSettings(integrator=integrator, **ST)
    images = []
    for incremental in (True, False):
        context_cache.clear()
        r1 = render_frame(_scene(), st)
        if not incremental:
            context_cache.clear()
        r2 = render_frame(_scene({5: (0.3, -0.2, 0.0)}), dataclasses.replace(st, frame=2), history=r1.history)
        assert isinstance(context_cache._LAST.ctx.geom_accel, SplitAccel) == incremental
        images.append(r2.passes["Combined"])
    assert np.array_equal(images[0], images[1])
    # power: the moved box changes the image
    context_cache.clear()
    unmoved = render_frame(_scene(), dataclasses.replace(st, frame=2)).passes["Combined"]
    assert not np.array_equal(unmoved, images[0])


def test_other_changes_rebuild():
    context_cache.clear()
    _ctx(_scene())
    most = _scene({k: (0.1, 0.0, 0.0) for k in range(1, 13)} | {0: (0, 0, 0.01)})  # everything moved
    assert type(_ctx(most).geom_accel) is Accel
    fewer = _scene(boxes=11)  # a box deleted: another layout
    assert type(_ctx(fewer).geom_accel) is Accel
    recoloured = _scene(boxes=11)
    recoloured.geometry.material[:800] = 1  # the floor's material changed
    assert type(_ctx(recoloured).geom_accel) is Accel


def test_worker_processes_update_their_contexts_the_same_way():
    """Three frames (a box moving on) rendered in two worker processes, whose contexts are updated in each worker,
    give the images of one process bit for bit."""
    st = RenderSettings(integrator="RESTIR", tile_pixels=256, **ST)
    images = {}
    for processes in (1, 2):
        context_cache.clear()
        hist, out = None, []
        for frame in range(3):
            r = render_frame(_scene({5: (0.2 * frame, 0.0, 0.0)}), dataclasses.replace(st, frame=frame + 1),
                             history=hist, processes=processes)
            hist = r.history
            out.append(r.passes["Combined"])
        images[processes] = out
    for a, b in zip(images[1], images[2]):
        assert np.array_equal(a, b)
