"""Shader nodes inside node groups, and transparency from any node graph, as third-party files build them (the glTF
add-on's materials: a Principled BSDF inside a group, an alpha cut-off by Math nodes, a Mix with a Transparent BSDF
by Backfacing for single-sided surfaces).

Statistics: a cut-out pixel is a Bernoulli draw per sample (the surface is there with probability α at each point),
so a column of H pixels at N samples has mean 1 - α(x) (a white world behind a black surface) with standard error
sqrt(α(1 - α) / (N H)); columns are checked at 5 standard errors (0.005 % false alarms per column)."""
import math

import bpy
import pytest
import numpy as np
from bpy_scenes import _with_uvs, render_passes
from harness.render import configure_restir
from harness.scenes import camera, enable_nodes, plane, reset

from restir_engine.export import export_scene

N, W, H = 64, 32, 8


def _white_world(scene):
    world = bpy.data.worlds.new("White")
    enable_nodes(world)
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (1, 1, 1, 1)
    scene.world = world


def _facing_plane(build, back=False):
    """A plane of the material ``build()`` makes, filling an orthographic camera's W x H view (seen from the front,
    or from behind), in front of a white world."""
    scene = reset()
    _white_world(scene)
    material = build()
    _with_uvs(plane("Sheet", 1.0, (0, 0, 0), material=material, scale=(1.0, H / W, 1.0)))
    if back:
        camera((0, 0, -5), (math.pi, 0, 0), ortho_scale=1.0)
    else:
        camera((0, 0, 5), (0, 0, 0), ortho_scale=1.0)
    scene.render.resolution_x, scene.render.resolution_y = W, H
    configure_restir(scene, N, 1, seed=3, integrator="PATH")
    return scene


def _gradient(tree):
    """A Gradient Texture's Fac over Generated coordinates: x from 0 to 1 across the plane."""
    g = tree.nodes.new("ShaderNodeTexGradient")
    return g.outputs["Fac"]


def _black_principled(tree):
    b = tree.nodes["Principled BSDF"]
    b.inputs["Base Color"].default_value = (0, 0, 0, 1)
    b.inputs["Specular IOR Level"].default_value = 0.0
    return b


def _column_check(img, opacity):
    """Each column's mean against 1 - opacity(x) at 5 standard errors (the world is white behind)."""
    x = (np.arange(W) + 0.5) / W
    a = opacity(x)
    got = img[..., :3].mean(axis=(0, 2))
    se = np.sqrt(np.maximum(a * (1 - a), 1e-4) / (N * H))
    z = (got - (1 - a)) / se
    assert np.abs(z).max() < 5.0, (np.round(got, 3), np.round(1 - a, 3))


def test_principled_alpha_from_a_graph_is_a_cut_out_per_hit(addon):
    """Alpha = Gradient (x across the plane): the plane's opacity follows x; before, a graph on Alpha was folded to
    the socket's value (opaque), 1 - α = 0 everywhere, a z of about 50 at mid-plane."""
    def build():
        mat = bpy.data.materials.new("Ramp")
        enable_nodes(mat)
        t = mat.node_tree
        b = _black_principled(t)
        t.links.new(_gradient(t), b.inputs["Alpha"])
        return mat
    scene = _facing_plane(build)
    _column_check(render_passes(scene)["Combined"], lambda x: x)
    sc = export_scene(bpy.context.evaluated_depsgraph_get())
    i = sc.materials.names.index("Ramp")
    assert sc.materials.alpha_program[i] and "alpha" in sc.materials.programs[sc.materials.program[i]].outputs


def test_transparent_mix_by_a_varying_factor_and_alpha_in_mixes(addon):
    """Mix(Fac = x², Principled (Alpha 0.5, black), Transparent): opacity (1 - x²) x 0.5, the Principled's own
    alpha joining the Transparent BSDF's share."""
    scene = _facing_plane(_veil)
    _column_check(render_passes(scene)["Combined"], lambda x: (1 - x * x) * 0.5)


def _veil():
    mat = bpy.data.materials.new("Veil")
    enable_nodes(mat)
    t = mat.node_tree
    b = _black_principled(t)
    b.inputs["Alpha"].default_value = 0.5
    sq = t.nodes.new("ShaderNodeMath")
    sq.operation = "POWER"
    t.links.new(_gradient(t), sq.inputs[0])
    sq.inputs[1].default_value = 2.0
    mix = t.nodes.new("ShaderNodeMixShader")
    clear = t.nodes.new("ShaderNodeBsdfTransparent")
    t.links.new(sq.outputs[0], mix.inputs["Fac"])
    t.links.new(b.outputs[0], mix.inputs[1])
    t.links.new(clear.outputs[0], mix.inputs[2])
    t.links.new(mix.outputs[0], t.nodes["Material Output"].inputs["Surface"])
    return mat


def test_constant_alpha_inside_a_mix_is_transparent_share(addon):
    """Add(Principled Alpha 0.3, Volume Absorption): as Cycles, the volume adds nothing to the surface and the
    Principled's alpha makes it 70 % see-through (before: rendered opaque with a warning)."""
    scene = _facing_plane(_thin)
    _column_check(render_passes(scene)["Combined"], lambda x: np.full_like(x, 0.3))
    sc = export_scene(bpy.context.evaluated_depsgraph_get())
    assert not [w for w in sc.warnings if "Thin" in w]


def _thin():
    mat = bpy.data.materials.new("Thin")
    enable_nodes(mat)
    t = mat.node_tree
    b = _black_principled(t)
    b.inputs["Alpha"].default_value = 0.3
    vol = t.nodes.new("ShaderNodeVolumeAbsorption")
    add = t.nodes.new("ShaderNodeAddShader")
    t.links.new(b.outputs[0], add.inputs[0])
    t.links.new(vol.outputs[0], add.inputs[1])
    t.links.new(add.outputs[0], t.nodes["Material Output"].inputs["Surface"])
    return mat


def _single_sided():
    """The glTF add-on's single-sided material: Mix(Fac = Backfacing, red Emission, Transparent)."""
    mat = bpy.data.materials.new("OneSided")
    enable_nodes(mat)
    t = mat.node_tree
    t.nodes.remove(t.nodes["Principled BSDF"])
    geo = t.nodes.new("ShaderNodeNewGeometry")
    red = t.nodes.new("ShaderNodeEmission")
    red.inputs["Color"].default_value = (1, 0, 0, 1)
    clear = t.nodes.new("ShaderNodeBsdfTransparent")
    mix = t.nodes.new("ShaderNodeMixShader")
    t.links.new(geo.outputs["Backfacing"], mix.inputs["Fac"])
    t.links.new(red.outputs[0], mix.inputs[1])
    t.links.new(clear.outputs[0], mix.inputs[2])
    t.links.new(mix.outputs[0], t.nodes["Material Output"].inputs["Surface"])
    return mat


def test_backfacing_transparency_shows_one_side(addon):
    """From the front the plane is red emission; from behind it is not there (the white world)."""
    front = render_passes(_facing_plane(_single_sided))["Combined"][..., :3].mean(axis=(0, 1))
    np.testing.assert_allclose(front, (1, 0, 0), atol=1e-4)
    back = render_passes(_facing_plane(_single_sided, back=True))["Combined"][..., :3].mean(axis=(0, 1))
    np.testing.assert_allclose(back, (1, 1, 1), atol=1e-4)


def _grouped_material(name):
    """A Principled BSDF inside a node group: Base Color from a Checker outside (through a group input and a
    reroute inside), Roughness typed on the group node, Metallic set inside, Alpha from a Gradient outside; the
    group's output reaches the Material Output through a reroute."""
    grp = bpy.data.node_groups.new(f"{name}Group", "ShaderNodeTree")
    grp.interface.new_socket("Color", in_out="INPUT", socket_type="NodeSocketColor")
    grp.interface.new_socket("Rough", in_out="INPUT", socket_type="NodeSocketFloat")
    grp.interface.new_socket("Alpha", in_out="INPUT", socket_type="NodeSocketFloat")
    grp.interface.new_socket("BSDF", in_out="OUTPUT", socket_type="NodeSocketShader")
    gi, go = grp.nodes.new("NodeGroupInput"), grp.nodes.new("NodeGroupOutput")
    p = grp.nodes.new("ShaderNodeBsdfPrincipled")
    p.inputs["Metallic"].default_value = 0.7
    rr = grp.nodes.new("NodeReroute")
    grp.links.new(gi.outputs["Color"], rr.inputs[0])
    grp.links.new(rr.outputs[0], p.inputs["Base Color"])
    grp.links.new(gi.outputs["Rough"], p.inputs["Roughness"])
    grp.links.new(gi.outputs["Alpha"], p.inputs["Alpha"])
    grp.links.new(p.outputs[0], go.inputs["BSDF"])
    mat = bpy.data.materials.new(name)
    enable_nodes(mat)
    t = mat.node_tree
    t.nodes.remove(t.nodes["Principled BSDF"])
    node = t.nodes.new("ShaderNodeGroup")
    node.node_tree = grp
    node.inputs["Rough"].default_value = 0.3
    chk = t.nodes.new("ShaderNodeTexChecker")
    chk.inputs["Color1"].default_value = (0.9, 0.1, 0.1, 1)
    chk.inputs["Color2"].default_value = (0.1, 0.2, 0.9, 1)
    t.links.new(chk.outputs["Color"], node.inputs["Color"])
    t.links.new(_gradient(t), node.inputs["Alpha"])
    out_rr = t.nodes.new("NodeReroute")
    t.links.new(node.outputs[0], out_rr.inputs[0])
    t.links.new(out_rr.outputs[0], t.nodes["Material Output"].inputs["Surface"])
    return mat


def _flat_material(name):
    """The same material without the group."""
    mat = bpy.data.materials.new(name)
    enable_nodes(mat)
    t = mat.node_tree
    p = t.nodes["Principled BSDF"]
    p.inputs["Metallic"].default_value = 0.7
    p.inputs["Roughness"].default_value = 0.3
    chk = t.nodes.new("ShaderNodeTexChecker")
    chk.inputs["Color1"].default_value = (0.9, 0.1, 0.1, 1)
    chk.inputs["Color2"].default_value = (0.1, 0.2, 0.9, 1)
    t.links.new(chk.outputs["Color"], p.inputs["Base Color"])
    t.links.new(_gradient(t), p.inputs["Alpha"])
    return mat


def test_shader_node_group_renders_as_its_flat_graph(addon):
    """The grouped material and its flat twin give the same image, bit for bit at the same seed (before: the group
    was 'not supported' and rendered in the viewport colour), and the same rows and program outputs."""
    images, rows = [], []
    for build in (_flat_material, _grouped_material):
        scene = _facing_plane(lambda: build("Lacquer"))
        images.append(render_passes(scene)["Combined"])
        sc = export_scene(bpy.context.evaluated_depsgraph_get())
        i = sc.materials.names.index("Lacquer")
        rows.append((float(sc.materials.metallic[i]), float(sc.materials.roughness[i]),
                     sorted(sc.materials.programs[sc.materials.program[i]].outputs), bool(sc.materials.alpha_program[i])))
        assert not [w for w in sc.warnings if "Lacquer" in w], sc.warnings
    assert rows[0] == rows[1]
    assert abs(rows[0][0] - 0.7) < 1e-6 and abs(rows[0][1] - 0.3) < 1e-6 and rows[0][2] == ["alpha", "base_color"]
    np.testing.assert_array_equal(images[0], images[1])
    assert images[0][..., :3].std() > 0.05  # a pattern, not a flat colour


def test_ambient_occlusion_passes_its_colour_through(addon):
    """Ambient Occlusion (no rays from node programs here) is taken as unoccluded: its Color output is its Color
    input, named in a warning (before: a constant black)."""
    def build():
        mat = bpy.data.materials.new("Occluded")
        enable_nodes(mat)
        t = mat.node_tree
        t.nodes.remove(t.nodes["Principled BSDF"])
        e = t.nodes.new("ShaderNodeEmission")
        ao = t.nodes.new("ShaderNodeAmbientOcclusion")
        ao.inputs["Color"].default_value = (0.2, 0.5, 0.7, 1)
        t.links.new(ao.outputs["Color"], e.inputs["Color"])
        t.links.new(e.outputs[0], t.nodes["Material Output"].inputs["Surface"])
        return mat
    _facing_plane(build)
    sc = export_scene(bpy.context.evaluated_depsgraph_get())
    i = sc.materials.names.index("Occluded")
    np.testing.assert_allclose(sc.materials.emission[i], (0.2, 0.5, 0.7), atol=1e-6)
    assert any("Ambient Occlusion" in w and "unoccluded" in w for w in sc.warnings)


def test_sheen_bsdf_is_named_and_exported_as_a_sheen_lobe(addon):
    """A Sheen BSDF (glTF's sheen, velvet; Microfiber) becomes a sheen row: its Color and Roughness for the separable
    lobe of core/materials/sheen.py (before: a diffuse of the viewport colour, several times too bright; then a
    diffuse of its mean albedo), and is named as an approximation; an Ashikhmin one stays a diffuse of its colour
    times the lobe's mean albedo."""
    from restir_engine.export.sheen import SHEEN_ALBEDO, SHEEN_ROUGHNESS

    def build(name, distribution):
        def make():
            mat = bpy.data.materials.new(name)
            enable_nodes(mat)
            t = mat.node_tree
            t.nodes.remove(t.nodes["Principled BSDF"])
            sh = t.nodes.new("ShaderNodeBsdfSheen")
            sh.distribution = distribution
            sh.inputs["Color"].default_value = (0.9, 0.3, 0.6, 1)
            sh.inputs["Roughness"].default_value = 0.6
            t.links.new(sh.outputs[0], t.nodes["Material Output"].inputs["Surface"])
            return mat
        return make
    _facing_plane(build("Velvet", "MICROFIBER"))
    sc = export_scene(bpy.context.evaluated_depsgraph_get())
    i = sc.materials.names.index("Velvet")
    np.testing.assert_allclose(sc.materials.base_color[i], [0.9, 0.3, 0.6], rtol=1e-5)
    assert abs(float(sc.materials.sheen_roughness[i]) - 0.6) < 1e-6
    assert float(sc.materials.metallic[i]) == 0 and float(sc.materials.f0[i]) == 0
    assert any("Sheen BSDF" in w and "approximated" in w for w in sc.warnings)
    _facing_plane(build("Velvet2", "ASHIKHMIN"))
    sc = export_scene(bpy.context.evaluated_depsgraph_get())
    i = sc.materials.names.index("Velvet2")
    albedo = np.interp(0.6, SHEEN_ROUGHNESS, SHEEN_ALBEDO["ASHIKHMIN"])
    np.testing.assert_allclose(sc.materials.base_color[i], np.array([0.9, 0.3, 0.6]) * albedo, rtol=1e-5)
    assert float(sc.materials.sheen_roughness[i]) == 0


def test_the_output_cycles_renders_is_used(addon):
    """A material with an active EEVEE-only output and an inactive Cycles output renders the Cycles one, as Cycles
    does (the glTF add-on's test files carry such pairs; before: the EEVEE output's shader was used)."""
    def build():
        mat = bpy.data.materials.new("TwoOutputs")
        enable_nodes(mat)
        t = mat.node_tree
        t.nodes.remove(t.nodes["Principled BSDF"])
        eevee = t.nodes["Material Output"]
        eevee.target = "EEVEE"
        red, green = t.nodes.new("ShaderNodeEmission"), t.nodes.new("ShaderNodeEmission")
        red.inputs["Color"].default_value = (1, 0, 0, 1)
        green.inputs["Color"].default_value = (0, 1, 0, 1)
        t.links.new(red.outputs[0], eevee.inputs["Surface"])
        cycles = t.nodes.new("ShaderNodeOutputMaterial")
        cycles.target = "CYCLES"
        t.links.new(green.outputs[0], cycles.inputs["Surface"])
        eevee.is_active_output = True
        return mat
    _facing_plane(build)
    sc = export_scene(bpy.context.evaluated_depsgraph_get())
    i = sc.materials.names.index("TwoOutputs")
    np.testing.assert_allclose(sc.materials.emission[i], (0, 1, 0), atol=1e-6)


def _sunlit_floor():
    """A white diffuse floor (0.8, no specular) under a sun of 1 W/m² straight above (angle 0), a black world and an
    orthographic camera 0.5 above the floor looking down (under anything placed higher), 16 x 16 pixels."""
    from harness.scenes import black_world, light

    scene = reset()
    black_world(scene)
    floor = bpy.data.materials.new("Floor")
    enable_nodes(floor)
    fb = floor.node_tree.nodes["Principled BSDF"]
    fb.inputs["Base Color"].default_value = (0.8, 0.8, 0.8, 1)
    fb.inputs["Specular IOR Level"].default_value = 0.0
    plane("Floor", 4.0, (0, 0, 0), material=floor)
    light("SUN", (0, 0, 5), (0, 0, 0), energy=1.0, angle=0.0)
    camera((0, 0, 0.5), (0, 0, 0), ortho_scale=2.0)
    scene.render.resolution_x, scene.render.resolution_y = 16, 16
    return scene


@pytest.mark.parametrize("transparent_shadows", [True, False])
def test_transparent_shadows_setting(addon, transparent_shadows):
    """A sheet of Alpha 0.5 (above the camera) between a sun straight above and a white diffuse floor: with
    Material > Settings > Transparent Shadows on, half the sun reaches the floor (L = 0.8/π x E x 0.5); off, the
    sheet shadows as if opaque (L = 0), as Cycles (the glTF add-on's vertex-colour file turns it off; before, light
    always passed). Tolerance: 5 standard errors of the image mean (Bernoulli shadow rays)."""
    scene = _sunlit_floor()
    veil = bpy.data.materials.new("Veil")
    enable_nodes(veil)
    veil.node_tree.nodes["Principled BSDF"].inputs["Alpha"].default_value = 0.5
    veil.use_transparent_shadow = transparent_shadows
    plane("Sheet", 8.0, (0, 0, 1), material=veil)
    configure_restir(scene, N, 1, seed=5, integrator="PATH")
    got = float(render_passes(scene)["Combined"][..., :3].mean())
    t = 0.5 if transparent_shadows else 0.0
    full = 0.8 / math.pi
    se = full * math.sqrt(0.25 / (N * 256))
    assert abs(got - full * t) < 5 * se + 1e-6, (got, full * t)


def test_objects_that_cast_no_shadow(addon):
    """Object > Visibility > Ray Visibility > Shadow off: an opaque sheet between the sun and the floor lets the
    whole sun through to the floor (L = 0.8/π x E exactly: no random cut-out here), as Cycles; glossy visibility,
    which is not honoured, is named in a warning."""
    scene = _sunlit_floor()
    sheet = plane("Sheet", 8.0, (0, 0, 1))
    scene.render.resolution_x, scene.render.resolution_y = 8, 8
    configure_restir(scene, 4, 1, seed=5, integrator="PATH")
    assert float(render_passes(scene)["Combined"][..., :3].mean()) < 1e-6  # the sheet's shadow
    sheet.visible_shadow = False
    np.testing.assert_allclose(render_passes(scene)["Combined"][..., :3], 0.8 / math.pi, rtol=1e-4)
    sheet.visible_glossy = False
    sc = export_scene(bpy.context.evaluated_depsgraph_get())
    assert any("Ray Visibility" in w and "Sheet" in w and "glossy" in w for w in sc.warnings)


@pytest.mark.parametrize("integrator", ["PATH", "RESTIR"])
def test_objects_the_camera_does_not_see(addon, integrator):
    """Object > Visibility > Ray Visibility > Camera off: a sheet over the left half of the floor, between the
    camera and the floor, is not seen (Depth is the floor's 0.5 everywhere instead of the sheet's 0.25) and still
    shadows the floor (left half black, right half lit by the sun alone: L = 0.8/π x E, 1 bounce, no random
    cut-out), as Cycles; seen by the camera, it covers the left half (Depth 0.25)."""
    scene = _sunlit_floor()
    sheet = plane("Blocker", 2.0, (-1, 0, 0.25))
    scene.view_layers[0].use_pass_z = True
    configure_restir(scene, 4, 1, seed=5, integrator=integrator)
    seen = render_passes(scene)
    np.testing.assert_allclose(seen["Depth"][:, :8], 0.25, rtol=1e-4)
    sheet.visible_camera = False
    hidden = render_passes(scene)
    np.testing.assert_allclose(hidden["Depth"], 0.5, rtol=1e-4)
    img = hidden["Combined"][..., :3]
    assert float(img[:, :8].max()) < 1e-6  # the floor in the hidden sheet's shadow
    np.testing.assert_allclose(img[:, 8:], 0.8 / math.pi, rtol=1e-3)
    sc = export_scene(bpy.context.evaluated_depsgraph_get())
    assert not any("Ray Visibility" in w for w in sc.warnings)


def test_udim_images_are_named(addon):
    """An image with UDIM tiles (not supported: its first tile repeats over every tile) is named in a warning
    rather than silently wrong."""
    def build():
        image = bpy.data.images.new("Tiles", 8, 8, tiled=True)
        image.tiles.new(1002)
        mat = bpy.data.materials.new("Tiled")
        enable_nodes(mat)
        t = mat.node_tree
        tex = t.nodes.new("ShaderNodeTexImage")
        tex.image = image
        t.links.new(tex.outputs["Color"], t.nodes["Principled BSDF"].inputs["Base Color"])
        return mat
    _facing_plane(build)
    sc = export_scene(bpy.context.evaluated_depsgraph_get())
    assert any("UDIM" in w and "Tiles" in w for w in sc.warnings)


def test_sunlight_through_a_glass_pane(addon):
    """A smooth glass pane (IOR 1.5, 2 cm) between a wide sun (40°, straight above) and a white diffuse floor, the
    camera under the pane: the floor's light comes only from paths through the pane to the sun's disk (its shadow
    rays are blocked by the glass), L = 0.8/π x E x T with T = (1 - R)² (1 + R² + ...) ≈ 0.9231 (R = 0.04 at normal
    incidence; 0.9216 for the paths within the bounce limit, within the tolerance). Before, a ray leaving glass never
    met a sun and the floor was black. Tolerance: 5 standard errors of the image mean (from the pixels' spread)."""
    scene = _sunlit_floor()
    glass = bpy.data.materials.new("Pane")
    enable_nodes(glass)
    t = glass.node_tree
    t.nodes.remove(t.nodes["Principled BSDF"])
    g = t.nodes.new("ShaderNodeBsdfGlass")
    g.inputs["Roughness"].default_value = 0.0
    g.inputs["IOR"].default_value = 1.5
    t.links.new(g.outputs[0], t.nodes["Material Output"].inputs["Surface"])
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(0, 0, 1.01))
    pane = bpy.context.active_object
    pane.scale = (40.0, 40.0, 0.02)
    pane.data.materials.append(glass)
    bpy.data.lights["SUN light"].angle = math.radians(40.0)
    configure_restir(scene, 256, 8, seed=7, integrator="PATH")
    img = render_passes(scene)["Combined"][..., :3].mean(axis=2)
    expected = 0.8 / math.pi * 0.9216
    se = img.std() / math.sqrt(img.size)
    assert abs(img.mean() - expected) < 5 * se + 0.002 * expected, (img.mean(), expected, se)


def _tinted_film(varying: bool):
    """A Transparent BSDF of Color (0.2, 0.5, 0.9), alone; or (``varying``) mixed half and half with a black
    Principled BSDF, its Color (x, 1 - x, 0.5) across the plane (Combine Color of a Gradient)."""
    mat = bpy.data.materials.new("Film")
    enable_nodes(mat)
    t = mat.node_tree
    clear = t.nodes.new("ShaderNodeBsdfTransparent")
    out = t.nodes["Material Output"].inputs["Surface"]
    if not varying:
        t.nodes.remove(t.nodes["Principled BSDF"])
        clear.inputs["Color"].default_value = (0.2, 0.5, 0.9, 1)
        t.links.new(clear.outputs[0], out)
        return mat
    x = _gradient(t)
    inv = t.nodes.new("ShaderNodeMath")
    inv.operation = "SUBTRACT"
    inv.inputs[0].default_value = 1.0
    t.links.new(x, inv.inputs[1])
    rgb = t.nodes.new("ShaderNodeCombineColor")
    t.links.new(x, rgb.inputs[0])
    t.links.new(inv.outputs[0], rgb.inputs[1])
    rgb.inputs[2].default_value = 0.5
    t.links.new(rgb.outputs[0], clear.inputs["Color"])
    mix = t.nodes.new("ShaderNodeMixShader")
    mix.inputs["Fac"].default_value = 0.5
    t.links.new(_black_principled(t).outputs[0], mix.inputs[1])
    t.links.new(clear.outputs[0], mix.inputs[2])
    t.links.new(mix.outputs[0], out)
    return mat


@pytest.mark.parametrize("varying", [False, True])
def test_a_coloured_transparent_bsdf_tints_what_is_seen_through_it(addon, varying):
    """The white world seen through a Transparent BSDF takes its Color: alone (every sample passes: exactly the
    colour), or from a node graph per hit and mixed half with a black surface (per channel and column, mean
    0.5 x colour(x) within 5 standard errors of the Bernoulli cut-out). Before, the colour was dropped with a
    warning (white: z of 20-60 in the red and green columns)."""
    scene = _facing_plane(lambda: _tinted_film(varying))
    img = render_passes(scene)["Combined"][..., :3]
    sc = export_scene(bpy.context.evaluated_depsgraph_get())
    i = sc.materials.names.index("Film")
    assert not [w for w in sc.warnings if "Transparent" in w]
    if not varying:
        np.testing.assert_allclose(img.reshape(-1, 3), np.tile([0.2, 0.5, 0.9], (W * H, 1)), atol=1e-5)
        np.testing.assert_allclose(sc.materials.transparent_tint[i], (0.2, 0.5, 0.9), atol=1e-6)
        return
    assert "transparent_tint" in sc.materials.programs[sc.materials.program[i]].outputs
    x = (np.arange(W) + 0.5) / W
    for ch, tint in enumerate((x, 1 - x, np.full_like(x, 0.5))):
        got = img[..., ch].mean(axis=0)
        se = np.maximum(tint, 0.05) * np.sqrt(0.25 / (N * H))
        z = (got - 0.5 * tint) / se
        assert np.abs(z).max() < 5.0, (ch, np.round(got, 3), np.round(0.5 * tint, 3))
