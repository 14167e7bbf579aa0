"""Worker processes (core/parallel/processes.py): a frame rendered by N processes is the frame one process renders,
bit for bit (each chunk and span keeps its own random stream whoever computes it, and each pixel's film sum is
added in the same order), for stills, animation frames with temporal history, every integrator and reuse stage;
a stop request ends every worker's pass; a worker that dies gives one error and leaves no process and no
shared-memory segment behind."""
import dataclasses
import os
import signal
import time

import numpy as np
import pytest
from scenes_core import regression_room

from restir_engine.core.parallel import processes
from restir_engine.core.parallel.processes import WorkerFailed
from restir_engine.core.pipeline.shared_frame import SharedHistory
from restir_engine.core.renderer import Cancelled, RenderSettings, render_frame

SIZE = (96, 72)
TILE = 1024  # pixels per chunk: 7 chunks, shared unevenly by 2 or 3 workers

SETTINGS = {
    "path-batched": RenderSettings(integrator="PATH", samples=3, max_bounces=2, tile_pixels=TILE, sample_batch=2),
    "ris-light-tiles": RenderSettings(integrator="RESTIR", direct_method="RIS", samples=2, max_bounces=1,
                                      tile_pixels=TILE, light_tiles="ON", light_sampler="SPATIAL"),
    "restir-di-unbiased": RenderSettings(integrator="RESTIR", direct_method="RESTIR", samples=2, max_bounces=1,
                                         tile_pixels=TILE, bias_correction="UNBIASED"),
    "restir-di-boiling": RenderSettings(integrator="RESTIR", direct_method="RESTIR", samples=1, max_bounces=0,
                                        tile_pixels=TILE, bias_correction="NONE", boiling_filter=True,
                                        boiling_threshold=1.5),
    "di-gi-unbiased": RenderSettings(integrator="RESTIR", direct_method="RESTIR", indirect_method="RESTIR_GI",
                                     samples=2, max_bounces=2, tile_pixels=TILE, bias_correction="UNBIASED",
                                     denoise_data=True),
    "auto": RenderSettings(integrator="RESTIR", direct_method="AUTO", indirect_method="AUTO", samples=2,
                           max_bounces=2, tile_pixels=TILE),
}


def _frames(settings, n):
    """Two frames of the room (the second with the first's history); passes of both, and the second's stats."""
    scene = regression_room(*SIZE)
    first = render_frame(scene, settings, processes=n)
    second = render_frame(scene, dataclasses.replace(settings, frame=2), history=first.history, processes=n)
    return first.passes, second.passes, second.stats


@pytest.fixture(scope="module", autouse=True)
def _end_teams():
    yield
    processes.shutdown()


@pytest.mark.parametrize("name", list(SETTINGS))
def test_processes_render_the_image_one_process_renders(name):
    settings = SETTINGS[name]
    alone = _frames(settings, 1)
    for n in (2, 3):
        team = _frames(settings, n)
        assert team[2]["processes"] == n
        for frame in (0, 1):
            assert set(team[frame]) == set(alone[frame])
            for key, image in alone[frame].items():
                assert np.array_equal(image, team[frame][key]), (name, n, frame, key)
    if settings.integrator == "RESTIR" and settings.direct_method == "RESTIR":
        assert team[2]["reuse"]["temporal_accepted"] > 0.5  # the history crossed frames in the workers


def test_the_split_matters_to_the_test():
    """Power: a change of the random streams (another seed) or of one chunk's work is seen by the comparison."""
    settings = SETTINGS["restir-di-unbiased"]
    a = _frames(settings, 1)[1]["Combined"]
    b = _frames(dataclasses.replace(settings, seed=1), 3)[1]["Combined"]
    assert not np.array_equal(a, b)


def test_a_team_is_started_once_and_kept():
    settings = SETTINGS["path-batched"]
    scene = regression_room(*SIZE)
    render_frame(scene, settings, processes=2)
    team = processes.team(2)
    t0 = time.perf_counter()
    render_frame(scene, settings, processes=2)
    assert processes.team(2) is team and team.alive()
    assert time.perf_counter() - t0 < 30


def test_histories_of_the_other_kind_are_not_reused():
    settings = SETTINGS["restir-di-unbiased"]
    scene = regression_room(*SIZE)
    shared = render_frame(scene, settings, processes=2)
    assert isinstance(shared.history, SharedHistory)
    fresh = render_frame(scene, dataclasses.replace(settings, frame=2), processes=1)
    handed = render_frame(scene, dataclasses.replace(settings, frame=2), history=shared.history, processes=1)
    assert np.array_equal(fresh.passes["Combined"], handed.passes["Combined"])
    alone = render_frame(scene, settings, processes=1)
    back = render_frame(scene, dataclasses.replace(settings, frame=2), history=alone.history, processes=2)
    assert np.array_equal(fresh.passes["Combined"], back.passes["Combined"])


def test_a_stop_keeps_the_finished_passes_and_the_team_goes_on():
    settings = dataclasses.replace(SETTINGS["restir-di-unbiased"], samples=4)
    scene = regression_room(*SIZE)
    calls = {"passes": 0}

    def progress(fraction, label):
        calls["passes"] = int(label.split()[1].split("/")[0])  # "Sample k/n": pass k is about to render

    result = render_frame(scene, settings, progress=progress, should_stop=lambda: calls["passes"] >= 2,
                          processes=3)
    assert result.cancelled and result.samples_done == 1
    one = render_frame(scene, dataclasses.replace(settings, samples=1), processes=1)
    assert np.array_equal(result.passes["Combined"], one.passes["Combined"])
    with pytest.raises(Cancelled):
        render_frame(scene, settings, should_stop=lambda: True, processes=3)
    again = render_frame(scene, dataclasses.replace(settings, samples=1), processes=3)  # the team still works
    assert np.array_equal(again.passes["Combined"], one.passes["Combined"])


STILLS = {  # stills whose passes after the first render one per worker (pipeline/spread.py)
    "path": RenderSettings(integrator="PATH", samples=7, max_bounces=2, tile_pixels=TILE),
    "path-batched": RenderSettings(integrator="PATH", samples=9, max_bounces=1, tile_pixels=TILE, sample_batch=2),
    "restir-di-light-tiles": RenderSettings(integrator="RESTIR", direct_method="RESTIR", samples=5, max_bounces=1,
                                            tile_pixels=TILE, bias_correction="UNBIASED", light_tiles="ON",
                                            denoise_data=True),
    "di-gi": RenderSettings(integrator="RESTIR", direct_method="RESTIR", indirect_method="RESTIR_GI", samples=5,
                            max_bounces=2, tile_pixels=TILE),
    "auto": RenderSettings(integrator="RESTIR", direct_method="AUTO", indirect_method="AUTO", samples=5,
                           max_bounces=2, tile_pixels=TILE),
    # adaptive sampling: checks after samples 16 and 32 stop pixels; the passes between them render one per worker
    "adaptive": RenderSettings(integrator="PATH", samples=40, max_bounces=1, tile_pixels=TILE,
                               use_adaptive_sampling=True, adaptive_threshold=0.05, adaptive_min_samples=2),
}


@pytest.mark.parametrize("name", list(STILLS))
def test_passes_rendered_one_per_worker_give_the_image_one_process_renders(name):
    """A still's passes after the first go whole to the workers in turn, at the same time; each pixel's samples
    still reach the film in sample order, so the image is the one process's, bit for bit (any other order of the
    float32 sums changes the last bits of most pixels)."""
    settings = STILLS[name]
    scene = regression_room(*SIZE)
    alone = render_frame(scene, settings, processes=1)
    for n in (2, 3):
        team = render_frame(scene, settings, processes=n)
        assert team.stats["passes_one_per_process"] >= n, (name, n, team.stats["passes_one_per_process"])
        assert team.samples_done == alone.samples_done == settings.samples
        for key, image in alone.passes.items():
            assert np.array_equal(image, team.passes[key]), (name, n, key)
        for key in ("gi_skipped_passes", "boiling_dropped", "light_tiles", "indirect_method", "direct_method"):
            assert team.stats[key] == alone.stats[key], (name, n, key)


def test_the_order_of_the_film_sums_matters_to_the_test():
    """Power: the same passes added to the film in another order (pass 2 before pass 1) give another image."""
    from restir_engine.core.parallel.team import Solo
    from restir_engine.core.pipeline.frame import FrameRenderer
    settings = dataclasses.replace(STILLS["path"], samples=3)
    scene = regression_room(*SIZE)
    in_order = render_frame(scene, settings, processes=1).passes["Combined"]
    fr = FrameRenderer(scene, settings, keep_history=False)
    assert fr.sample_pass() and fr.passes_independent()
    for sample in (2, 1):
        assert fr.independent_pass(sample, 1, Solo())
    fr.film.samples = 3
    swapped = fr.passes()["Combined"]
    assert np.allclose(swapped, in_order, rtol=1e-5, atol=1e-6) and not np.array_equal(swapped, in_order)


def test_passes_that_change_the_next_one_are_not_rendered_one_per_worker():
    """Auto indirect measures every ReSTIR GI pass and motion blur poses each pass from the last: their passes are
    shared out pass by pass; adaptive sampling's check passes too (spread.samples_at_once)."""
    from restir_engine.core.pipeline.frame import FrameRenderer
    from restir_engine.core.pipeline.spread import samples_at_once
    scene = regression_room(*SIZE)
    fr = FrameRenderer(scene, dataclasses.replace(STILLS["auto"], direct_method="RESTIR"), keep_history=False)
    assert not fr.passes_independent()  # before the first pass
    assert fr.sample_pass() and fr.gi_auto
    for method, independent in (("RESTIR_GI", False), ("PATH", True)):  # what Auto chose after the first pass
        fr.indirect.method = method
        assert fr.passes_independent() == independent
    blurred = FrameRenderer(scene, STILLS["path"], keep_history=False)
    assert blurred.sample_pass() and blurred.passes_independent()
    blurred.blur = object()  # a scene whose objects move in the shutter
    assert not blurred.passes_independent()
    assert samples_at_once(39, 1, 1, None) == 39
    assert samples_at_once(39, 1, 1, 16) == 14  # samples 1..14; sample 15 (the 16th) renders with the check
    assert samples_at_once(39, 1, 4, 16) == 12  # whole passes of 4 that end before the check's pass
    assert samples_at_once(39, 17, 1, 16) == 0


def test_a_stop_among_passes_rendered_one_per_worker_keeps_the_first_ones():
    """Stopped while the workers render passes one each: the film holds the passes committed before the stop (always
    the first ones, each whole), so the image is one process's image of that many samples."""
    settings = dataclasses.replace(STILLS["restir-di-light-tiles"], samples=40)
    scene = regression_room(*SIZE)
    seen = {}

    def progress(fraction, label):
        seen["k"] = int(label.split()[1].split("/")[0])

    result = render_frame(scene, settings, progress=progress, should_stop=lambda: seen.get("k", 0) >= 6,
                          processes=3)
    assert result.cancelled and 1 <= result.samples_done < settings.samples
    one = render_frame(scene, dataclasses.replace(settings, samples=result.samples_done), processes=1)
    for key, image in one.passes.items():
        assert np.array_equal(image, result.passes[key]), key
    again = render_frame(scene, STILLS["path"], processes=3)  # the team goes on
    assert again.stats["passes_one_per_process"] > 0 and not again.cancelled


def _segments(team):
    return [s.name for s in team.slot_segs + ([team.film_seg] if team.film_seg is not None else [])]


@pytest.mark.skipif(not os.path.isdir("/dev/shm"), reason="shared-memory segments are listed in /dev/shm here")
@pytest.mark.parametrize("samples", [3, 7])  # 7: killed while the workers render passes one each (others wait for
def test_a_worker_dying_in_a_render_ends_the_team_with_one_error_and_nothing_left_behind(samples):  # its turn)
    settings = dataclasses.replace(SETTINGS["restir-di-unbiased"], samples=samples)
    scene = regression_room(*SIZE)
    render_frame(scene, settings, processes=3)
    team = processes.team(3)
    names = _segments(team)
    assert names and all(os.path.exists(f"/dev/shm/{n.lstrip('/')}") for n in names)

    killed = []

    def kill_in_pass_two(fraction, label):
        if label.startswith("Sample 2/") and not killed:
            os.kill(team.procs[1].pid, signal.SIGKILL)
            killed.append(True)

    with pytest.raises(WorkerFailed, match=r"render worker process 1 \(pid \d+\) ended unexpectedly"):
        render_frame(scene, settings, progress=kill_in_pass_two, processes=3)
    assert not any(p.is_alive() for p in team.procs)
    assert not any(os.path.exists(f"/dev/shm/{n.lstrip('/')}") for n in names)
    after = render_frame(scene, settings, processes=3)  # the next render starts a new team
    assert processes.team(3) is not team
    assert np.array_equal(after.passes["Combined"], render_frame(scene, settings, processes=1).passes["Combined"])


@pytest.mark.skipif(not os.path.isdir("/dev/shm"), reason="shared-memory segments are listed in /dev/shm here")
def test_a_worker_dead_before_a_message_is_sent_gives_the_same_one_error():
    """A worker killed just before the next pass is sent (its pipe already closed): the send itself fails, and that
    is the same WorkerFailed, with no process or segment left (it was a BrokenPipeError once, in CI)."""
    settings = dataclasses.replace(SETTINGS["restir-di-unbiased"], samples=3)
    scene = regression_room(*SIZE)
    render_frame(scene, settings, processes=3)
    team = processes.team(3)
    names = _segments(team)
    killed = []

    def kill_before_pass_two(fraction, label):
        if label.startswith("Sample 2/") and not killed:
            os.kill(team.procs[1].pid, signal.SIGKILL)
            team.procs[1].join(5.0)  # dead, and its end of the pipe closed, before the pass is sent
            killed.append(True)

    with pytest.raises(WorkerFailed, match=r"render worker process 1 \(pid \d+\) ended unexpectedly"):
        render_frame(scene, settings, progress=kill_before_pass_two, processes=3)
    assert killed and not any(p.is_alive() for p in team.procs)
    assert not any(os.path.exists(f"/dev/shm/{n.lstrip('/')}") for n in names)


def test_a_worker_that_died_between_renders_is_replaced():
    settings = SETTINGS["path-batched"]
    scene = regression_room(*SIZE)
    render_frame(scene, settings, processes=2)
    team = processes.team(2)
    os.kill(team.procs[0].pid, signal.SIGKILL)
    team.procs[0].join(5)
    result = render_frame(scene, settings, processes=2)
    assert processes.team(2) is not team and not any(p.is_alive() for p in team.procs)
    assert np.array_equal(result.passes["Combined"], render_frame(scene, settings, processes=1).passes["Combined"])


def test_auto_uses_processes_from_two_cores_and_at_most_one_per_chunk():
    assert processes.split(2, 0) == (2, 1)
    assert processes.split(16, 0) == (16, 1)
    assert processes.split(16, 4) == (4, 4)
    assert processes.split(1, 0) == (1, 1)
    assert processes.split(16, 0, chunks=8) == (8, 2)
    processes.set_process_count(0)
    try:
        assert processes.process_count(16, 8) == 8 and processes.process_count(1, 8) == 1
    finally:
        processes.set_process_count(None)
    assert processes.process_count(16, 8) == 1  # not set: the rendering process alone


def test_chunks_go_to_the_least_loaded_process_by_their_measured_costs():
    from restir_engine.core.parallel.team import SEGMENTS, assign
    assert list(assign(5, 2, None)) == [0, 1, 0, 1, 0]  # nothing measured: round-robin
    cost = np.zeros((SEGMENTS, 6))
    cost[0] = [8, 1, 1, 1, 1, 4]  # one heavy chunk: the others share the rest
    owner = assign(6, 2, cost)
    loads = [cost[0][owner == m].sum() for m in (0, 1)]
    assert max(loads) == 8 and list(assign(6, 2, cost)) == list(owner)  # balanced as well as can be, and stable
    cost[1] = [0, 0, 0, 0, 0, 12]  # a second segment: chunk 5 is heavy there, so chunk 0 goes elsewhere
    owner = assign(6, 2, cost)
    assert owner[0] != owner[5]


def test_a_process_count_that_would_not_fit_in_memory_is_lowered_with_a_message(monkeypatch):
    from restir_engine.core.pipeline import memory
    settings = SETTINGS["path-batched"]
    scene = regression_room(*SIZE)
    estimate = memory.frame_estimate(scene, settings)
    each = memory.WORKER_FIXED + memory.BVH_PER_TRIANGLE * len(scene.geometry) + memory.WORKER_PER_PIXEL * estimate.pixels
    monkeypatch.setattr(memory, "available_memory", lambda: estimate.high + 2 * each + 1)  # room for 2 workers
    result = render_frame(scene, settings, processes=3)
    assert result.stats["processes"] == 2
    assert "3 render processes would not fit in memory" in result.stats["processes_note"]
    assert "rendering with 2" in result.stats["processes_note"]
    monkeypatch.setattr(memory, "available_memory", lambda: estimate.high + 1)  # no room for any: this process
    alone = render_frame(scene, settings, processes=3)
    assert "processes" not in alone.stats and "rendering with 1" in alone.stats["processes_note"]
    assert np.array_equal(alone.passes["Combined"], result.passes["Combined"])


def test_esc_stops_every_worker_within_half_a_second():
    """A stop asked half-way through the second pass of a 64-sample ReSTIR DI + GI frame (320x240, 2 processes of
    its 2 chunks): the render returns within 0.5 s with the first pass, and every worker is free for the next."""
    scene = regression_room(320, 240)
    settings = RenderSettings(integrator="RESTIR", direct_method="RESTIR", indirect_method="RESTIR_GI", samples=64,
                              max_bounces=4)
    render_frame(scene, dataclasses.replace(settings, samples=1), processes=2)  # the team started
    asked = {}

    def progress(fraction, _label):
        if fraction > 1.5 / 64 and "t" not in asked:
            asked["t"] = time.perf_counter()

    result = render_frame(scene, settings, progress=progress, should_stop=lambda: "t" in asked, processes=2)
    latency = time.perf_counter() - asked["t"]
    assert result.cancelled and result.samples_done == 1 and result.stats["processes"] == 2
    assert latency < 0.5, f"stopped {latency:.2f} s after the request"
    assert processes.team(2).alive()


def test_workers_that_cannot_start_leave_the_render_to_this_process_with_a_message(monkeypatch):
    """A worker whose core fails to import (as where no Python can be spawned, or shared memory is missing): the
    frame renders in this process, the stats say why, and later frames do not try again."""
    processes.shutdown()
    monkeypatch.setattr(processes, "_DISABLED", None)
    monkeypatch.setattr(processes, "CORE_DIR", "/nonexistent/restir_core")
    settings = SETTINGS["path-batched"]
    scene = regression_room(*SIZE)
    result = render_frame(scene, settings, processes=2)
    assert "processes" not in result.stats
    assert "render worker processes could not start" in result.stats["processes_note"]
    assert processes._TEAM is None and processes._DISABLED
    assert np.array_equal(result.passes["Combined"], render_frame(scene, settings, processes=1).passes["Combined"])
    t0 = time.perf_counter()
    again = render_frame(scene, settings, processes=2)
    assert "could not start" in again.stats["processes_note"] and time.perf_counter() - t0 < 10


def _anisotropic_sheen_room(width, height):
    """The regression room with an anisotropic floor (aspect 0.4, the radial tangent turned by 0.1) and sheen walls
    (roughness 0.5): the target terms' extension rows (restir/target.py) cross frames and processes."""
    scene = regression_room(width, height)
    mats = scene.materials
    mats.aniso_aspect = mats.aniso_aspect.copy()
    mats.aniso_aspect[0] = 0.4
    mats.aniso_rotation = mats.aniso_rotation.copy()
    mats.aniso_rotation[0] = 0.1
    mats.sheen_roughness = mats.sheen_roughness.copy()
    mats.sheen_roughness[1] = 0.5
    return scene


def test_anisotropic_and_sheen_frames_render_the_same_in_processes():
    """ReSTIR DI + GI (unbiased) over two frames with history on anisotropic and sheen materials: finite, and 2
    processes render what one renders, bit for bit."""
    _two_frames_agree_in_processes(lambda: _anisotropic_sheen_room(*SIZE))


@pytest.mark.slow_case  # long: dealt out between the Blenders in CI (tests/conftest.py)
def test_subsurface_frames_render_the_same_in_processes():
    """ReSTIR DI + GI (unbiased) over two frames with history where the walls scatter beneath their surface
    (core/integrators/subsurface.py: one walk per camera hit, on the chunk's own random stream): finite, and 2
    processes render what one renders, bit for bit."""
    from restir_engine.core.integrators.subsurface import WALK_VAN_DE_HULST

    def build():
        scene = regression_room(*SIZE)
        mats = scene.materials
        mats.subsurface = np.float32([0, 1, 0, 0, 0, 0])
        mats.sss_radius = np.tile(np.float32([0.3, 0.1, 0.05]), (6, 1))
        mats.sss_method = np.full(6, WALK_VAN_DE_HULST, np.int32)
        return scene
    _two_frames_agree_in_processes(build)


def _two_frames_agree_in_processes(build):
    """ReSTIR DI + GI (unbiased), two frames with history of ``build()`` in 1 and in 2 processes: finite, equal bit
    for bit, and unlike the plain regression room's first frame (the scene's materials changed the image)."""
    settings = SETTINGS["di-gi-unbiased"]
    images = []
    for n in (1, 2):
        scene = build()
        first = render_frame(scene, settings, processes=n)
        second = render_frame(scene, dataclasses.replace(settings, frame=2), history=first.history, processes=n)
        images.append((first.passes["Combined"], second.passes["Combined"]))
    for frame in (0, 1):
        assert np.isfinite(images[0][frame]).all()
        assert np.array_equal(images[0][frame], images[1][frame])
    plain = render_frame(regression_room(*SIZE), settings, processes=1).passes["Combined"]
    assert not np.array_equal(plain, images[0][0])


# -- the viewport's renderer on worker processes (pipeline/shared_view.py) ----------------------------------------
def _moved(camera, k, divider=1):
    """The camera moved k steps sideways, at 1/divider of its resolution (a viewport navigation step)."""
    m = camera.cam_to_world.copy()
    m[:3, 3] += 0.02 * k * m[:3, 0]
    w, h = camera.width // divider, camera.height // divider
    return dataclasses.replace(camera, cam_to_world=m, width=w, height=h, window=(0, 0, w, h))


def _view_session(make, scene, settings, edited):
    """What the viewport does to its renderer, in order: passes, moves at other resolutions (the navigation
    candidate cap, a batch of refinement samples), a pass stopped before it kept anything, an edit that carries the
    history into a new renderer. Returns every pass's images (Combined, DI M and GI M, data passes at the end)."""
    from restir_engine.core.scene import Motion
    full = scene.camera
    out = []
    r = make(scene, settings, None)

    def shot():
        out.append((r.samples_done, r.combined().copy(), r.mean("res_m").copy(), r.mean("gi_m").copy()))

    def move(cam, frame):
        prev = r.camera
        r.move_camera(cam, frame)
        mats = np.zeros((0, 4, 4))
        r.set_motion(Motion(current=mats, prev=mats, next=mats, camera_prev=dataclasses.replace(
            prev, width=cam.width, height=cam.height, window=cam.window)))

    assert r.sample_pass(batch=1)
    shot()
    move(_moved(full, 1, 2), 2)
    assert r.reuses_history()
    assert r.sample_pass(batch=1, light_candidate_cap=8)
    shot()
    move(_moved(full, 2, 1), 3)
    assert not r.sample_pass(should_stop=lambda: True, batch=1)  # stopped before it kept a history
    move(_moved(full, 3, 1), 4)  # reprojects the half-resolution view's history
    assert r.sample_pass(batch=1)
    shot()
    assert r.sample_pass(batch=r.batch_size(2))
    shot()
    r = make(edited, settings, r)  # an edit: the newest history goes on into the new renderer
    move(_moved(full, 4, 1), 5)
    assert r.sample_pass(batch=1)
    shot()
    out.append(tuple(a.copy() for a in r.data_passes()))
    r.release()
    return out


def test_the_viewport_renders_the_same_views_on_processes_as_in_one():
    from restir_engine.core.pipeline.shared_view import SharedViewRenderer
    from restir_engine.core.renderer import FrameRenderer
    settings = dataclasses.replace(SETTINGS["di-gi-unbiased"], samples=64, frame=1)
    scene = regression_room(*SIZE)
    edited = regression_room(*SIZE)
    edited.materials.base_color[0] = (0.2, 0.5, 0.8)  # the floor re-coloured
    assert not np.array_equal(edited.materials.base_color, scene.materials.base_color)

    def alone(sc, st, old):
        fr = FrameRenderer(dataclasses.replace(sc, camera=scene.camera) if old else sc, st)
        if old is not None:
            fr.adopt_history(old.latest_history())
            old.release()
        return fr

    team = processes.borrow(2)

    def shared(sc, st, old):
        out = SharedViewRenderer(team, dataclasses.replace(sc, camera=scene.camera) if old else sc, st,
                                 SIZE[0] * SIZE[1], carry=old is not None)
        if old is not None:
            old.release()
        return out

    try:
        a = _view_session(alone, regression_room(*SIZE), settings, edited)
        b = _view_session(shared, regression_room(*SIZE), settings, edited)
    finally:
        processes.give_back(team)
    assert len(a) == len(b) == 6
    for i, (x, y) in enumerate(zip(a, b)):
        if i < 5:
            assert x[0] == y[0]
        for u, v in zip(x[1:] if i < 5 else x, y[1:] if i < 5 else y):
            assert np.array_equal(u, v), i
    assert processes.borrow(2) is team  # given back, kept idle, lent again
    processes.give_back(team)


def test_how_many_passes_render_one_per_worker():
    """Whole rounds of one pass per worker, and a last partial round only where it keeps 3/4 of them busy (else
    its passes are shared out: one pass alone on a worker takes the time the team takes for several)."""
    from restir_engine.core.pipeline.spread import passes_at_once
    assert passes_at_once(15, 1, 16) == 15  # the demo's F12 after its first pass: one round, one worker idle
    assert passes_at_once(17, 1, 16) == 16  # the 17th pass is shared out
    assert passes_at_once(10, 1, 16) == 0
    assert passes_at_once(15, 1, 2) == 14
    assert passes_at_once(13, 2, 3) == 6  # 7 passes of 2 samples (the last of 1)
    assert passes_at_once(1, 1, 2) == 0


def test_passes_one_per_worker_only_where_their_working_sets_fit():
    from restir_engine.core.pipeline.spread import fits, working_set
    scene = regression_room(*SIZE)
    st = STILLS["di-gi"]
    each = working_set(scene, st, "RESTIR", True)
    assert each > working_set(scene, st, "LIGHT_SAMPLING", False) > 0
    assert fits(scene, st, "RESTIR", True, 4, free=None)
    assert fits(scene, st, "RESTIR", True, 4, free=8 * each)
    assert not fits(scene, st, "RESTIR", True, 4, free=4 * each)
