"""Lamp colour as Blender's light settings and node trees give it: Exposure, Temperature, and Emission Color and
Strength folded through their nodes (RGB, Math, Mix, Blackbody); what cannot be folded is named."""
import bpy
import numpy as np
import pytest


def _lamp(name="Lamp"):
    light = bpy.data.lights.new(name, "POINT")
    light.energy = 10.0
    light.color = (1.0, 0.5, 0.25)
    return light


def _power(light):
    from restir_engine.export.lights import _lamp_power
    warnings = []
    return _lamp_power(light, light.name, warnings), warnings


def test_blackbody_table_is_blenders_colour(addon):
    from restir_engine.core.lights.blackbody import blackbody_rgb
    light = _lamp("Blackbody probe")
    light.use_temperature = True
    rng = np.random.default_rng(3)
    for t in np.exp(rng.uniform(np.log(900), np.log(35000), 12)):
        light.temperature = float(t)
        np.testing.assert_allclose(blackbody_rgb(t).ravel(), light.temperature_color, rtol=3e-3, atol=2e-3)


def test_exposure_temperature_and_node_tree(addon):
    light = _lamp("Lamp settings")
    base = np.array([10.0, 5.0, 2.5])
    got, warns = _power(light)
    np.testing.assert_allclose(got, base, rtol=1e-6)
    light.exposure = 1.5
    np.testing.assert_allclose(_power(light)[0], base * 2 ** 1.5, rtol=1e-6)
    light.exposure = 0.0
    light.use_temperature = True
    light.temperature = 3200.0
    np.testing.assert_allclose(_power(light)[0], base * np.array(light.temperature_color), rtol=3e-3)
    light.use_temperature = False
    light.use_nodes = True
    tree = light.node_tree
    em = next(n for n in tree.nodes if n.type == "EMISSION")
    rgb = tree.nodes.new("ShaderNodeRGB")
    rgb.outputs[0].default_value = (1.0, 0.1, 0.1, 1.0)  # the third-party red lamp
    math = tree.nodes.new("ShaderNodeMath")
    math.operation = "MULTIPLY"
    math.inputs[0].default_value = 2.0
    math.inputs[1].default_value = 3.0
    tree.links.new(rgb.outputs[0], em.inputs["Color"])
    tree.links.new(math.outputs[0], em.inputs["Strength"])
    got, warns = _power(light)
    np.testing.assert_allclose(got, base * np.array([1.0, 0.1, 0.1]) * 6.0, rtol=1e-5)
    assert not warns
    bb = tree.nodes.new("ShaderNodeBlackbody")
    bb.inputs["Temperature"].default_value = 2000.0
    tree.links.new(bb.outputs[0], em.inputs["Color"])
    light.use_temperature = True
    light.temperature = 2000.0  # the same colour through the node
    want = base * np.array(light.temperature_color) * 6.0
    light.use_temperature = False
    np.testing.assert_allclose(_power(light)[0], want, rtol=3e-3)
    tex = tree.nodes.new("ShaderNodeTexNoise")
    tree.links.new(tex.outputs["Color"], em.inputs["Color"])
    # a graph that varies over the lamp: a node program (core/lights/lamp_textures.py, tests/cycles
    # test_lamp_textures_cycles), the constant factor 1; without a program to give it to (a sun) it is named
    from restir_engine.core.lights.lamp_textures import OUTPUT
    from restir_engine.export.lights import _lamp_power
    warns, program = [], []
    got = _lamp_power(light, light.name, warns, None, None, program)
    assert not warns and len(program) == 1 and program[0].has(OUTPUT) and "generated" in program[0].reads
    np.testing.assert_allclose(got, base, rtol=1e-6)
    got, warns = _power(light)
    assert any("varies over the light" in w for w in warns)
    np.testing.assert_allclose(got, base * np.array(em.inputs["Color"].default_value[:3]) * 6.0, rtol=1e-5)


@pytest.mark.parametrize("output", ["Quadratic", "Linear", "Constant"])
def test_light_falloff(addon, output):
    """A lamp's Light Falloff: its Strength folds into the power, and the output used (with its Smooth) becomes
    the lamp's distance factor (scene.Lamps.falloff, applied per receiver: tests/cycles test_light_falloff), with
    no warning; two falloffs of different kinds are named and the first used."""
    from restir_engine.export.lights import _lamp_power
    light = _lamp(f"Falloff {output}")
    light.use_nodes = True
    tree = light.node_tree
    em = next(n for n in tree.nodes if n.type == "EMISSION")
    fo = tree.nodes.new("ShaderNodeLightFalloff")
    fo.inputs["Strength"].default_value = 4.0
    fo.inputs["Smooth"].default_value = 0.5
    tree.links.new(fo.outputs[output], em.inputs["Strength"])
    warns, falloff = [], [0, 0.0]
    got = _lamp_power(light, light.name, warns, falloff)
    np.testing.assert_allclose(got, np.array([10.0, 5.0, 2.5]) * np.array(em.inputs["Color"].default_value[:3]) * 4,
                               rtol=1e-6)
    assert not warns
    assert tuple(falloff) == (("Quadratic", "Linear", "Constant").index(output), 0.5)
    other = tree.nodes.new("ShaderNodeLightFalloff")
    mix = tree.nodes.new("ShaderNodeMath")
    tree.links.new(fo.outputs[output], mix.inputs[0])
    tree.links.new(other.outputs["Constant" if output != "Constant" else "Linear"], mix.inputs[1])
    tree.links.new(mix.outputs[0], em.inputs["Strength"])
    warns, falloff = [], [0, 0.0]
    _lamp_power(light, light.name, warns, falloff)
    assert any("mix falloffs" in w for w in warns) and falloff[0] == ("Quadratic", "Linear", "Constant").index(output)


@pytest.mark.parametrize("kind", ["POINT", "SPOT", "AREA_DISK", "AREA_RECTANGLE"])
def test_normalize_off_does_not_spread_the_power_over_the_light(addon, kind):
    """Light > Normalize off (Blender 4.2+): Cycles does not divide the power by the light's surface, so the
    radiance is the normalized one times the area (measured with Cycles 5.2 on a lit cube: 4πr² for point lights at
    r = 0.05, 0.2 and 0.5, the disk's and the rectangle's area for area lights). Before, Normalize was ignored (a
    ratio of 1)."""
    from harness.scenes import camera, reset

    from restir_engine.export import export_scene
    reset()
    camera((0, -5, 0), (np.pi / 2, 0, 0))
    light = bpy.data.lights.new("Probe", kind.split("_")[0])
    if kind.startswith("AREA"):
        light.shape = kind.split("_")[1]
        light.size, light.size_y = 0.7, 2.0
        # the world-space area, with the object's scale (1, 1.5, 1) below
        area = np.pi * 0.35 * 0.35 * 1.5 if light.shape == "DISK" else 0.7 * 2.0 * 1.5
    else:
        light.shadow_soft_size = 0.2
        area = 4 * np.pi * 0.2 ** 2
    obj = bpy.data.objects.new("Probe", light)
    obj.scale = (1.0, 1.5, 1.0) if kind.startswith("AREA") else (1, 1, 1)
    bpy.context.scene.collection.objects.link(obj)
    radiance = []
    for normalize in (True, False):
        light.normalize = normalize
        sc = export_scene(bpy.context.evaluated_depsgraph_get())
        radiance.append(sc.materials.emission[sc.materials.names.index("(light Probe)")])
    np.testing.assert_allclose(radiance[1], radiance[0] * area, rtol=1e-4)


def test_ies_texture_on_a_lamp_is_a_program_and_a_missing_file_is_named(addon, tmp_path):
    """An IES Texture on a lamp's Strength: a node program of the profile (its images against Cycles:
    tests/cycles test_ies_lamps_match_cycles); an external file that is not there is named, and reads 100 as in
    Cycles."""
    from bpy_scenes import ies_text

    from restir_engine.core.lights.lamp_textures import OUTPUT
    from restir_engine.export.lights import _lamp_power
    light = _lamp("IES probe")
    light.use_nodes = True
    tree = light.node_tree
    em = next(n for n in tree.nodes if n.type == "EMISSION")
    node = tree.nodes.new("ShaderNodeTexIES")
    tree.links.new(node.outputs["Fac"], em.inputs["Strength"])
    path = tmp_path / "profile.ies"
    path.write_text(ies_text("full"))
    node.mode, node.filepath = "EXTERNAL", str(path)
    warns, program = [], []
    _lamp_power(light, light.name, warns, None, None, program)
    assert not warns and len(program) == 1 and program[0].has(OUTPUT)
    node.filepath = str(tmp_path / "missing.ies")
    warns, program = [], []
    _lamp_power(light, light.name, warns, None, None, program)
    assert any("IES Texture" in w and "missing.ies" in w for w in warns)
    assert len(program) == 1  # the lookup reads 100 everywhere, folded into the lamp's program


def test_textured_lamps_render_alike_on_worker_processes(addon):
    """A scene with textured lamps (a gobo spot and an IES point lamp: their programs, images and profiles cross to
    the workers) renders bit for bit the image one process renders, with ReSTIR DI."""
    from bpy_scenes import ies_lamp_scene, textured_lamp_scene

    from restir_engine.core.parallel import processes
    from restir_engine.core.renderer import RenderSettings, render_frame
    from restir_engine.export import export_scene
    settings = RenderSettings(integrator="RESTIR", direct_method="RESTIR", samples=2, max_bounces=1,
                              tile_pixels=1024, light_tiles="ON")
    try:
        for build in (lambda: textured_lamp_scene("spot", (48, 40)), lambda: ies_lamp_scene("turned", (48, 40))):
            build()
            scene = export_scene(bpy.context.evaluated_depsgraph_get())
            assert scene.lamps.textured is not None
            alone = render_frame(scene, settings, processes=1)
            team = render_frame(scene, settings, processes=2)
            assert team.stats["processes"] == 2
            combined = alone.passes["Combined"]
            assert combined[..., :3].mean() > 0.01
            assert np.array_equal(combined, team.passes["Combined"])
    finally:
        processes.shutdown()
