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
        v = _node(tree, "ShaderNodeWireframe")
        tree.links.new(v.outputs["Fac"], bsdf.inputs["Base Color"])
    sc, _ = _principled_plane(wire)
    i = sc.materials.names.index("Wired")
    prog = sc.materials.programs[sc.materials.program[i]]
    assert set(prog.outputs) == {"roughness"}  # the Wireframe node is not supported: a constant, reported
    assert any("Wireframe" in w and "not supported" in w for w in sc.warnings)


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
