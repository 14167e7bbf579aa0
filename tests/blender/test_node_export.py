"""Node graphs at export: constant graphs fold into the material's constants (no program, no cost per hit, no
warning), graphs that vary become a node program for exactly the fields they drive and unsupported nodes are
named."""
import bpy
import numpy as np
from bpy_scenes import node_planes
from node_graphs import _node, _set

from restir_engine.export import export_scene


def _principled_plane(wire):
    scene = node_planes([lambda tree, socket: None], 1, 8)
    mat = bpy.data.materials.new("Wired")
    mat.use_nodes = True
    wire(mat.node_tree, mat.node_tree.nodes["Principled BSDF"])
    bpy.data.objects["NodesPlane0"].data.materials[0] = mat
    return export_scene(bpy.context.evaluated_depsgraph_get()), scene


def test_constant_graph_folds_into_the_row(addon):
    def wire(tree, bsdf):
        m = _node(tree, "ShaderNodeMath", operation="ADD")
        _set(m, "Value", 0.2)
        _set(m, "Value_001", 0.3)
        tree.links.new(m.outputs[0], bsdf.inputs["Roughness"])
        rgb = _node(tree, "ShaderNodeRGB")
        rgb.outputs[0].default_value = (0.2, 0.4, 0.6, 1)
        inv = _node(tree, "ShaderNodeInvert")
        tree.links.new(rgb.outputs[0], inv.inputs["Color"])
        tree.links.new(inv.outputs[0], bsdf.inputs["Base Color"])
    sc, _ = _principled_plane(wire)
    i = sc.materials.names.index("Wired")
    assert sc.materials.program[i] == -1 and not sc.materials.programs
    assert abs(float(sc.materials.roughness[i]) - 0.5) < 1e-6
    np.testing.assert_allclose(sc.materials.base_color[i], (0.8, 0.6, 0.4), atol=1e-6)
    assert not [w for w in sc.warnings if "Wired" in w]


def test_varying_graph_becomes_a_program_and_unsupported_nodes_are_named(addon):
    def wire(tree, bsdf):
        n = _node(tree, "ShaderNodeTexNoise")
        tree.links.new(n.outputs["Fac"], bsdf.inputs["Roughness"])
        v = _node(tree, "ShaderNodeHairInfo")
        tree.links.new(v.outputs["Tangent Normal"], bsdf.inputs["Base Color"])
    sc, _ = _principled_plane(wire)
    i = sc.materials.names.index("Wired")
    prog = sc.materials.programs[sc.materials.program[i]]
    assert set(prog.outputs) == {"roughness"}  # Curves Info is not supported on a mesh: a constant, reported
    assert any("HAIR_INFO" in w and "not supported" in w for w in sc.warnings), sc.warnings


def test_node_programs_render_the_same_in_worker_processes(addon):
    """Programs travel to the workers with the scene (ramp tables, images, hashes): the same image, bit for bit."""
    from node_graphs import MIXES, NOISE, TEXTURES

    from process_runs import one_and_two_processes

    from restir_engine.core.renderer import RenderSettings
    node_planes([g for _n, g in NOISE[:3] + TEXTURES[-4:] + MIXES[:1]], 4, 16)
    sc = export_scene(bpy.context.evaluated_depsgraph_get())
    settings = RenderSettings(integrator="RESTIR", direct_method="RESTIR", samples=2, max_bounces=1, tile_pixels=512)
    one, two = one_and_two_processes(sc, settings)
    assert two.stats["processes"] == 2
    assert one.passes["Combined"][..., :3].mean() > 0.05
    assert np.array_equal(one.passes["Combined"], two.passes["Combined"])


def test_attribute_node_without_a_name_gives_zero(addon):
    """As Cycles (the glTF add-on's test files have such nodes): an Attribute node whose name is empty finds no
    attribute, so its Color is black (before: the mesh's first colour attribute was read)."""
    def wire(tree, bsdf):
        a = _node(tree, "ShaderNodeAttribute")
        a.attribute_name = ""
        tree.links.new(a.outputs["Color"], bsdf.inputs["Base Color"])
    sc, _ = _principled_plane(wire)
    i = sc.materials.names.index("Wired")
    np.testing.assert_array_equal(sc.materials.base_color[i], (0, 0, 0))
    assert sc.materials.program[i] == -1


def test_uv_map_node_reads_the_map_it_names(addon):
    """A UV Map node naming a second UV map (the glTF importer's texCoord indices) reads that map: here the first map
    mirrored in u, so a Gradient through it runs right to left (before: the render UV map, left to right)."""
    from bpy_scenes import render_passes
    from harness.render import configure_restir

    def graph(tree, socket):
        uv = _node(tree, "ShaderNodeUVMap")
        uv.uv_map = "Mirrored"
        grad = _node(tree, "ShaderNodeTexGradient")
        tree.links.new(uv.outputs["UV"], grad.inputs["Vector"])
        tree.links.new(grad.outputs["Color"], socket)

    def setup(obj):
        layer = obj.data.uv_layers.new(name="Mirrored")
        layer.data.foreach_set("uv", np.array([1, 0, 0, 0, 0, 1, 1, 1], np.float32))
        obj.data.uv_layers["UVMap"].active_render = True
    graph.setup = setup
    scene = node_planes([graph], 1, 16)
    configure_restir(scene, 4, 1, seed=1, integrator="PATH")
    img = render_passes(scene)["Combined"][..., 0].mean(axis=0)
    x = (np.arange(16) + 0.5) / 16
    np.testing.assert_allclose(img, 1 - x, atol=1 / 16)


def test_objects_sharing_a_mesh_read_what_their_own_materials_need(addon):
    """Two objects of one mesh with object-linked materials: the second one's colour attribute is read although the
    first object's material reads none (before: the mesh was read once, for the first object)."""
    def wire(tree, bsdf):
        pass
    sc, _ = _principled_plane(wire)
    first = bpy.data.objects["NodesPlane0"]
    attr = first.data.color_attributes.new("Col", "FLOAT_COLOR", "POINT")
    attr.data.foreach_set("color", np.tile([0.1, 0.7, 0.3, 1.0], 4).astype(np.float32))
    second = bpy.data.objects.new("SharedPlane", first.data)
    bpy.context.scene.collection.objects.link(second)
    second.location.x += 0.1
    mat = bpy.data.materials.new("ByAttribute")
    mat.use_nodes = True
    t = mat.node_tree
    ca = _node(t, "ShaderNodeVertexColor")
    ca.layer_name = "Col"
    t.links.new(ca.outputs["Color"], t.nodes["Principled BSDF"].inputs["Base Color"])
    second.material_slots[0].link = "OBJECT"
    second.material_slots[0].material = mat
    sc = export_scene(bpy.context.evaluated_depsgraph_get())
    i = sc.materials.names.index("ByAttribute")
    rows = np.flatnonzero(sc.geometry.material == i)
    assert len(rows) == 2
    np.testing.assert_allclose(sc.geometry.attributes["Col"][rows][..., :3], np.tile([0.1, 0.7, 0.3], (2, 3, 1)),
                               atol=1e-6)


def test_anisotropy_exports_cycles_aspect_rotation_and_tangent(addon):
    """Principled Anisotropic and Rotation become the row's aspect (√(1 - 0.9 a)) and rotation without a warning; a
    Noise Texture on Anisotropic and a Tangent node on Tangent become the program's fields; transmission under
    anisotropy is named (rendered isotropic)."""
    def constant(tree, bsdf):
        _set(bsdf, "Metallic", 1.0)
        _set(bsdf, "Anisotropic", 0.6)
        _set(bsdf, "Anisotropic Rotation", 0.25)
    sc, _ = _principled_plane(constant)
    m, i = sc.materials, sc.materials.names.index("Wired")
    assert abs(float(m.aniso_aspect[i]) - np.sqrt(1 - 0.9 * 0.6)) < 1e-6
    assert abs(float(m.aniso_rotation[i]) - 0.25) < 1e-6 and m.program[i] == -1
    assert not [w for w in sc.warnings if "Wired" in w]

    def varying(tree, bsdf):
        noise = _node(tree, "ShaderNodeTexNoise")
        tree.links.new(noise.outputs["Fac"], bsdf.inputs["Anisotropic"])
        tan = _node(tree, "ShaderNodeTangent")
        tree.links.new(tan.outputs["Tangent"], bsdf.inputs["Tangent"])
        _set(bsdf, "Transmission Weight", 0.5)
    sc, _ = _principled_plane(varying)
    m, i = sc.materials, sc.materials.names.index("Wired")
    prog = m.programs[m.program[i]]
    assert prog.has("aniso_aspect") and prog.has("tangent")
    assert [w for w in sc.warnings if "Wired" in w and "transmission is rendered isotropic" in w]


def test_principled_subsurface_exports_the_walks_medium(addon):
    """Subsurface Weight, Radius x Scale, the method (Random Walk: van de Hulst's walk on Blender 5.2, Chiang's
    before; Skin with its Subsurface IOR) and Anisotropy become the row's fields without a warning; a Noise Texture
    on the weight becomes the program's "subsurface"; Christensen-Burley is named (rendered as a random walk)."""
    from restir_engine.core.integrators import subsurface

    def constant(tree, bsdf):
        _set(bsdf, "Subsurface Weight", 0.8)
        _set(bsdf, "Subsurface Radius", (1.0, 0.5, 0.25))
        _set(bsdf, "Subsurface Scale", 0.2)
        _set(bsdf, "Subsurface Anisotropy", 0.3)
        _set(bsdf, "IOR", 1.45)
    sc, _ = _principled_plane(constant)
    m, i = sc.materials, sc.materials.names.index("Wired")
    assert abs(float(m.subsurface[i]) - 0.8) < 1e-6 and m.program[i] == -1
    np.testing.assert_allclose(m.sss_radius[i], (0.2, 0.1, 0.05), rtol=1e-6)
    walk = subsurface.WALK_VAN_DE_HULST if bpy.app.version >= (5, 2, 0) else subsurface.WALK_CHIANG
    assert m.sss_method[i] == walk and abs(float(m.sss_ior[i]) - 1.45) < 1e-6
    assert abs(float(m.sss_anisotropy[i]) - 0.3) < 1e-6
    assert not [w for w in sc.warnings if "Wired" in w]

    def skin(tree, bsdf):
        _set(bsdf, "Subsurface Weight", 1.0)
        bsdf.subsurface_method = "RANDOM_WALK_SKIN"
        _set(bsdf, "Subsurface IOR", 1.3)
        noise = _node(tree, "ShaderNodeTexNoise")
        tree.links.new(noise.outputs["Fac"], bsdf.inputs["Subsurface Weight"])
    sc, _ = _principled_plane(skin)
    m, i = sc.materials, sc.materials.names.index("Wired")
    assert m.sss_method[i] == subsurface.WALK_SKIN and abs(float(m.sss_ior[i]) - 1.3) < 1e-6
    assert m.programs[m.program[i]].has("subsurface")

    def burley(tree, bsdf):
        _set(bsdf, "Subsurface Weight", 1.0)
        bsdf.subsurface_method = "BURLEY"
    sc, _ = _principled_plane(burley)
    m, i = sc.materials, sc.materials.names.index("Wired")
    assert m.sss_method[i] == subsurface.WALK_CHIANG
    assert [w for w in sc.warnings if "Wired" in w and "Christensen-Burley" in w]


def test_principled_sheen_becomes_a_sheen_component_over_the_base(addon):
    """A Principled BSDF with Sheen becomes a Mix of a sheen row (its Tint, its Roughness as sheen_roughness) and the
    base, named as an approximation; a Sheen Roughness from a graph becomes the sheen row's program field; a Sheen
    Weight of 0 leaves the material a plain Principled row."""
    def wire(tree, bsdf):
        _set(bsdf, "Sheen Weight", 0.7)
        _set(bsdf, "Sheen Tint", (1.0, 0.5, 0.25, 1.0))
        noise = _node(tree, "ShaderNodeTexNoise")
        tree.links.new(noise.outputs["Fac"], bsdf.inputs["Sheen Roughness"])
    sc, _ = _principled_plane(wire)
    m = sc.materials
    i = m.names.index("Wired")
    comps = m.mix_comp[m.mix_first[i]:m.mix_first[i] + m.mix_count[i]]
    sheen_rows = [int(c) for c in comps if m.sheen_roughness[c] > 0]
    assert len(comps) == 2 and len(sheen_rows) == 1
    k = sheen_rows[0]
    np.testing.assert_allclose(m.base_color[k], (1.0, 0.5, 0.25), atol=1e-6)
    assert m.programs[m.program[k]].has("sheen_roughness")
    assert [w for w in sc.warnings if "Wired" in w and "Sheen" in w and "approximated" in w]

    def off(tree, bsdf):
        _set(bsdf, "Sheen Weight", 0.0)
    sc, _ = _principled_plane(off)
    i = sc.materials.names.index("Wired")
    assert sc.materials.mix_first[i] == -1 and not [w for w in sc.warnings if "Sheen" in w]


def test_a_missing_image_reads_magenta_at_every_point(addon):
    """An Image Texture whose file is gone reads Cycles' magenta (1, 0, 1) at every point, whatever its
    interpolation and extension and wherever its coordinates fall (before: a 1 x 1 magenta image, which Clip and
    Linear sampling faded to black toward the plane's edges)."""
    from bpy_scenes import render_passes
    from harness.render import configure_restir
    made = []

    def graph(interpolation, extension):
        def wire(tree, socket):
            if not made:
                image = bpy.data.images.new("Gone", 4, 4)
                image.source = "FILE"
                image.filepath = "/nonexistent/gone.png"
                made.append(image)
            tex = _node(tree, "ShaderNodeTexImage", image=made[0], interpolation=interpolation, extension=extension)
            scale = _node(tree, "ShaderNodeVectorMath", operation="SCALE")
            tree.links.new(_node(tree, "ShaderNodeTexCoord").outputs["UV"], scale.inputs[0])
            _set(scale, "Scale", 1.7)
            tree.links.new(scale.outputs[0], tex.inputs["Vector"])
            tree.links.new(tex.outputs["Color"], socket)
        return wire
    cases = [("Linear", "CLIP"), ("Closest", "CLIP"), ("Cubic", "EXTEND"), ("Linear", "REPEAT")]
    scene = node_planes([graph(i, e) for i, e in cases], len(cases), 16)
    configure_restir(scene, 2, 0, 0, integrator="PATH")
    image = render_passes(scene)["Combined"][..., :3]
    inner = image[3:-3].reshape(10, len(cases), 16, 3)[:, :, 3:-3]  # each plane's inside, away from its edges
    np.testing.assert_allclose(inner, np.broadcast_to([1.0, 0.0, 1.0], inner.shape), atol=1e-5)


def test_principled_inputs_not_rendered_are_named(addon):
    """Thin Film and Thin Wall (and Dispersion where the Blender version has it), set on a Principled BSDF, are named
    in one warning each; left at their defaults they are not."""
    def plain(tree, bsdf):
        pass

    def wire(tree, bsdf):
        bsdf.inputs["Thin Film Thickness"].default_value = 400.0
        if "Thin Wall" in bsdf.inputs:
            bsdf.inputs["Thin Wall"].default_value = True
    sc, _ = _principled_plane(plain)
    assert not [w for w in sc.warnings if "Thin" in w]
    sc, _ = _principled_plane(wire)
    named = [w for w in sc.warnings if "Wired" in w and "Thin" in w]
    assert any("Thin Film" in w for w in named), sc.warnings
    assert any("Thin Wall" in w for w in named) or "Thin Wall" not in bpy.data.materials["Wired"].node_tree.nodes[
        "Principled BSDF"].inputs


def test_sky_worlds_render_the_same_in_worker_processes_and_warn_of_nothing(addon):
    """A Sky Texture world (its radiance table, sun disc and the world's sun cone) travels to the workers with the
    scene: the same image, bit for bit, with ReSTIR DI holding the world's samples; the Sky Texture is not named as
    unsupported (every model is rendered)."""
    from bpy_scenes import sky_scene

    from process_runs import one_and_two_processes

    from restir_engine.core.renderer import RenderSettings
    for model in ("MULTIPLE_SCATTERING", "SINGLE_SCATTERING", "PREETHAM", "HOSEK_WILKIE"):
        sky_scene(model, (32, 16), "LIT")
        sc = export_scene(bpy.context.evaluated_depsgraph_get())
        assert not [w for w in sc.warnings if "Sky" in w], sc.warnings
    settings = RenderSettings(integrator="RESTIR", direct_method="RESTIR", world_method="RESAMPLED", samples=2,
                              max_bounces=1, tile_pixels=256)
    sky_scene("MULTIPLE_SCATTERING", (32, 24), "LIT", sun_elevation=0.4)
    sc = export_scene(bpy.context.evaluated_depsgraph_get())
    assert sc.world_graph is not None and len(sc.world_graph.suns) == 1
    one, two = one_and_two_processes(sc, settings)
    assert two.stats["processes"] == 2
    assert one.passes["Combined"][..., :3].mean() > 0.05
    assert np.array_equal(one.passes["Combined"], two.passes["Combined"])
