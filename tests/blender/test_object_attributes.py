"""The Attribute node's Object, Instancer and View Layer types (export/object_properties.py) against Cycles, pixel by
pixel:
a grid of emissive planes seen by an orthographic camera, each plane's Emission driven by one Attribute node (its
Color into the Emission colour, or its Fac or Alpha into the Strength), read from custom properties of the object
(a number, an integer, a boolean, a 2-, 3- and 4-array, a string), of its mesh, RNA paths (``color``,
``location``), through a collection instance whose empty holds its own value (Instancer) over the instanced
object's (Object), and of the view layer, scene and world (View Layer, in that order; an RNA path of the scene). Emission alone has no noise: inside each plane both engines give the same value to float32
precision."""
import bpy
import numpy as np
from bpy_scenes import configure_cycles, configure_restir, render_passes

# (attribute type, name, output) per plane; planes after INSTANCED are inside a collection instance
CASES = [("OBJECT", "fprop", "Color"), ("OBJECT", '["vprop"]', "Color"), ("OBJECT", "v4prop", "Alpha"),
         ("OBJECT", "v4prop", "Color"), ("OBJECT", "color", "Fac"), ("OBJECT", "mprop", "Color"),
         ("OBJECT", "both", "Color"), ("OBJECT", "b2", "Color"), ("OBJECT", "iprop", "Fac"),
         ("OBJECT", "flag", "Color"), ("OBJECT", "sprop", "Alpha"), ("OBJECT", "location", "Color"),
         ("OBJECT", "missing", "Alpha"), ("INSTANCER", "fprop", "Color"),
         ("INSTANCER", "inst", "Color"), ("OBJECT", "inst", "Color"), ("INSTANCER", "both", "Fac"),
         ("INSTANCER", "location", "Color"),
         ("VIEW_LAYER", "a", "Color"), ("VIEW_LAYER", "b", "Color"), ("VIEW_LAYER", "c", "Fac"),
         ("VIEW_LAYER", "d", "Alpha"), ("VIEW_LAYER", "render.resolution_x", "Fac"), ("VIEW_LAYER", "fprop", "Color")]
INSTANCED = range(14, 18)  # these planes are instanced by an empty
COLS, ROWS, CELL = 6, 4, 8  # grid of planes; pixels per plane


def _material(kind, name, output):
    mat = bpy.data.materials.new(f"attr_{kind}_{name}_{output}")
    tree = mat.node_tree
    for n in list(tree.nodes):
        tree.nodes.remove(n)
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    em = tree.nodes.new("ShaderNodeEmission")
    att = tree.nodes.new("ShaderNodeAttribute")
    att.attribute_type, att.attribute_name = kind, name
    tree.links.new(em.outputs[0], out.inputs["Surface"])
    if output == "Color":
        tree.links.new(att.outputs["Color"], em.inputs["Color"])
    else:
        em.inputs["Color"].default_value = (1, 1, 1, 1)
        tree.links.new(att.outputs[output], em.inputs["Strength"])
    return mat


def _plane(k, material):
    mesh = bpy.data.meshes.new(f"attr_plane{k}")
    x, y = (k % COLS) - (COLS - 1) / 2, (ROWS - 1) / 2 - (k // COLS)
    h = 0.45
    mesh.from_pydata([(x - h, y - h, 0), (x + h, y - h, 0), (x + h, y + h, 0), (x - h, y + h, 0)], [],
                     [(0, 1, 2, 3)])
    mesh.materials.append(material)
    mesh["mprop"] = 0.75
    mesh["both"] = 0.5
    ob = bpy.data.objects.new(f"attr_plane{k}", mesh)
    ob["fprop"], ob["vprop"], ob["v4prop"], ob["iprop"] = 0.25, (0.1, 0.2, 0.3), [0.4, 0.5, 0.6, 0.7], 2
    ob["both"], ob["b2"], ob["flag"], ob["sprop"], ob["inst"] = 0.35, [0.3, 0.6], True, "text", 0.4
    ob.color = (0.9, 0.5, 0.2, 0.8)
    ob.location = (0.0, 0.0, 0.01 * k)  # the RNA path "location" reads this, not the plane's place in the grid
    return ob


def object_attribute_scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = COLS * CELL, ROWS * CELL
    scene.render.resolution_percentage = 100
    cam = bpy.data.objects.new("attr_cam", bpy.data.cameras.new("attr_cam"))
    cam.data.type, cam.data.ortho_scale = "ORTHO", COLS
    cam.location = (0, 0, 5)
    scene.collection.objects.link(cam)
    scene.camera = cam
    coll = bpy.data.collections.new("attr_instanced")
    for k, case in enumerate(CASES):
        ob = _plane(k, _material(*case))
        (coll if k in INSTANCED else scene.collection).objects.link(ob)
    empty = bpy.data.objects.new("attr_instancer", None)
    empty.instance_type, empty.instance_collection = "COLLECTION", coll
    empty["inst"], empty["fprop"] = 0.9, 0.15
    empty.location = (0.0, 0.0, -0.5)
    scene.collection.objects.link(empty)
    world = bpy.data.worlds.new("attr_world")
    world.color = (0, 0, 0)
    scene.world = world
    # View Layer attributes: the view layer's, else the scene's, else the world's
    scene.view_layers[0]["a"], scene["a"], world["a"] = 0.1, 0.2, 0.3
    scene["b"], world["b"], world["c"], scene["d"] = 0.45, 0.5, (0.6, 0.7, 0.8), [0.1, 0.2, 0.3, 0.4]
    return scene


def _inner_pixels(image):
    """(planes, 3): each plane's mean over its inner 4 x 4 pixels (rows of the image top-down)."""
    img = image[::-1]
    out = []
    for k in range(len(CASES)):
        r, c = k // COLS, k % COLS
        out.append(img[r * CELL + 2:r * CELL + 6, c * CELL + 2:c * CELL + 6, :3].reshape(-1, 3))
    return np.array(out)


def test_object_and_instancer_attributes_match_cycles(addon):
    scene = object_attribute_scene()
    configure_cycles(scene, 4, 0, 0)
    cycles = _inner_pixels(render_passes(scene)["Combined"])
    configure_restir(scene, 4, 0, 0, integrator="PATH")
    ours = _inner_pixels(render_passes(scene)["Combined"])
    assert np.ptp(cycles, axis=1).max() < 1e-5  # flat emission: one value per plane
    names = [f"{k} {c}" for k, c in enumerate(CASES)]
    err = np.abs(ours - cycles).max(axis=(1, 2))
    assert (err < 1e-4).all(), [(n, o[0].tolist(), c[0].tolist()) for n, o, c, e in zip(names, ours, cycles, err)
                                if e >= 1e-4]
    # what the cases tell apart: numbers, arrays, the mesh's, the instancer's over the object's
    values = cycles[:, 0]
    assert np.allclose(values[0], 0.25) and np.allclose(values[1], (0.1, 0.2, 0.3))
    assert np.allclose(values[13], 0.25)  # Instancer on an object nothing instances: the object's own
    assert np.allclose(values[14], 0.9) and np.allclose(values[15], 0.4)  # the empty's; the instanced object's
    assert np.allclose(values[16], 0.35) and np.allclose(values[17], (0, 0, -0.5))  # the empty has no "both"
    assert np.allclose(values[18:21, 0], (0.1, 0.45, 0.7)) and np.allclose(values[22], COLS * CELL)  # render.resolution_x
    assert np.allclose(values[23], 0.0)  # an object's property is not the view layer's
    assert np.allclose(values[10], 0.0) and np.allclose(values[12], 0.0)  # a string, a missing name: alpha 0


def test_a_property_edit_reaches_the_viewports_export(addon):
    """An edit of an object's property that a material reads (its Color, the RNA path "color") exports the instances
    again (TRANSFORM, no mesh read) with the new value; were the properties not read, it would stay a SHADING edit
    (the triangles and instances of the last export kept)."""
    from restir_engine.export import export_scene
    from restir_engine.export.incremental import SceneExporter, reads_object_properties, update_level
    object_attribute_scene()
    dg = bpy.context.evaluated_depsgraph_get()
    exporter = SceneExporter()
    cam = export_scene(dg).camera
    first = exporter.export(dg, cam, "FULL")
    assert reads_object_properties(first)
    seen = []

    def on_update(_scene, depsgraph):
        level = update_level(depsgraph.updates, reads_object_properties(exporter.last))
        seen.append((level, update_level(depsgraph.updates), exporter.export(depsgraph, cam, level)))

    bpy.app.handlers.depsgraph_update_post.append(on_update)
    try:
        ob = bpy.data.objects["attr_plane4"]  # its material reads the Fac of "color"
        ob.color = (0.3, 0.6, 0.9, 1.0)
        bpy.context.view_layer.update()
    finally:
        bpy.app.handlers.depsgraph_update_post.remove(on_update)
    assert len(seen) == 1
    level, plain_level, out = seen[0]
    assert level == "TRANSFORM" and plain_level == "SHADING" and out.export_stats["meshes_read"] == 0
    objs = out.geometry.objects
    k = objs.names.index("attr_plane4")
    assert np.allclose(objs.properties["OBJECT:color"][k], (0.3, 0.6, 0.9, 1.0))
    assert np.allclose(first.geometry.objects.properties["OBJECT:color"][k], (0.9, 0.5, 0.2, 0.8))


def test_an_instancer_attribute_found_nowhere_is_named(addon):
    """An Instancer attribute that neither the instancer, the instanced object nor its mesh holds (Cycles may find
    it among a Geometry Nodes instance's attributes, which Python cannot read) reads 0, with a warning naming it."""
    from restir_engine.export import export_scene
    object_attribute_scene()
    assert not [w for w in export_scene(bpy.context.evaluated_depsgraph_get()).warnings if "(Instancer)" in w]
    node = bpy.data.materials["attr_INSTANCER_inst_Color"].node_tree.nodes["Attribute"]
    node.attribute_name = "nowhere"
    sc = export_scene(bpy.context.evaluated_depsgraph_get())
    assert [w for w in sc.warnings if "Attribute 'nowhere' (Instancer)" in w]
    assert not sc.geometry.objects.properties["INSTANCER:nowhere"].any()


def test_an_object_colour_edit_reaches_the_viewports_export(addon):
    """A material reading Object Info's Color: an edit of the object's Color exports the instances again with it
    (before, the viewport kept the last export's object table until a full export)."""
    from restir_engine.export import export_scene
    from restir_engine.export.incremental import SceneExporter, reads_object_properties, update_level
    object_attribute_scene()
    ob = bpy.data.objects["attr_plane0"]
    mat = ob.data.materials[0]
    tree = mat.node_tree
    info = tree.nodes.new("ShaderNodeObjectInfo")
    tree.links.new(info.outputs["Color"], tree.nodes["Emission"].inputs["Color"])
    for other in bpy.data.materials:  # no material reads properties: Object Info alone decides
        if other != mat:
            node = other.node_tree.nodes["Attribute"]
            node.attribute_type, node.attribute_name = "GEOMETRY", "none"
    dg = bpy.context.evaluated_depsgraph_get()
    exporter = SceneExporter()
    cam = export_scene(dg).camera
    first = exporter.export(dg, cam, "FULL")
    assert first.geometry.objects.properties is None and reads_object_properties(first)
    seen = []

    def on_update(_scene, depsgraph):
        level = update_level(depsgraph.updates, reads_object_properties(exporter.last))
        seen.append((level, exporter.export(depsgraph, cam, level)))

    bpy.app.handlers.depsgraph_update_post.append(on_update)
    try:
        ob.color = (0.2, 0.7, 0.1, 1.0)
        bpy.context.view_layer.update()
    finally:
        bpy.app.handlers.depsgraph_update_post.remove(on_update)
    level, out = seen[-1]
    k = out.geometry.objects.names.index("attr_plane0")
    assert level == "TRANSFORM" and np.allclose(out.geometry.objects.color[k], (0.2, 0.7, 0.1, 1.0))


def _world_reading_view_layer_b():
    """object_attribute_scene with its world's Background Color the View Layer attribute "b", Strength 2."""
    scene = object_attribute_scene()
    tree = scene.world.node_tree
    att = tree.nodes.new("ShaderNodeAttribute")
    att.attribute_type, att.attribute_name = "VIEW_LAYER", "b"
    tree.links.new(att.outputs["Color"], tree.nodes["Background"].inputs["Color"])
    tree.nodes["Background"].inputs["Strength"].default_value = 2.0
    return scene


def test_a_world_reads_view_layer_attributes(addon):
    """A world whose Background Color is a View Layer attribute: the scene's value over the world's (one constant
    radiance); before, the node was approximated by its socket's value with a warning."""
    from restir_engine.export import export_scene
    scene = _world_reading_view_layer_b()
    sc = export_scene(bpy.context.evaluated_depsgraph_get())
    assert np.allclose(sc.world_radiance, 0.9) and not [w for w in sc.warnings if "Attribute" in w]


def test_a_scene_property_edit_reaches_the_viewports_graphs(addon):
    """A View Layer attribute is folded into the graphs that read it; an edit of the scene's properties (a Scene
    update) compiles them again in the viewport (SHADING, no mesh read) with the new value. A scene whose graphs read
    none keeps a scene edit at SETTINGS (the exported scene reused)."""
    from types import SimpleNamespace

    from restir_engine.export import export_scene
    from restir_engine.export.incremental import SceneExporter, reads_view_layer, update_level
    scene = _world_reading_view_layer_b()
    dg = bpy.context.evaluated_depsgraph_get()
    exporter = SceneExporter()
    cam = export_scene(dg).camera
    first = exporter.export(dg, cam, "FULL")
    assert reads_view_layer(first) and np.allclose(first.world_radiance, 0.9)
    # what the properties panel sends for a scene's custom property: an update of the Scene alone
    edit = [SimpleNamespace(id=scene, is_updated_geometry=False, is_updated_transform=False)]
    assert update_level(edit, view_layer=reads_view_layer(first)) == "SHADING"
    assert update_level(edit) == "SETTINGS"
    scene["b"] = 0.25
    scene.update_tag()  # as the panel's edit tags it: the evaluated scene takes the new value
    bpy.context.view_layer.update()
    out = exporter.export(bpy.context.evaluated_depsgraph_get(), cam, "SHADING")
    assert exporter.last_level == "SHADING"  # around the last export's triangles: no mesh read
    assert np.allclose(out.world_radiance, 0.5) and reads_view_layer(out)
    from bpy_scenes import cornell_box
    cornell_box()  # graphs that read no View Layer attribute
    assert not reads_view_layer(export_scene(bpy.context.evaluated_depsgraph_get()))
