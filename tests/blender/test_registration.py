import bpy


def engine_selectable(engine_id="RESTIR") -> bool:
    scene = bpy.context.scene
    old = scene.render.engine
    try:
        scene.render.engine = engine_id
    except TypeError:
        return False
    scene.render.engine = old
    return True


def test_engine_is_registered_and_selectable(addon):
    assert engine_selectable()
    scene = bpy.context.scene
    scene.render.engine = "RESTIR"
    assert scene.render.engine == "RESTIR"
    from restir_engine.engine import RestirRenderEngine
    assert RestirRenderEngine.bl_label == "ReSTIR"
    assert RestirRenderEngine.bl_use_shading_nodes_custom is False
    assert RestirRenderEngine.bl_use_eevee_viewport is True


def test_settings_defaults(addon):
    scene = bpy.data.scenes.new("fresh")
    try:
        s = scene.restir
        assert (s.samples, s.seed, s.max_bounces, s.integrator) == (16, 0, 4, "RESTIR")
        assert (s.direct_method, s.light_candidates, s.bsdf_candidates, s.coverage_samples) == ("AUTO", 32, 1, "AUTO")
        assert (s.light_tiles, s.light_tile_count, s.light_tile_size) == ("AUTO", 128, 1024)
        assert (s.temporal_reuse, s.confidence_cap, s.spatial_neighbors, s.spatial_radius, s.bias_correction) == (
            True, 20.0, 5, 0.0, "UNBIASED")
        vl = scene.view_layers[0].restir
        assert not (vl.use_pass_direct or vl.use_pass_indirect or vl.use_pass_emission or vl.use_pass_reservoir_m)
    finally:
        bpy.data.scenes.remove(scene)


def test_panels_registered_and_only_for_this_engine(addon):
    for name in ("RESTIR_PT_sampling", "RESTIR_PT_light_paths", "RESTIR_PT_passes"):
        panel = getattr(bpy.types, name)
        assert panel.COMPAT_ENGINES == {"RESTIR"}

        class Ctx:
            engine = "RESTIR"
        assert panel.poll(Ctx)
        Ctx.engine = "CYCLES"
        assert not panel.poll(Ctx)
    for name in ("RENDER_PT_format", "RENDER_PT_output", "RENDER_PT_color_management", "DATA_PT_lens",
                 "EEVEE_MATERIAL_PT_context_material", "EEVEE_MATERIAL_PT_surface", "DATA_PT_camera",
                 "DATA_PT_light", "OBJECT_PT_visibility", "EEVEE_WORLD_PT_surface"):
        assert "RESTIR" in getattr(bpy.types, name).COMPAT_ENGINES, name


def test_unregister_and_register_again(addon):
    addon.unregister()
    try:
        assert not hasattr(bpy.types.Scene, "restir")
        assert not engine_selectable()
        assert "RESTIR" not in bpy.types.RENDER_PT_format.COMPAT_ENGINES
    finally:
        addon.register()
    assert hasattr(bpy.types.Scene, "restir")
    bpy.context.scene.render.engine = "RESTIR"


def test_presets_set_the_settings(addon):
    s = bpy.context.scene.restir
    bpy.ops.restir.apply_preset(preset="UNBIASED")
    assert (s.integrator, s.direct_method, s.bias_correction, s.temporal_reuse) == ("RESTIR", "RESTIR", "UNBIASED", True)
    bpy.ops.restir.apply_preset(preset="FAST")
    assert (s.bias_correction, s.light_candidates, s.samples) == ("NONE", 8, 4)
    bpy.ops.restir.apply_preset(preset="REFERENCE")
    assert (s.integrator, s.samples) == ("PATH", 256)


def test_panels_draw_every_setting(addon):
    from panel_drawing import drawn_properties
    scene = bpy.context.scene
    scene.restir.integrator, scene.restir.direct_method = "RESTIR", "RESTIR"
    seen = [name for _data, name in drawn_properties(scene, bpy.context.view_layer)]
    for name in ("samples", "seed", "max_bounces", "light_candidates", "temporal_reuse", "confidence_cap",
                 "preroll_frames", "spatial_neighbors", "bias_correction", "use_pass_reservoir_m", "use_pass_vector"):
        assert name in seen, name


def test_panels_draw_with_the_last_render_choices(addon):
    """The Sampling and Passes panels draw (with a recording stand-in for the layout) for the defaults, including
    the box that shows what Auto chose in the last render."""
    from restir_engine import engine
    from restir_engine.ui import panels

    drawn = []

    class Layout:
        def __getattr__(self, name):
            def call(*args, **kwargs):
                drawn.append((name, args, kwargs.get("text")))
                return Layout()
            return call

        def __setattr__(self, name, value):
            pass

    class Context:
        scene = bpy.context.scene
        view_layer = bpy.context.view_layer
        engine = "RESTIR"

    st = Context.scene.restir
    st.integrator, st.direct_method, st.coverage_samples, st.spatial_radius = "RESTIR", "AUTO", "AUTO", 0.0
    engine.LAST_CHOICES[Context.scene.name] = {"direct_method": "LIGHT_SAMPLING", "direct_reason": "1 point lamp",
                                               "coverage_samples": 4, "coverage_reason": "emitters can be seen",
                                               "spatial_radius": 8.0}
    try:
        for panel in panels.PANELS:
            class Fake:
                layout = Layout()
                split_layout = panels.RestirPanel.split_layout
            panel.draw(Fake(), Context())
    finally:
        engine.LAST_CHOICES.clear()
    texts = [t for _n, _a, t in drawn if t]
    assert "Last render: Light Sampling" in texts and "1 point lamp" in texts
    assert any(t.startswith("Pixel coverage: 4 rays") for t in texts)


def test_viewport_render_pass_selector(addon):
    """The 3D view's shading settings carry the viewport pass (every documented pass is selectable) and the
    Shading popover's panel draws it for Rendered shading with this engine only."""
    from panel_drawing import RecordingLayout
    from restir_engine.ui import panels
    from restir_engine.viewport import VIEWPORT_PASSES
    space = next(a.spaces[0] for s in bpy.data.screens for a in s.areas if a.type == "VIEW_3D")
    shading = space.shading
    for key, _label, _desc in VIEWPORT_PASSES:
        shading.restir.render_pass = key
        assert shading.restir.render_pass == key
    seen = []

    class Ctx:
        engine = "RESTIR"
        space_data = space
    shading.type = "RENDERED"
    assert panels.RESTIR_PT_viewport_render_pass.poll(Ctx)
    holder = type("Holder", (), {"layout": RecordingLayout(seen)})()
    panels.RESTIR_PT_viewport_render_pass.draw(holder, Ctx)
    assert [name for _data, name in seen] == ["render_pass"]
    Ctx.engine = "CYCLES"
    assert not panels.RESTIR_PT_viewport_render_pass.poll(Ctx)
    shading.type = "SOLID"


def test_light_group_and_shadow_catcher_panels(addon):
    """Light groups can be set up from the UI with this engine: the view layer's list with add/remove (Passes
    panel), and an object's and the world's Light Group field (Object and World Properties), with the button that
    adds a group the view layer lacks; the panels show for this engine only."""
    from restir_engine.ui import panels
    bpy.ops.mesh.primitive_cube_add()
    obj = bpy.context.active_object
    obj.lightgroup = "Key (not in the view layer)"
    calls = []

    class Layout:
        use_property_split = use_property_decorate = False

        def __getattr__(self, name):
            def call(*args, **kwargs):
                calls.append((name, args, kwargs))
                return Layout()
            return call

    class Ctx:
        engine = "RESTIR"
        object = obj
        world = bpy.context.scene.world
        scene = bpy.context.scene
        view_layer = bpy.context.view_layer
    holder = type("Holder", (), {"layout": Layout(), "split_layout": panels.RestirPanel.split_layout,
                                 "draw_group": panels.RestirLightGroupPanel.draw_group})()
    for panel in (panels.RESTIR_PT_object_light_group, panels.RESTIR_PT_world_light_group):
        assert getattr(bpy.types, panel.__name__, None) is not None
        assert panel.poll(Ctx)
        calls.clear()
        panel.draw(holder, Ctx)
        search = [c for c in calls if c[0] == "prop_search"]
        assert search and search[0][1][1:] == ("lightgroup", Ctx.view_layer, "lightgroups")
        ops = [c[1][0] for c in calls if c[0] == "operator"]
        name = search[0][1][0].lightgroup
        missing = bool(name) and name not in Ctx.view_layer.lightgroups
        assert ops == (["scene.view_layer_add_lightgroup"] if missing else [])
    Ctx.engine = "CYCLES"
    assert not any(panel.poll(Ctx) for panel in panels.DATA_PANELS)
    Ctx.engine = "RESTIR"
    calls.clear()  # a shadow catcher is set in Object Properties > Visibility
    assert panels.RESTIR_PT_object_mask.poll(Ctx)
    panels.RESTIR_PT_object_mask.draw(holder, Ctx)
    assert [c[1][1] for c in calls if c[0] == "prop"] == ["is_shadow_catcher"]
    calls.clear()
    panels.RESTIR_PT_passes.draw(holder, Ctx)
    lists = [c for c in calls if c[0] == "template_list"]
    assert any("lightgroups" in c[1] for c in lists)
    assert {"scene.view_layer_add_lightgroup", "scene.view_layer_remove_lightgroup"} <= \
        {c[1][0] for c in calls if c[0] == "operator"}
    assert ("use_pass_shadow_catcher" in [c[1][1] for c in calls if c[0] == "prop"])
