"""The engine inside Blender: passes, their conventions (checked against Cycles), border, alpha."""

import bpy
import numpy as np
import pytest
from bpy_scenes import configure_cycles, configure_restir, cornell_box, render_passes
from stats import welch_se


@pytest.fixture
def box(addon):
    scene = cornell_box("EMISSIVE", (40, 30))
    vl = scene.view_layers[0]
    vl.use_pass_z = vl.use_pass_normal = True
    vl.restir.use_pass_direct = vl.restir.use_pass_indirect = vl.restir.use_pass_emission = True
    return scene


def interior(depth: np.ndarray) -> np.ndarray:
    """Pixels whose 4 neighbours lie on the same surface (depth within 5 cm): away from silhouettes,
    where a pixel-centre ray may fall either side of an edge."""
    d = np.pad(depth, 1, mode="edge")
    c = d[1:-1, 1:-1]
    same = np.all([np.abs(n - c) < 0.05 for n in (d[:-2, 1:-1], d[2:, 1:-1], d[1:-1, :-2], d[1:-1, 2:])], axis=0)
    return same & (depth < 1e9)


def test_all_passes_written_finite_and_consistent(box):
    configure_restir(box, 4, 2)
    p = render_passes(box)
    assert set(p) >= {"Combined", "Depth", "Normal", "Direct", "Indirect", "Emission"}
    for name, img in p.items():
        assert img.shape[:2] == (30, 40), name
        assert np.isfinite(img).all(), name
    assert np.allclose(p["Combined"][..., :3], p["Emission"] + p["Direct"] + p["Indirect"], atol=1e-4)
    assert p["Indirect"].mean() > 0 and p["Direct"].mean() > 0
    assert np.allclose(p["Combined"][..., 3], 1.0)


def test_rows_are_bottom_up_floor_below_ceiling(box):
    configure_restir(box, 1, 0)
    n = render_passes(box)["Normal"]
    assert np.allclose(n[0, 20], [0, 0, 1], atol=1e-3)    # bottom row, middle: the floor
    assert np.allclose(n[-1, 20], [0, 0, -1], atol=1e-3)  # top row, middle: the ceiling


def test_depth_and_normal_follow_cycles_conventions(box):
    configure_restir(box, 4, 0)
    ours = render_passes(box)
    configure_cycles(box, 4, 0)
    ref = render_passes(box)
    # pixel-centre data: compare where both see the same flat surface (away from edges)
    flat = interior(ref["Depth"][..., 0])
    assert np.allclose(ours["Depth"][..., 0][flat], ref["Depth"][..., 0][flat], rtol=0.01)
    dots = (ours["Normal"] * ref["Normal"]).sum(axis=2)
    assert np.median(dots[flat]) > 0.999


def test_border_with_and_without_crop(box):
    configure_restir(box, 1, 0)
    r = box.render
    r.use_border = True
    r.border_min_x, r.border_max_x, r.border_min_y, r.border_max_y = 0.5, 1.0, 0.0, 0.5
    r.use_crop_to_border = True
    cropped = render_passes(box)["Combined"]
    assert cropped.shape[:2] == (15, 20)
    r.use_crop_to_border = False
    full = render_passes(box)["Combined"]
    assert full.shape[:2] == (30, 40)
    assert full[15:, :, 3].max() == 0 and full[:, :20, 3].max() == 0  # outside the border: empty
    assert np.allclose(full[:15, 20:], cropped)


def test_film_transparent_gives_alpha(addon):
    scene = cornell_box("SUN", (32, 32))
    configure_restir(scene, 2, 0)
    scene.render.film_transparent = True
    world = scene.world.node_tree.nodes["Background"].inputs["Color"]
    world.default_value = (1, 1, 1, 1)
    c = render_passes(scene)["Combined"]
    assert c[..., 3].min() == 0.0 and c[..., 3].max() == 1.0
    sky = c[..., 3] == 0
    assert np.allclose(c[sky, :3], 0.0)


def test_animation_frames_render_each_frame(addon, tmp_path):
    scene = cornell_box("EMISSIVE", (16, 16))
    configure_restir(scene, 1, 0)
    cam = scene.camera
    cam.keyframe_insert("location", frame=1)
    cam.location.x += 0.5
    cam.keyframe_insert("location", frame=2)
    scene.frame_start, scene.frame_end = 1, 2
    scene.render.filepath = str(tmp_path / "f_")
    scene.render.image_settings.file_format = "PNG"
    bpy.ops.render.render(animation=True)
    assert (tmp_path / "f_0001.png").exists() and (tmp_path / "f_0002.png").exists()
    a = bpy.data.images.load(str(tmp_path / "f_0001.png"))
    b = bpy.data.images.load(str(tmp_path / "f_0002.png"))
    assert not np.array_equal(np.array(a.pixels[:]), np.array(b.pixels[:]))  # the camera moved


@pytest.mark.parametrize("ortho", [False, True])
def test_camera_models_match_cycles_geometry(box, ortho):
    """Orthographic and shifted/sensor-fitted perspective cameras see the same surfaces as Cycles."""
    cam = box.camera.data
    cam.shift_x, cam.shift_y = 0.1, -0.05
    cam.sensor_fit = "VERTICAL"
    if ortho:
        cam.type = "ORTHO"
        cam.ortho_scale = 2.5
    configure_restir(box, 1, 0)
    ours = render_passes(box)
    configure_cycles(box, 1, 0)
    ref = render_passes(box)
    flat = interior(ref["Depth"][..., 0])
    assert flat.mean() > 0.2
    assert np.allclose(ours["Depth"][..., 0][flat], ref["Depth"][..., 0][flat], rtol=0.01)
    assert np.median((ours["Normal"] * ref["Normal"]).sum(axis=2)[flat]) > 0.999


def test_reservoir_passes_only_with_reservoirs(box):
    vl = box.view_layers[0]
    vl.restir.use_pass_reservoir_m = vl.restir.use_pass_reservoir_ucw = True
    configure_restir(box, 2, 1, integrator="PATH")
    assert "Reservoir M" not in render_passes(box)  # the path tracer has no reservoirs: no placeholder pass
    configure_restir(box, 2, 1, integrator="RESTIR", direct_method="RIS", light_candidates=8)
    p = render_passes(box)
    m, w = p["Reservoir M"][..., 0], p["Reservoir UCW"][..., 0]
    inside = interior(p["Depth"][..., 0])  # away from silhouettes, where jittered samples mix hit and miss
    assert np.allclose(m[inside], 1.0)  # one initial RIS reservoir per pixel and sample
    assert ((m >= 0) & (m <= 1)).all()
    assert np.isfinite(w).all() and (w >= 0).all() and w[inside].mean() > 0
    assert np.allclose(p["Combined"][..., :3], p["Emission"] + p["Direct"] + p["Indirect"], atol=1e-4)


def test_animation_carries_temporal_history_between_frames(addon, tmp_path):
    """Frames rendered in sequence reuse the previous frame's reservoirs (confidence grows up to the cap);
    a frame rendered on its own starts fresh."""
    from harness.render import read_exr, use_multilayer_exr
    scene = cornell_box("AREA", (24, 24))
    configure_restir(scene, 1, 0, integrator="RESTIR", direct_method="RESTIR", spatial_neighbors=0,
                     confidence_cap=2.0, preroll_frames=0)
    scene.view_layers[0].restir.use_pass_reservoir_m = True
    use_multilayer_exr(scene)
    scene.frame_start, scene.frame_end = 1, 3
    scene.render.filepath = str(tmp_path / "f_")
    bpy.ops.render.render(animation=True)
    m = [read_exr(str(tmp_path / f"f_{f:04d}.exr"))["Reservoir M"][..., 0] for f in (1, 2, 3)]
    inside = m[0] > 0.99  # pixels with a surface
    assert m[0].max() <= 1.0                         # first frame: initial reservoirs only
    assert m[1][inside].mean() > 1.5                 # second frame: + the previous frame's reservoir
    assert m[2][inside].max() <= 2.0 + 1.0 + 1e-5    # cap 2 on the history, + the new initial reservoir
    scene.frame_current = 7
    p = render_passes(scene)                         # a jump: no history
    assert p["Reservoir M"].max() <= 1.0


def test_vector_pass_matches_cycles(addon):
    """Motion vectors from Blender's object and camera transforms, in Cycles' convention
    (prev - current, current - next, raster pixels), on a moving block seen by a moving camera."""
    scene = cornell_box("EMISSIVE", (48, 48))
    scene.render.use_motion_blur = False
    scene.view_layers[0].use_pass_vector = True
    scene.view_layers[0].use_pass_z = True
    block = bpy.data.objects["Block"]
    for f, dx in ((1, -0.1), (2, 0.0), (3, 0.12)):
        block.location.x = 0.3 + dx
        block.keyframe_insert("location", frame=f)
    cam = scene.camera
    for f, dz in ((1, -0.05), (2, 0.0), (3, 0.04)):
        cam.location.z = 1.0 + dz
        cam.keyframe_insert("location", frame=f)
    scene.frame_set(2)
    configure_restir(scene, 1, 0)
    ours = render_passes(scene)
    configure_cycles(scene, 1, 0)
    ref = render_passes(scene)
    flat = interior(ref["Depth"][..., 0])
    v_ours, v_ref = ours["Vector"][flat], ref["Vector"][flat]
    assert np.abs(v_ref).max() > 0.5  # there is motion to compare
    assert np.allclose(v_ours, v_ref, atol=0.02), np.abs(v_ours - v_ref).max()


def render_chunk(scene, first: int, last: int) -> dict:
    """Render frames first..last as an animation job (a farm chunk); passes of the last frame."""
    import tempfile

    from harness.render import read_exr, use_multilayer_exr
    use_multilayer_exr(scene)
    scene.frame_start, scene.frame_end = first, last
    with tempfile.TemporaryDirectory() as tmp:
        scene.render.filepath = tmp + "/f_"
        bpy.ops.render.render(animation=True)
        return read_exr(f"{tmp}/f_{last:04d}.exr")


def test_preroll_builds_history_for_a_chunk_start(addon):
    """An animation job that starts mid-animation without history prerolls the frames before it, so its
    reservoirs carry history (confidence above one) as in a sequential render. A still never prerolls:
    its sample passes reuse each other."""
    from restir_engine import engine
    scene = cornell_box("AREA", (24, 24))
    configure_restir(scene, 1, 0, integrator="RESTIR", direct_method="RESTIR", spatial_neighbors=0)
    scene.view_layers[0].restir.use_pass_reservoir_m = True
    engine._TEMPORAL_HISTORY.clear()
    scene.restir.preroll_frames = 0
    assert render_chunk(scene, 20, 20)["Reservoir M"].max() <= 1.0
    engine._TEMPORAL_HISTORY.clear()
    scene.restir.preroll_frames = 3
    m = render_chunk(scene, 40, 40)["Reservoir M"][..., 0]
    assert m.max() > 3.0 and m.max() <= 4.0 + 1e-5  # three preroll frames + this frame's own reservoir
    engine._TEMPORAL_HISTORY.clear()
    scene.frame_set(60)
    assert render_passes(scene)["Reservoir M"].max() <= 1.0  # a still: no preroll


def _moving_camera_box(size=(24, 24)):
    scene = cornell_box("AREA", size)
    cam = scene.camera
    for f in range(1, 5):
        cam.location.x = 0.04 * (f - 1)
        cam.keyframe_insert("location", frame=f)
    scene.view_layers[0].restir.use_pass_reservoir_m = True
    return scene


def _frame4(scene, chunked: bool, first_preroll: int = 0):
    """Frame 4 of a job starting there with three preroll frames (a farm chunk), or of a job rendering
    frames 1-4, whose frame 1 prerolls ``first_preroll`` frames."""
    from restir_engine import engine
    engine._TEMPORAL_HISTORY.clear()
    scene.restir.preroll_frames = 3 if chunked else first_preroll
    return render_chunk(scene, 4 if chunked else 1, 4)


def test_chunked_render_matches_sequential(addon):
    """A chunk starting at frame 4 prerolls the first sample pass of frames 1-3 (the pass the history
    travels through) with the same seeds: it reproduces a sequential render that started at frame 1
    exactly. Against a sequential render whose first frame had its own preroll (a longer history) it
    matches statistically once the preroll reaches the confidence cap (here 3 frames, cap 2): frame-4
    mean within 5 standard errors over 6 seeds,
    mean confidence M within 5 %."""
    scene = _moving_camera_box()
    configure_restir(scene, 2, 0)
    seq, chunk = _frame4(scene, False), _frame4(scene, True)
    assert seq["Reservoir M"].max() > 3.0  # history was carried
    assert np.array_equal(seq["Combined"], chunk["Combined"])
    assert np.array_equal(seq["Reservoir M"], chunk["Reservoir M"])
    means, ms = {False: [], True: []}, {False: [], True: []}
    for seed in range(6):
        configure_restir(scene, 2, 0, seed, confidence_cap=2.0)
        for chunked in (False, True):
            p = _frame4(scene, chunked, first_preroll=3)
            means[chunked].append(p["Combined"][..., :3].mean())
            ms[chunked].append(p["Reservoir M"].mean())
    a, b = np.array(means[False]), np.array(means[True])
    se = welch_se(a, b)
    assert abs(a.mean() - b.mean()) < 5 * se, (a.mean(), b.mean(), se)
    assert abs(np.mean(ms[True]) / np.mean(ms[False]) - 1) < 0.05, (np.mean(ms[True]), np.mean(ms[False]))


def test_data_passes_only_when_written(addon):
    """Depth, Normal and Vector cost a ray per pixel: the engine asks the core for them only when the view
    layer writes one, and the core then skips them."""
    from restir_engine.core.renderer import RenderSettings, render_frame
    from restir_engine.engine import settings_from_scene, with_data_passes
    from scenes_core import floor_with_emitter
    scene = cornell_box("AREA", (16, 16))
    configure_restir(scene, 1, 0)
    vl = scene.view_layers[0]
    vl.use_pass_z = vl.use_pass_normal = vl.use_pass_vector = False
    assert not with_data_passes(settings_from_scene(scene), vl).data_passes
    vl.use_pass_vector = True
    assert with_data_passes(settings_from_scene(scene), vl).data_passes
    core = floor_with_emitter(width=8)
    assert not {"Depth", "Normal", "Vector"} & set(render_frame(core, RenderSettings(samples=1,
                                                                                   data_passes=False)).passes)
    assert {"Depth", "Normal", "Vector"} <= set(render_frame(core, RenderSettings(samples=1)).passes)


def test_gi_reservoir_passes_only_with_restir_gi(box):
    """GI Reservoir M / UCW exist only when ReSTIR GI runs (Indirect Method ReSTIR GI, bounces > 0); with it the
    passes are finite, M at least one on every hit pixel, and Combined = Emission + Direct + Indirect."""
    vl = box.view_layers[0]
    vl.restir.use_pass_gi_reservoir_m = vl.restir.use_pass_gi_reservoir_ucw = True
    configure_restir(box, 2, 1, integrator="RESTIR", indirect_method="PATH")
    assert "GI Reservoir M" not in render_passes(box)
    configure_restir(box, 2, 0, integrator="RESTIR", indirect_method="RESTIR_GI")
    assert "GI Reservoir M" not in render_passes(box)  # no bounces: no indirect light to resample
    configure_restir(box, 2, 1, integrator="RESTIR", indirect_method="RESTIR_GI")
    p = render_passes(box)
    m, w = p["GI Reservoir M"][..., 0], p["GI Reservoir UCW"][..., 0]
    inside = interior(p["Depth"][..., 0])
    assert (m[inside] >= 1.0).all() and np.isfinite(w).all() and (w >= 0).all() and w[inside].mean() > 0
    assert np.allclose(p["Combined"][..., :3], p["Emission"] + p["Direct"] + p["Indirect"], atol=1e-4)


def test_chunked_render_matches_sequential_with_gi(addon):
    """The GI history travels like the DI history: a chunk starting at frame 4 with three preroll frames reproduces
    frame 4 of a sequential render exactly, and carries history (temporal confidence above one)."""
    scene = _moving_camera_box()
    scene.view_layers[0].restir.use_pass_gi_reservoir_m = True
    configure_restir(scene, 1, 1, integrator="RESTIR", direct_method="LIGHT_SAMPLING", indirect_method="RESTIR_GI",
                     gi_spatial_neighbors=0)
    seq, chunk = _frame4(scene, False), _frame4(scene, True)
    assert seq["GI Reservoir M"].max() > 3.0  # temporal only: own sample + three frames of history
    assert np.array_equal(seq["Combined"], chunk["Combined"])
    assert np.array_equal(seq["GI Reservoir M"], chunk["GI Reservoir M"])


def test_light_group_passes_split_combined(box):
    """View Layer > Light Groups: one "Combined_<group>" pass per group, from lamps, emissive objects and the world
    (a sun in "key", the ceiling quad in "key", a lamp in "fill", the world in "sky"; a lamp whose group the view
    layer does not have is in none); the passes add up to Combined less the ungrouped lamp's light. Without light
    groups there are no such passes."""
    import math

    from bpy_scenes import enable_nodes, light
    configure_restir(box, 4, 2)
    plain = render_passes(box)
    assert not any(k.startswith("Combined_") for k in plain)
    layer = box.view_layers[0]
    for name in ("key", "fill", "sky"):
        layer.lightgroups.add(name=name)
    bpy.data.objects["Lamp"].lightgroup = "key"
    light("POINT", (0.4, 0.0, 0.6), energy=20.0, shadow_soft_size=0.1).lightgroup = "fill"
    light("SUN", (0, 0, 5), (math.radians(20), 0, 0), energy=2.0).lightgroup = "key"
    stray = light("POINT", (-0.4, 0.0, 0.6), energy=20.0, shadow_soft_size=0.1)
    stray.lightgroup = "nonexistent"
    world = bpy.data.worlds.new("Sky")
    enable_nodes(world)
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.2, 0.3, 0.5, 1)
    world.lightgroup = "sky"
    box.world = world
    grouped = render_passes(box)
    groups = {n: grouped[f"Combined_{n}"] for n in ("key", "fill", "sky")}
    assert all(g.mean() > 1e-3 for g in groups.values())
    total = sum(groups.values())
    assert np.abs(total - grouped["Combined"][..., :3]).mean() > 1e-3  # the stray lamp's light is in no group
    stray.lightgroup = "fill"
    again = render_passes(box)
    total = sum(again[f"Combined_{n}"] for n in ("key", "fill", "sky"))
    assert np.abs(total - again["Combined"][..., :3]).max() <= 1e-4 * max(1.0, float(again["Combined"].max()))
