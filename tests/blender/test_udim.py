"""Images and UV maps beyond the render map's one image: UDIM image sets, each tile read from its own file
(export/udim.py) and sampled where the UVs fall on it, as Cycles does (textures.UdimImage), through an Image Texture
wired straight into a socket and through a node program, with the colour a UV on no tile gets (magenta), checked
against the tiles' known colours and against Cycles; a Normal Map naming a UV map takes that map's tangents."""
import os

import bpy
import numpy as np
import pytest
from bpy_scenes import node_planes, render_passes
from harness.render import configure_cycles, configure_restir
from node_graphs import _node

from restir_engine.export import export_scene

TILES = {1001: (0.8, 0.3, 0.1), 1002: (0.1, 0.4, 0.7)}  # sRGB pixel values of each tile's file
PX = 24


def _linear(c):
    c = np.round(np.asarray(c, np.float64) * 255) / 255  # 8-bit PNG
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def _tiled_image(folder):
    for number, rgb in TILES.items():
        im = bpy.data.images.new(f"tile{number}", 8, 8)
        im.pixels.foreach_set(np.tile(np.array((*rgb, 1.0), np.float32), 64))
        im.filepath_raw = os.path.join(folder, f"udim.{number}.png")
        im.file_format = "PNG"
        im.save()
        bpy.data.images.remove(im)
    image = bpy.data.images.load(os.path.join(folder, "udim.1001.png"))
    image.source = "TILED"
    assert sorted(t.number for t in image.tiles) == sorted(TILES)
    return image


def _scene(folder):
    """Two emission planes whose UV maps span three tiles across (u in [0, 3]): the left one with the set wired
    straight into Emission Color, the right one through a node program (an identity Mapping node on the UVs).
    (Cycles' final renders load only the tiles that a mesh's UV corners lie on where the image reads the UVs
    directly: a face spanning several tiles, or a Mapping that moves UVs onto other tiles, reads magenta there. Here
    each face lies on one tile, as in assets.)"""
    made = []

    def image():  # after node_planes' reset of the file
        if not made:
            made.append(_tiled_image(folder))
        return made[0]

    def straight(tree, socket):
        tex = _node(tree, "ShaderNodeTexImage", image=image())
        tree.links.new(tex.outputs["Color"], socket)

    def stretched(obj):  # three quads across, one per tile (as assets lay their faces out), u = 3 x, v = y
        import bmesh
        bm = bmesh.new()
        bm.from_mesh(obj.data)
        bmesh.ops.subdivide_edges(bm, edges=[e for e in bm.edges if abs(e.verts[0].co.y - e.verts[1].co.y) < 1e-6],
                                  cuts=2, use_grid_fill=True)
        layer = bm.loops.layers.uv["UVMap"]
        for face in bm.faces:
            for loop in face.loops:
                loop[layer].uv = (3 * (loop.vert.co.x + 0.5), loop.vert.co.y + 0.5)
        bm.to_mesh(obj.data)
        bm.free()
    straight.setup = stretched

    def mapped(tree, socket):
        uv = _node(tree, "ShaderNodeTexCoord")
        mapping = _node(tree, "ShaderNodeMapping")
        tex = _node(tree, "ShaderNodeTexImage", image=image())
        tree.links.new(uv.outputs["UV"], mapping.inputs["Vector"])
        tree.links.new(mapping.outputs["Vector"], tex.inputs["Vector"])
        tree.links.new(tex.outputs["Color"], socket)
    mapped.setup = stretched
    return node_planes([straight, mapped], 2, PX, name="Udim")


def _thirds(image):
    """(planes, thirds, 3) mean colour over the inner pixels of each third of each plane (away from tile edges)."""
    top = np.asarray(image)[::-1, :, :3]
    out = []
    for p in range(2):
        plane = top[:, p * PX:(p + 1) * PX]
        third = PX // 3
        out.append([plane[2:-2, k * third + 2:(k + 1) * third - 2].reshape(-1, 3).mean(axis=0) for k in range(3)])
    return np.array(out)


def _imbuf_pixels() -> bool:
    import imbuf
    return hasattr(imbuf.types.ImBuf, "with_buffer")


@pytest.mark.skipif(not _imbuf_pixels(), reason="this Blender's imbuf gives no pixel access (Blender 5.2 does)")
def test_udim_tiles_render_where_their_uvs_fall_as_in_cycles(addon, tmp_path):
    scene = _scene(str(tmp_path))
    exported = export_scene(bpy.context.evaluated_depsgraph_get())
    assert not [w for w in exported.warnings if "UDIM" in w], exported.warnings
    mats = exported.materials
    assert mats.program[mats.names.index("Udim1")] >= 0 and mats.program[mats.names.index("Udim0")] < 0  # both paths
    again = export_scene(bpy.context.evaluated_depsgraph_get()).materials.textures  # the next frame's export
    assert any(t is u for t in mats.textures for u in again)  # the tiles read once, kept while the files stay
    expected = np.array([_linear(TILES[1001]), _linear(TILES[1002]), (1.0, 0.0, 1.0)])
    configure_restir(scene, 4, 0, seed=1, integrator="PATH")
    ours = _thirds(render_passes(scene)["Combined"])
    configure_cycles(scene, 4, 0, seed=1)
    cycles = _thirds(render_passes(scene)["Combined"])
    for plane in range(2):  # the expected colours to within the files' 8-bit rounding; ours as Cycles', exactly
        np.testing.assert_allclose(cycles[plane], expected, atol=0.01, err_msg="Cycles reads the tiles otherwise")
        np.testing.assert_allclose(ours[plane], cycles[plane], atol=1e-3, err_msg=f"plane {plane}")
    # power: the first tile repeated (what was rendered before) differs from the second and third thirds
    assert np.abs(expected[1:] - expected[0]).max(axis=1).min() > 0.1


@pytest.mark.skipif(_imbuf_pixels(), reason="this Blender reads UDIM tiles")
def test_udim_sets_this_blender_cannot_read_are_named(addon, tmp_path):
    _scene(str(tmp_path))
    exported = export_scene(bpy.context.evaluated_depsgraph_get())
    assert [w for w in exported.warnings if "UDIM tiles, which cannot be read here" in w], exported.warnings


def _normal_map_on(uv_map, uvs):
    """An emission plane showing 0.5 + 0.5 n of a constant tangent-space Normal Map (tilted along +T) that names
    the UV map ``uv_map``, which the plane gets with corner UVs ``uvs`` beside its render map."""
    def graph(tree, socket):
        nmap = _node(tree, "ShaderNodeNormalMap", space="TANGENT", uv_map=uv_map)
        nmap.inputs["Color"].default_value = (0.85, 0.5, 0.9, 1.0)
        shown = _node(tree, "ShaderNodeVectorMath", operation="MULTIPLY_ADD")
        shown.inputs[1].default_value = (0.5, 0.5, 0.5)
        shown.inputs[2].default_value = (0.5, 0.5, 0.5)
        tree.links.new(nmap.outputs["Normal"], shown.inputs[0])
        tree.links.new(shown.outputs["Vector"], socket)

    def setup(obj):
        layer = obj.data.uv_layers.new(name=uv_map)
        layer.data.foreach_set("uv", np.array(uvs, np.float32))
        obj.data.uv_layers["UVMap"].active_render = True
    graph.setup = setup
    return graph


def test_a_normal_map_takes_the_tangents_of_the_uv_map_it_names(addon):
    """The tangent frame of the named map (rotated a quarter turn, mirrored), not the render map's: as Cycles."""
    graphs = [_normal_map_on("Rotated", [1, 0, 1, 1, 0, 1, 0, 0]), _normal_map_on("Mirrored", [1, 0, 0, 0, 0, 1, 1, 1]),
              _normal_map_on("Missing", [0, 0, 1, 0, 1, 1, 0, 1])]
    scene = node_planes(graphs, 3, 8, name="NamedUV")
    bpy.data.objects["NamedUVPlane2"].data.uv_layers.remove(bpy.data.objects["NamedUVPlane2"].data.uv_layers["Missing"])
    configure_restir(scene, 1, 0, seed=1, integrator="PATH")
    ours = render_passes(scene)["Combined"][..., :3]
    configure_cycles(scene, 1, 0, seed=1)
    cycles = render_passes(scene)["Combined"][..., :3]
    cells = lambda im: np.asarray(im)[::-1].reshape(1, 8, 3, 8, 3)[:, 2:6, :, 2:6].mean(axis=(0, 1, 3))  # noqa: E731
    np.testing.assert_allclose(cells(ours), cells(cycles), atol=2e-3)
    # power: the three frames tilt the normal three different ways (the render map's frame is the third plane's)
    c = cells(cycles)
    assert min(np.abs(c[0] - c[2]).max(), np.abs(c[1] - c[2]).max(), np.abs(c[0] - c[1]).max()) > 0.1
