"""Bump node: the perturbed normal against its closed form, and the export of Bump (and Bump over Normal Map)."""
from types import SimpleNamespace

import numpy as np
import pytest

from restir_engine.core.materials.image_normals import bump_map
from restir_engine.core.materials.textures import NearestImage, gradient


def ramp(w=8, h=4, step=0.1):
    """An image whose first channel rises by ``step`` per texel along u: dH/du = step * w inside."""
    img = np.zeros((h, w, 3), np.float32)
    img[...] = (np.arange(w, dtype=np.float32) * step)[None, :, None]
    return img


def test_gradient_is_the_derivative_of_the_bilinear_interpolation():
    img = ramp()
    uv = np.array([[0.3, 0.5], [0.55, 0.2]], np.float32)
    g = gradient(img, uv)
    assert np.allclose(g[:, 0], 0.1 * 8, atol=1e-5) and np.allclose(g[:, 1], 0.0, atol=1e-6)
    assert np.allclose(gradient(img.view(NearestImage), uv), 0.0)  # Closest: piecewise constant


@pytest.mark.parametrize("mirror", [False, True])
@pytest.mark.parametrize("strength", [1.0, 0.5])
def test_bump_normal_matches_the_closed_form(mirror, strength):
    """A triangle in z = 0 whose u runs along x over L = 2 m (or mirrored): H(u) = 0.8 u (ramp), so the surface
    gradient is ±0.4 / m along x and N' = normalize(N - d ∇H), mixed with N by the strength."""
    L, d = 2.0, 0.5
    verts = np.array([[[0, 0, 0], [L, 0, 0], [0, L, 0]]], np.float32)
    u_of_x = (lambda x: 1 - x / L) if mirror else (lambda x: x / L)
    uvs = np.array([[[u_of_x(0), 0], [u_of_x(L), 0], [u_of_x(0), 1]]], np.float32)
    uvs[..., 0] = 0.2 + 0.6 * uvs[..., 0]  # keep inside the ramp (no wrap): dH/dx = 0.8 * 0.6 / L
    geom = SimpleNamespace(verts=verts, uvs=uvs)
    mats = SimpleNamespace(bump_tex=np.array([0]), bump_distance=np.array([d], np.float32),
                           bump_strength=np.array([strength], np.float32), textures=[ramp()])
    n = np.array([[0.0], [0.0], [1.0]], np.float32)
    got = bump_map(mats, geom, np.array([0]), np.array([0]), np.array([0.3], np.float32),
                   np.array([0.3], np.float32), n, np.array([0]))[:, 0]
    grad_x = 0.8 * 0.6 / L * (-1 if mirror else 1)
    full = np.array([-d * grad_x, 0.0, 1.0])
    full /= np.linalg.norm(full)
    want = strength * full + (1 - strength) * np.array([0.0, 0.0, 1.0])
    assert np.allclose(got, want / np.linalg.norm(want), atol=1e-5)


def test_bump_and_bump_over_normal_map_are_exported(addon):
    from bpy_scenes import bump_normal_image, principled, ridge_height_image
    from restir_engine.export.materials import MaterialRegistry
    mat = principled("Bump over map", (0.5, 0.5, 0.5))
    tree = mat.node_tree
    height = tree.nodes.new("ShaderNodeTexImage")
    height.image = ridge_height_image("Heights 2")
    bump = tree.nodes.new("ShaderNodeBump")
    bump.inputs["Strength"].default_value = 0.7
    bump.inputs["Distance"].default_value = 0.2
    bump.invert = True
    tree.links.new(height.outputs["Color"], bump.inputs["Height"])
    tree.links.new(bump.outputs["Normal"], tree.nodes["Principled BSDF"].inputs["Normal"])
    warnings = []
    reg = MaterialRegistry(warnings)
    row = reg.rows[reg.material_index(mat)]
    assert row["bump_tex"] >= 0 and row["bump_strength"] == pytest.approx(0.7)
    assert row["bump_distance"] == pytest.approx(-0.2) and row.get("normal_tex", -1) < 0 and not warnings
    nmap_tex = tree.nodes.new("ShaderNodeTexImage")
    nmap_tex.image = bump_normal_image("Bumps 2")
    nmap = tree.nodes.new("ShaderNodeNormalMap")
    tree.links.new(nmap_tex.outputs["Color"], nmap.inputs["Color"])
    tree.links.new(nmap.outputs["Normal"], bump.inputs["Normal"])
    reg = MaterialRegistry(warnings)
    row = reg.rows[reg.material_index(mat)]
    assert row["bump_tex"] >= 0 and row["normal_tex"] >= 0 and not warnings
    assert reg.uses_textures([reg.index[mat.name_full]]) and reg.uses_normal_maps([reg.index[mat.name_full]])
    tree.links.remove(height.outputs["Color"].links[0])
    noise = tree.nodes.new("ShaderNodeTexNoise")
    tree.links.new(noise.outputs["Fac"], bump.inputs["Height"])
    reg = MaterialRegistry(warnings)
    row = reg.rows[reg.material_index(mat)]
    # a procedural height: the whole Normal input becomes the node program's normal (Bump of Noise over the
    # image's Normal Map), which needs the UV tangents
    assert row.get("bump_tex", -1) < 0 and row.get("normal_tex", -1) < 0 and not warnings
    assert "normal" in row["program"].outputs and "tangent_uv" in row["program"].reads
    assert reg.uses_normal_maps([reg.index[mat.name_full]])
