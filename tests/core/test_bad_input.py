"""Bad input gives a clear message and a valid (finite) image, never a crash."""
import math
import time

import bpy
import numpy as np
import pytest
from bpy_scenes import camera, configure_restir, cornell_box, render_passes, reset

from restir_engine.core.renderer import RenderSettings, render_frame
from restir_engine.engine import scene_problems
from restir_engine.export import export_scene


def export():
    return export_scene(bpy.context.evaluated_depsgraph_get())


def small_scene():
    scene = reset()
    scene.render.resolution_x = scene.render.resolution_y = 16
    camera((0, -5, 1), (math.pi / 2, 0, 0))
    configure_restir(scene, 1, 1)
    return scene


def test_no_camera_render_fails_with_a_message(addon):
    scene = reset()
    scene.render.engine = "RESTIR"
    bpy.ops.mesh.primitive_cube_add()
    with pytest.raises(RuntimeError, match="(?i)camera"):
        bpy.ops.render.render()


def test_no_lights_gives_black_image_and_warning(addon):
    scene = small_scene()
    bpy.ops.mesh.primitive_cube_add()
    p = render_passes(scene)
    assert np.isfinite(p["Combined"]).all() and p["Combined"][..., :3].max() == 0
    s = export()
    assert any("no lights" in m for m in scene_problems(s, 0))


def test_empty_scene_renders_the_world(addon):
    scene = small_scene()
    scene.world = bpy.data.worlds.new("W")
    scene.world.color = (0.25, 0.5, 1.0)
    if bpy.app.version >= (5, 0, 0):
        scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.25, 0.5, 1.0, 1)
    p = render_passes(scene)
    assert np.allclose(p["Combined"][..., :3], (0.25, 0.5, 1.0), atol=1e-5)
    assert any("nothing to render" in m for m in scene_problems(export(), 0))


def _mesh(verts, faces, name="bad"):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def test_zero_area_nan_and_huge_triangles_are_skipped_with_warnings(addon):
    cornell = cornell_box("EMISSIVE", (16, 16))
    configure_restir(cornell, 1, 1)
    _mesh([(0, 0, 0), (1, 0, 0), (2, 0, 0)], [(0, 1, 2)], "degenerate")
    nan = _mesh([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)], "nan")
    nan.data.vertices[0].co = (float("nan"), 0, 0)
    _mesh([(1e9, 0, 0), (1e9 + 1, 0, 0), (1e9, 1, 0)], [(0, 1, 2)], "huge")
    s = export()
    assert any("zero-area" in w for w in s.warnings)
    assert any("NaN" in w and "nan" in w for w in s.warnings)
    assert np.isfinite(s.geometry.verts).all() and np.abs(s.geometry.verts).max() < 1e7
    p = render_passes(cornell)
    for img in p.values():
        assert np.isfinite(img).all()
    assert p["Combined"][..., :3].mean() > 0


def test_cancel_stops_within_a_second(addon):
    """Esc (test_break) during the second sample pass: the render returns within a second with the
    first pass kept."""
    cornell_box("EMISSIVE", (320, 240))
    s = export()
    samples = 64
    asked = {}

    def progress(fraction, _msg):
        if fraction > 1.5 / samples and "t" not in asked:
            asked["t"] = time.perf_counter()

    r = render_frame(s, RenderSettings(samples=samples, max_bounces=4), progress=progress,
                     should_stop=lambda: "t" in asked)
    latency = time.perf_counter() - asked["t"]
    assert r.cancelled and r.samples_done == 1
    assert latency < 1.0, f"stopped {latency:.2f}s after the request"
    assert np.isfinite(r.passes["Combined"]).all()


def test_camera_inside_geometry_and_zero_size_light(addon):
    scene = cornell_box("AREA", (16, 16))
    configure_restir(scene, 1, 1)
    bpy.data.lights[0].size = 0.0
    scene.camera.location = (0, 0, 0.0)  # on the floor plane
    s = export()
    assert any("zero area" in w for w in s.warnings)
    p = render_passes(scene)
    assert np.isfinite(p["Combined"]).all()


def _frames(scene, frames=(1, 2, 3)):
    """Combined of each frame rendered in turn (each frame after the first reuses the one before)."""
    out = []
    for f in frames:
        scene.frame_set(f)
        out.append(render_passes(scene)["Combined"])
    return out


@pytest.mark.parametrize("scale", [(0, 0, 0), (1, 1, 0)], ids=["hidden", "flattened"])
def test_an_object_scaled_to_zero_renders_with_temporal_history(addon, scale):
    """Scaling to 0 is how animators hide objects: frames with history (motion of every instance) render,
    without a warning for a hidden object's triangles."""
    cornell = cornell_box("EMISSIVE", (24, 16))
    configure_restir(cornell, 1, 1, direct_method="RESTIR")
    bpy.ops.mesh.primitive_cube_add(size=0.3, location=(-0.4, 0.3, 0.3))
    cube = bpy.context.active_object
    cube.scale = scale
    cube.keyframe_insert("location", frame=1)
    cube.location.x += 0.2
    cube.keyframe_insert("location", frame=3)
    for img in _frames(cornell):
        assert np.isfinite(img).all() and img[..., :3].mean() > 0
    warnings = export().warnings
    assert not any("zero-area" in w for w in warnings) if scale == (0, 0, 0) else True


def test_motion_of_singular_instances_follows_the_object():
    """scene.affine_inverse: the pseudo-inverse on singular instances, the inverse elsewhere."""
    from restir_engine.core.scene import Motion, affine_inverse
    regular = np.eye(4)
    regular[:3, :3] = [[2, 0, 0], [0, 0, -3], [0, 1, 0]]
    regular[:3, 3] = (1, 2, 3)
    flat = np.diag([2.0, 1.0, 0.0, 1.0])
    flat[:3, 3] = (0, 0, 5)
    zero = np.zeros((4, 4))
    zero[:, 3] = (4, 5, 6, 1)
    inv = affine_inverse(np.stack([regular, flat, zero]))
    assert np.allclose(inv[0] @ regular, np.eye(4))
    moved = np.stack([regular, flat, zero]).copy()
    moved[:, :3, 3] += (1.0, 0.0, 0.0)  # every instance one unit along x
    motion = Motion(current=np.stack([regular, flat, zero]), prev=moved, next=moved)
    pts = np.array([[1.0, 2.0, 4.0], [2.0, 3.0, 5.0], [3.0, 5.0, 6.0]])  # one point on each (columns)
    then = motion.moved_points(pts, np.array([0, 1, 2]), "prev")
    assert np.allclose(then, pts + np.array([[1.0], [0.0], [0.0]]), atol=1e-5)


def test_a_camera_scaled_to_zero_gives_a_black_frame_with_a_warning(addon):
    cornell = cornell_box("EMISSIVE", (16, 16))
    configure_restir(cornell, 1, 1, direct_method="RESTIR")
    cornell.camera.scale = (0, 0, 0)
    for img in _frames(cornell, (1, 2)):
        assert np.isfinite(img).all() and img.max() == 0
    assert any("scaled to zero" in w for w in export().warnings)
    cornell.camera.scale = (1, 0, 1)  # one axis lost: rebuilt from the other two, the same picture
    flat = export().camera.cam_to_world
    cornell.camera.scale = (1, 1, 1)
    assert np.allclose(flat, export().camera.cam_to_world, atol=1e-6)


def test_a_clip_start_at_blenders_minimum_renders_the_scene(addon):
    """Typing 0 stores 1e-6: the near plane must stay finite (Blender's projection is float32), and the image
    is the one a clip start of 1 cm gives with the same seed."""
    import warnings as py_warnings
    cornell = cornell_box("EMISSIVE", (16, 16))
    configure_restir(cornell, 1, 1)
    images = {}
    for clip in (1e-6, 0.01):
        cornell.camera.data.clip_start = clip
        with py_warnings.catch_warnings():
            py_warnings.simplefilter("error", RuntimeWarning)
            images[clip] = render_passes(cornell)["Combined"]
    assert images[1e-6][..., :3].mean() > 0.05
    assert np.allclose(images[1e-6], images[0.01], rtol=1e-3, atol=1e-4)


def _mix_chain(levels: int, fac: float, shared: bool):
    """A material of ``levels`` nested Mix shaders: each mixes a grey Diffuse (A, weight 1 - fac) with the next
    level (B, weight fac); with ``shared`` every Mix takes both inputs from the level below (a DAG of 2^levels
    paths to one Diffuse)."""
    m = bpy.data.materials.new(f"chain{levels}{shared}")
    enable = getattr(m, "use_nodes", None)
    if enable is not None and not m.node_tree:
        m.use_nodes = True
    nodes, links = m.node_tree.nodes, m.node_tree.links
    nodes.remove(nodes["Principled BSDF"])
    grey = nodes.new("ShaderNodeBsdfDiffuse")
    grey.inputs["Color"].default_value = (0.5, 0.5, 0.5, 1)
    below = grey
    for _ in range(levels):
        mix = nodes.new("ShaderNodeMixShader")
        mix.inputs["Fac"].default_value = fac
        links.new((below if shared else grey).outputs[0], mix.inputs[1])
        links.new(below.outputs[0], mix.inputs[2])
        below = mix
    links.new(below.outputs[0], nodes["Material Output"].inputs["Surface"])
    return m


@pytest.mark.parametrize("levels,shared", [(24, False), (40, True)], ids=["deep", "shared-40"])
def test_deep_and_shared_mix_trees_keep_their_weight(addon, levels, shared):
    """Cycles follows any depth: the flattened weights of a grey Diffuse mixed with itself sum to 1 (cut off at 8
    levels, a 0.9 chain kept 1 - 0.9^8 = 57 % of it); a DAG of 2^40 paths exports at once, as one component."""
    small_scene()
    bpy.ops.mesh.primitive_cube_add()
    bpy.context.active_object.data.materials.append(_mix_chain(levels, 0.9, shared))
    t0 = time.perf_counter()
    table = export().materials
    assert time.perf_counter() - t0 < 10.0
    row = int(np.flatnonzero(table.mix_count > 0)[0])
    first, count = table.mix_first[row], table.mix_count[row]
    assert count == 1
    assert abs(float(table.mix_weight[first:first + count].sum()) - 1.0) < 1e-5


def test_extreme_emission_is_clamped_beside_a_negative_lamp(addon):
    """Radiance of 1e38 would overflow float32 sums (the emitter rendered black): clamped to export.limits'
    maximum with a warning, the emitter seen at that radiance; a lamp of negative power beside it is exported (it
    subtracts light: tests/core/test_negative_lights.py), without a warning."""
    from restir_engine.export.limits import MAX_RADIANCE
    cornell = cornell_box("EMISSIVE", (16, 16))
    configure_restir(cornell, 1, 1)
    bpy.ops.mesh.primitive_cube_add(size=0.5, location=(0, 0.3, 0.8))
    m = bpy.data.materials.new("Blinding")
    nodes = m.node_tree.nodes if m.node_tree else (setattr(m, "use_nodes", True) or m.node_tree.nodes)
    nodes["Principled BSDF"].inputs["Emission Color"].default_value = (1, 1, 1, 1)
    nodes["Principled BSDF"].inputs["Emission Strength"].default_value = 1e38
    bpy.context.active_object.data.materials.append(m)
    lamp = bpy.data.lights.new("Negative", "POINT")
    lamp.energy = -50.0
    obj = bpy.data.objects.new("Negative", lamp)
    obj.location = (0, 0, 1.0)
    cornell.collection.objects.link(obj)
    warnings = export().warnings
    assert any("Blinding" in w and "clamped" in w for w in warnings)
    assert not any("Negative" in w for w in warnings)
    img = render_passes(cornell)["Combined"][..., :3].astype(np.float64)
    assert np.isfinite(img).all()
    # the emitter's pixels, not black: about MAX_RADIANCE (a pixel may add the lit surfaces around it), never the
    # unclamped 1e38 that overflowed
    assert 0.5 * MAX_RADIANCE < img.max() < 4.0 * MAX_RADIANCE


def test_a_frame_that_cannot_fit_is_refused_before_any_work(addon, monkeypatch):
    """The engine estimates a frame's peak memory (core/pipeline/memory.py) and refuses, with the estimate, the free
    memory and what to change, where the settings' cheapest choice cannot fit; the path tracer it suggests then
    fits. Where only Auto's dearest choice cannot fit, it warns and renders."""
    from restir_engine.core.pipeline import memory
    from restir_engine.engine import settings_from_scene, with_data_passes

    def settings():  # what the engine renders with
        return with_data_passes(settings_from_scene(cornell), bpy.context.view_layer)
    cornell = cornell_box("EMISSIVE", (64, 48))
    configure_restir(cornell, 1, 1, direct_method="RESTIR", indirect_method="RESTIR_GI")
    est = memory.frame_estimate(export(), settings(), keeps_history=False)  # F12 of a still keeps no history
    assert est.low == est.high
    monkeypatch.setattr(memory, "available_memory", lambda: est.low - 1)
    with pytest.raises(RuntimeError, match=r"needs about .* MB of memory .* is free.*Path Tracing"):
        render_passes(cornell)
    cornell.restir.integrator = "PATH"
    assert memory.frame_estimate(export(), settings(), keeps_history=False).high < est.low
    assert np.isfinite(render_passes(cornell)["Combined"]).all()
    cornell.restir.integrator = "RESTIR"
    cornell.restir.direct_method = cornell.restir.indirect_method = "AUTO"
    auto = memory.frame_estimate(export(), settings(), keeps_history=False)
    assert auto.low < auto.high
    monkeypatch.setattr(memory, "available_memory", lambda: (auto.low + auto.high) // 2)
    img = render_passes(cornell)["Combined"]
    assert np.isfinite(img).all() and img[..., :3].mean() > 0


def test_the_memory_estimate_orders_the_methods():
    from restir_engine.core.pipeline import memory
    from restir_engine.core.renderer import RenderSettings
    path = memory.per_pixel_range(RenderSettings(integrator="PATH"))
    di = memory.per_pixel_range(RenderSettings(integrator="RESTIR", direct_method="RESTIR", indirect_method="PATH"))
    both = memory.per_pixel_range(RenderSettings(integrator="RESTIR", direct_method="RESTIR",
                                                 indirect_method="RESTIR_GI"))
    auto = memory.per_pixel_range(RenderSettings(integrator="RESTIR", direct_method="AUTO", indirect_method="AUTO"))
    assert path[0] == path[1] < di[0] == di[1] < both[0] == both[1]
    assert auto[0] < auto[1] == both[1]
    # a still keeps no history: less for each ReSTIR method, nothing less for the path tracer
    still = {name: memory.per_pixel_range(RenderSettings(**kw), keeps_history=False) for name, kw in (
        ("path", dict(integrator="PATH")), ("di", dict(integrator="RESTIR", direct_method="RESTIR",
                                                       indirect_method="PATH")),
        ("both", dict(integrator="RESTIR", direct_method="RESTIR", indirect_method="RESTIR_GI")))}
    assert still["path"] == path and still["di"][0] < di[0] and still["both"][0] < both[0]
    assert path[0] < still["di"][0] < still["both"][0]


def _fuzzed_scene(rng):
    """A Cornell box with a random handful of the bad inputs above combined."""
    cornell = cornell_box("EMISSIVE", (32, 24))
    configure_restir(cornell, 1, int(rng.integers(0, 3)), direct_method=str(rng.choice(["AUTO", "RESTIR", "RIS"])),
                     indirect_method=str(rng.choice(["AUTO", "PATH", "RESTIR_GI"])))
    picks = rng.choice(9, size=int(rng.integers(1, 5)), replace=False)
    for pick in picks:
        if pick == 0:  # an object scaled to zero, animated
            bpy.ops.mesh.primitive_cube_add(size=0.3, location=(0.2, 0.3, 0.3))
            bpy.context.active_object.scale = (0, 0, 0) if rng.random() < 0.5 else (1, 0, 1)
        elif pick == 1:
            nan = _mesh([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)], "nan")
            nan.data.vertices[int(rng.integers(0, 3))].co = (float("nan"), float("inf"), 0)
        elif pick == 2:
            strength = float(10.0 ** rng.uniform(20, 38))
            bpy.data.materials["Lamp"].node_tree.nodes["Emission"].inputs["Strength"].default_value = strength
        elif pick == 3:
            cornell.camera.scale = tuple(float(v) for v in rng.choice([0.0, 1.0], 3))
        elif pick == 4:
            cornell.camera.data.clip_start = 1e-6
        elif pick == 5:
            cornell.camera.data.type = "ORTHO"
            cornell.camera.data.ortho_scale = float(rng.choice([0.0, 2.0]))
        elif pick == 6:  # a missing texture on the floor's colour
            image = bpy.data.images.new("Missing", 4, 4)
            image.source = "FILE"
            image.filepath = "/nonexistent/texture.png"
            white = bpy.data.materials["White"]
            tex = white.node_tree.nodes.new("ShaderNodeTexImage")
            tex.image = image
            shader = next(n for n in white.node_tree.nodes if n.type == "BSDF_DIFFUSE")
            white.node_tree.links.new(tex.outputs["Color"], shader.inputs["Color"])
        elif pick == 7:
            bpy.ops.mesh.primitive_cube_add(size=0.4, location=(-0.3, 0.4, 0.3))
            bpy.context.active_object.data.materials.append(_mix_chain(int(rng.integers(9, 30)), 0.7, True))
        elif pick == 8:
            lamp = bpy.data.lights.new("Negative", "POINT")
            lamp.energy = -float(rng.uniform(1, 100))
            obj = bpy.data.objects.new("Negative", lamp)
            obj.location = (0, 0, 1.2)
            cornell.collection.objects.link(obj)
    return cornell, sorted(int(p) for p in picks)


@pytest.mark.parametrize("seed", range(20))
def test_fuzzed_bad_scenes_render_finite_or_fail_in_one_line(addon, seed):
    """20 random combinations of the bad inputs above, two frames each (the second with history): every pass is
    finite, or the render fails with one clear line."""
    cornell, picks = _fuzzed_scene(np.random.default_rng(seed))
    for frame in (1, 2):
        cornell.frame_set(frame)
        try:
            passes = render_passes(cornell)
        except RuntimeError as exc:
            # Blender repeats the engine's report in the operator's error: one message, maybe twice
            lines = {ln.strip() for ln in str(exc).strip().splitlines() if ln.strip()}
            assert len(lines) == 1 and "Traceback" not in str(exc), (picks, str(exc))
            continue
        for name, img in passes.items():
            assert np.isfinite(img).all(), (picks, name)


def test_the_memory_estimate_counts_the_denoiser(addon, monkeypatch):
    """A denoised frame's peak includes the denoiser's images and OIDN's scratch: with the free memory between the
    render's own peak and the denoised peak the engine refuses and says that turning Denoise off fits; with Denoise
    off the same frame renders."""
    from restir_engine.core.pipeline import memory
    from restir_engine.engine import settings_from_scene, with_data_passes
    cornell = cornell_box("EMISSIVE", (64, 48))
    configure_restir(cornell, 1, 1, integrator="PATH")
    st = with_data_passes(settings_from_scene(cornell), bpy.context.view_layer)
    alone = memory.frame_estimate(export(), st)
    denoised = memory.with_denoising(alone, st, keeps_history=False)
    assert denoised.low > memory.DENOISER_SCRATCH > alone.high and denoised.render == alone.high
    monkeypatch.setattr(memory, "available_memory", lambda: (alone.high + denoised.low) // 2)
    cornell.restir.use_denoising = True
    with pytest.raises(RuntimeError, match=r"turn Denoise off .*needs about"):
        render_passes(cornell)
    cornell.restir.use_denoising = False
    assert np.isfinite(render_passes(cornell)["Combined"]).all()
