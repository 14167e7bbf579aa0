"""Every scene setting is written once, in properties.SCENE_FIELDS: the Blender properties are generated from it,
settings_from_scene reads through it, and this test fails when a setting is missing anywhere (the core's
RenderSettings, the enum values the core knows, the presets, the panels) or when a saved file's values are lost."""
import json
import os

import bpy
import numpy as np

DATA = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "data")

# RenderSettings fields that do not come from scene.restir, and where they come from instead
NOT_SCENE = {"frame": "scene.frame_current", "film_transparent": "scene.render.film_transparent",
             "data_passes": "the view layer's Depth/Normal/Vector passes (engine.with_data_passes)",
             "reservoir_passes": "the view layer's reservoir passes", "gi_reservoir_passes": "the GI reservoir passes",
             "denoise_data": "the view layer's Denoising Data pass", "tile_pixels": "core tuning (chunk size)",
             "sample_batch": "core tuning (automatic)", "gi_target": "core measurements only",
             "shadow_catcher_pass": "the view layer's Shadow Catcher pass"}
# the core's defaults are the reference path tracer's; a new Blender scene defaults to ReSTIR with Auto methods
CORE_DEFAULT_DIFFERS = {"integrator", "direct_method", "indirect_method", "use_adaptive_sampling"}


def _fields():
    from restir_engine.properties import SCENE_FIELDS
    return SCENE_FIELDS


def test_every_core_setting_is_in_the_table_or_named(addon):
    import dataclasses

    from restir_engine.core.renderer import RenderSettings
    core = {f.name for f in dataclasses.fields(RenderSettings)}
    table = {f.name for f in _fields() if f.to_core is not None}
    assert table <= core, f"table fields the core does not have: {sorted(table - core)}"
    missing = sorted(core - table - set(NOT_SCENE))
    assert core - table == set(NOT_SCENE), f"core fields neither in the table nor named: {missing}"


def test_properties_are_the_table(addon):
    props = {k for k in bpy.types.Scene.bl_rna.properties["restir"].fixed_type.properties.keys()
             if k not in ("rna_type", "name")}
    assert props == {f.name for f in _fields()}


def test_defaults_agree_with_the_core(addon):
    import dataclasses

    from restir_engine.core.renderer import RenderSettings
    from restir_engine.engine import settings_from_scene
    scene = bpy.data.scenes.new("defaults")
    try:
        ours = settings_from_scene(scene)
        core = RenderSettings()
        def same(a, b):  # Blender keeps float properties in float32
            return np.float32(a) == np.float32(b) if isinstance(b, float) else a == b

        differ = {f.name for f in dataclasses.fields(RenderSettings)
                  if f.name not in NOT_SCENE and not same(getattr(ours, f.name), getattr(core, f.name))}
        assert differ == CORE_DEFAULT_DIFFERS, differ
    finally:
        bpy.data.scenes.remove(scene)


def test_enum_values_are_the_cores(addon):
    from restir_engine.core.integrators.method_choice import WORLD_METHODS
    from restir_engine.core.lights.tiles import TILE_MODES
    from restir_engine.core.pipeline.settings import INTEGRATORS, LIGHT_SAMPLERS
    from restir_engine.core.restir import di, gi, reuse
    known = {"integrator": INTEGRATORS, "direct_method": di.DIRECT_METHODS, "indirect_method": gi.INDIRECT_METHODS,
             "world_method": WORLD_METHODS, "light_tiles": TILE_MODES, "bias_correction": reuse.BIAS_CORRECTIONS,
             "light_sampler": LIGHT_SAMPLERS}
    rna = bpy.types.Scene.bl_rna.properties["restir"].fixed_type.properties
    for name, values in known.items():
        assert {i.identifier for i in rna[name].enum_items} == set(values), name


def test_presets_name_table_fields(addon):
    from restir_engine.presets import PRESETS
    names = {f.name for f in _fields()}
    for preset, values in PRESETS.items():
        assert set(values) <= names, (preset, set(values) - names)


def test_panels_draw_every_setting(addon):
    """Each scene setting is drawn by some panel (its draw or draw_header), for the ReSTIR integrator with ReSTIR
    direct light (where every sub-panel shows)."""
    from panel_drawing import drawn_properties
    scene = bpy.context.scene
    scene.restir.integrator, scene.restir.direct_method, scene.restir.indirect_method = "RESTIR", "RESTIR", "AUTO"
    seen = {name for data, name in drawn_properties(scene, bpy.context.view_layer) if data == scene.restir}
    assert {f.name for f in _fields()} - seen == set()


def test_a_file_saved_before_the_table_keeps_every_value(addon):
    """tests/data/settings_before_table.blend was saved (bpy 5.0.1) by the add-on before the settings were generated
    from the table, with a value other than the default in every setting; opening it finds each value."""
    with open(os.path.join(DATA, "settings_before_table.json")) as f:
        expected = json.load(f)
    bpy.ops.wm.open_mainfile(filepath=os.path.join(DATA, "settings_before_table.blend"))
    s = bpy.context.scene.restir
    got = {name: getattr(s, name) for name in expected}
    for name, value in expected.items():
        assert got[name] == value if not isinstance(value, float) else abs(got[name] - value) < 1e-6, (name, got[name])
    # every setting of the table when the file was saved but use_denoising (its update edited the compositor then)
    newer = {"processes", "pixel_filter", "filter_width", "time_limit", "use_adaptive_sampling", "adaptive_threshold",
             "adaptive_min_samples", "denoising_input_passes", "denoising_prefilter", "denoising_quality",
             "use_preview_denoising"}  # settings added since
    assert set(expected) >= {f.name for f in _fields()} - {"use_denoising"} - newer
