"""Materials against Cycles (same bpy, CPU): the Principled BSDF at every view angle, Glossy and Diffuse BSDFs.

Scenes (tests/bpy_scenes.py): a 6 x 4 grid of spheres (SPHERE_GRID: Principled dielectrics at roughness 0.1-1,
IOR 1.2/1.5/2.0, Specular IOR Level 0/0.5/1, Specular Tint; metals at roughness 0.1-1 and a tinted metal; Glossy
BSDFs; a Diffuse BSDF; a half-metal; a white and a black dielectric) lit by an area light or an emissive quad, and
a floor of four materials seen at grazing angles by a low camera. Each side renders 16 independent seeds (Cycles'
from the stored reference, tests/cycles_reference.py); per
sphere (its pixels only) or per floor cell the means are compared with Welch z-scores, with the bound of
tests/cycles/test_cycles_accuracy.py: |ours - Cycles| < 5 SE + 0.5 % of Cycles (two-sided p ≈ 2e-5 per cell at
the SE bound; the margin is 4x tighter than the 2 % the materials issue asks for).

Power: the cells that isolate a lobe (diffuse, the layered diffuse of a white dielectric, the dielectric specular
of a black one, rough metals, a Glossy BSDF, rough dielectrics of IOR 1.2 and 2.0) must each have a bound tighter
than a 3 % error: |1.03 x - x| > 5 SE + 0.5 % at the cell's mean x (relative SE below about 0.5 %), so a 3 % error
in any of those lobes fails at least half the time, and almost surely where the SE is well inside that. (The check
once scaled the *measured* mean by 1.03, which made it fail by chance where that mean fell 2-3 SE below Cycles'.)
Before the Cycles layering (diffuse weighted by 1 - Schlick(f0, cos θ_view)) the floor's rough dielectrics read
38 % dark in the far cells and spheres were off by up to 8 % (docs/RESULTS.md "Principled BSDF").
"""
import numpy as np
import pytest
from bpy_scenes import SPHERE_GRID, alpha_scene, grazing_floor, material_spheres, tinted_scene
from cycles_compare import cycles_reference, ours_cells
from stats import assert_cells_match, cell_means, image_cells

ROWS, COLS = len(SPHERE_GRID), len(SPHERE_GRID[0])
SIZE = (144, 96)
# (row, col) of the cells that isolate one lobe each (see the module docstring)
LOBE_CELLS = {"diffuse": (3, 2), "layered diffuse": (3, 4), "dielectric specular": (3, 5), "metal 0.5": (1, 2),
              "metal 1.0": (1, 4), "glossy": (3, 1), "IOR 1.2": (2, 1), "IOR 2.0": (2, 3)}
TRANSPARENT = 32  # Cycles' transparent bounces: cut-outs pass up to 32 transparent points in ours


def sphere_masks(size=SIZE):
    """(rows*COLS, h, w) bool: the pixels inside each sphere (orthographic camera, 6 units across, radius 0.4,
    half a pixel in from the silhouette; rows = height / cell size), row 0 of the image at the top."""
    w, h = size
    rows = h * COLS // w
    yy, xx = np.mgrid[0:h, 0:w] + 0.5
    r = 0.4 * w / COLS - 0.5
    return np.array([(yy - (i + 0.5) * h / rows) ** 2 + (xx - (j + 0.5) * w / COLS) ** 2 < r * r
                     for i in range(rows) for j in range(COLS)])


def by_masks(masks):
    return lambda images: cell_means(images, masks)


def both(case, build, bounces, ours_samples, cycles_samples, reduce, **settings):
    """((REPS, cells) ours, (REPS, cells) Cycles' stored reference ``case``) of ``build()``."""
    ours = ours_cells(build, bounces, ours_samples, reduce, **settings)
    ref = cycles_reference(case, build, bounces, cycles_samples, reduce, transparent_max_bounces=TRANSPARENT)
    return ours, ref


def grid_names():
    return [f"{kind} base {base} roughness {rough} {extra}" for row in SPHERE_GRID for kind, base, rough, extra in row]


POWER = [r * COLS + c for r, c in LOBE_CELLS.values()]


@pytest.mark.parametrize("light,bounces", [("AREA", 0), ("QUAD", 0), ("AREA", 3)])
def test_material_grid_path_tracer_matches_cycles(addon, light, bounces):
    samples = 16 if light == "QUAD" else 32  # the quad lamp's grid has the headroom (power log)
    ours, ref = both(f"spheres_{light.lower()}_b{bounces}", lambda: material_spheres(light, SIZE), bounces, samples, 64,
                     by_masks(sphere_masks()), integrator="PATH")
    assert_cells_match(ours, ref, grid_names(), POWER)


def test_material_grid_restir_di_matches_cycles(addon):
    """ReSTIR DI's target and shading use the same material model: unbiased mode converges to Cycles per sphere."""
    ours, ref = both("spheres_area_b0", lambda: material_spheres("AREA", SIZE), 0, 8, 64, by_masks(sphere_masks()),
                     integrator="RESTIR", direct_method="RESTIR", bias_correction="UNBIASED", temporal_reuse=True,
                     spatial_neighbors=5)
    assert_cells_match(ours, ref, grid_names(), POWER)


def test_grazing_floor_matches_cycles(addon):
    """Rough Principled floors seen at grazing angles (the issue's 11-12 % dark case; 38 % in this scene's far
    cells before the fix): 4 x 4 image cells, the sky cells (black in Cycles) left out; the three rows of floor
    cells below the horizon row must each be able to see a 3 % error."""
    size = (96, 64)
    a, b = both("grazing_floor", lambda: grazing_floor(size), 0, 64, 64, by_masks(image_cells(size)),
                integrator="PATH")
    lit = np.flatnonzero(b.mean(axis=0) > 0.02)
    assert set(range(4, 16)) <= set(lit)
    assert_cells_match(a[:, lit], b[:, lit], [f"cell {k}" for k in lit],
                       power=[i for i, k in enumerate(lit) if k >= 4])


def test_mix_and_add_shaders_match_cycles(addon):
    """Mix (constant factor, an image-texture factor, nested, two Principled BSDFs of different roughness) and Add
    shaders (two BSDFs; Emission + Principled) per sphere against Cycles. Before, the exporter blended the
    components' parameters (reported as an approximation)."""
    from bpy_scenes import MIX_GRID
    size = (144, 24)
    masks = sphere_masks(size)[:len(MIX_GRID[0])]
    ours, ref = both("mix_add", lambda: material_spheres("AREA", size, MIX_GRID), 0, 64, 256, by_masks(masks),
                     integrator="PATH")
    names = [str(spec[:2]) for spec in MIX_GRID[0]]
    assert_cells_match(ours, ref, names, power=[1, 2, 3, 5])


def path_vs_cycles_cells(case, build, bounces, size=(96, 64), samples=64):
    """Per-seed means of the 4 x 4 image cells of ``build(size)`` rendered by our path tracer (``samples``) and by
    Cycles (128, the stored reference ``case``): ((REPS, 16), (REPS, 16))."""
    return both(case, lambda: build(size), bounces, samples, 128, by_masks(image_cells(size)), integrator="PATH")


def test_alpha_cutouts_match_cycles(addon):
    """Principled Alpha 0.4 and a Mix(Transparent, Diffuse) whose factor is a checker image (Closest
    interpolation), seen by the camera in front of a wall and casting shadows: camera, shadow and (with the wall
    behind) every ray passes the transparent points as Cycles' transparency does, per 4 x 4 image cell."""
    assert_cells_match(*path_vs_cycles_cells("alpha_cutouts", alpha_scene, 0, samples=16), [f"cell {k}" for k in range(16)],
                       power=range(16))


def rgb_cells(masks):
    """Per-seed means of each channel over each mask: (k, 3 x cells), red cells first."""
    return lambda images: np.concatenate([cell_means(images[..., [ch]], masks) for ch in range(3)], axis=1)


def test_light_path_ray_types_match_cycles(addon):
    """Surfaces coloured by the ray that reaches them (bpy_scenes.light_path_types_scene: Is Glossy / Singular /
    Reflection / Transmission / Diffuse Ray, Ray Depth, Diffuse / Glossy / Transmission Depth on the floor and two
    walls), seen directly, in mirror, glass and rough metal spheres and through diffuse bounces, 3 bounces, the path
    tracer (the paths carry their Light Path state: integrators/path_state.py): per 4 x 4 image cell and channel
    against Cycles, every cell able to see a 3 % error but the glass sphere's green and blue (cell 6: rel SE 0.5 %).
    (Before, every non-camera hit read as a diffuse reflection of depth 1: the spheres' reflections of the floor
    lacked its red, the glass's view its blue.)"""
    from bpy_scenes import light_path_types_scene
    size = (96, 64)
    ours, ref = both("light_path_types", lambda: light_path_types_scene(size), 3, 64, 128, rgb_cells(image_cells(size)),
                     integrator="PATH")
    names = [f"{c} cell {k}" for c in "RGB" for k in range(16)]
    assert_cells_match(ours, ref, names, power=[i for i in range(48) if i not in (22, 38)])


def test_light_path_cut_outs_match_cycles(addon):
    """A surface hidden from shadow rays (Mix with a Transparent BSDF by Is Shadow Ray: seen, casting no shadow) and
    one hidden from camera rays (by Is Camera Ray: unseen, casting its shadow), as Cycles: the cut-out's alpha is
    its node program's as the ray that meets it sees it (tests/bpy_scenes.light_path_scene); per 4 x 4 image cell
    against Cycles, direct light, the path tracer; every lit cell able to see a 3 % error. (Before, Is Shadow Ray
    read 0 and camera rays read Is Camera Ray 0 at cut-outs: the red plane cast its shadow and the blue one showed.)"""
    from bpy_scenes import light_path_scene
    ours, ref = path_vs_cycles_cells("light_path_cutouts", light_path_scene, 0, samples=16)
    lit = [k for k in range(16) if ref.mean(0)[k] > 0.02]
    assert len(lit) >= 12
    assert_cells_match(ours, ref, [f"cell {k}" for k in range(16)], power=lit)


@pytest.mark.parametrize("method", ["PATH", "RESTIR"])
def test_coloured_transparency_matches_cycles(addon, method):
    """A red Transparent BSDF and a Mix of a Diffuse with a Transparent BSDF whose Color varies along the plane
    (tests/bpy_scenes.tinted_scene): the wall seen through them and their shadows on the floor take their colour,
    as Cycles' transparency passes it (camera, shadow and bounce rays keep the tint of every transparent point they
    pass). Per 4 x 4 image cell and channel against Cycles: the path tracer at 1 bounce, and ReSTIR DI unbiased
    (its shadow rays' transmittance); every cell not dark in a channel able to see a 3 % error there. (Before,
    the tint was dropped: white transparency.)"""
    size = (96, 64)
    names = [f"{ch} cell {k}" for ch in "RGB" for k in range(16)]
    if method == "PATH":
        ours, ref = both("tinted_b1", lambda: tinted_scene(size), 1, 16, 128, rgb_cells(image_cells(size)),
                         integrator="PATH")
    else:
        ours, ref = both("tinted_b0", lambda: tinted_scene(size), 0, 8, 128, rgb_cells(image_cells(size)),
                         integrator="RESTIR", direct_method="RESTIR", bias_correction="UNBIASED",
                         temporal_reuse=True, spatial_neighbors=5)
    lit = [k for k in range(len(names)) if ref.mean(0)[k] > 0.02]
    assert_cells_match(ours, ref, names, power=lit)


def test_transparent_shadows_off_matches_cycles(addon):
    """A sheet and a box of Alpha 0.5 whose Transparent Shadows setting is off (bpy_scenes.shadowless_veils_scene):
    the lamp's shadow rays are blocked by them as if opaque, while the constant world's light, which Cycles gathers
    with rays bouncing off the surfaces, passes them as transparent. Per 4 x 4 image cell against Cycles, direct
    light, the path tracer; every lit cell able to see a 3 % error. (Before, the world's shadow rays were blocked
    too: cells under the sheet read 1.2 % dark here, and the glTF add-on's vertex-colour file up to 11 %.)"""
    from bpy_scenes import shadowless_veils_scene
    size = (96, 64)
    names = [f"cell {k}" for k in range(16)]
    ours, ref = both("shadowless_veils", lambda: shadowless_veils_scene(size), 0, 16, 128, by_masks(image_cells(size)),
                     integrator="PATH")
    lit = [k for k in range(16) if ref.mean(0)[k] > 0.02]
    assert len(lit) >= 12
    assert_cells_match(ours, ref, names, power=lit)


@pytest.mark.parametrize("kind,bounces", [("IMAGE", 0), ("CONSTANT", 0), ("IMAGE", 3)])
def test_world_light_matches_cycles(addon, kind, bounces):
    """Spheres and a floor lit only by the world: an environment image (a sky with a small sun, made by the test,
    rotated by a Mapping node) or a constant colour, light-sampled (core/lights/world.py) with MIS; per 4 x 4 image cell,
    every cell below the horizon able to see a 3 % error except cell 7: the metal sphere's rim reflecting the sky,
    where ours reads ~1.2 % low (z ≈ 3 in 24 seeds; Cycles bends a smooth normal at silhouettes where we bend the
    view vector, docs/CONVENTIONS.md), inside the bound but too close to it for that power."""
    from bpy_scenes import world_scene
    cells = path_vs_cycles_cells(f"world_{kind.lower()}_b{bounces}", lambda size: world_scene(kind, size, rotation_z=0.8),
                                 bounces)
    assert_cells_match(*cells, [f"cell {k}" for k in range(16)], power=[4, 5, 6] + list(range(8, 16)))


@pytest.mark.parametrize("kind", ["GRADIENT", "MIXED", "CAMERA_RAY"])
def test_world_node_graphs_match_cycles(addon, kind):
    """A world whose Background is a node graph of the direction (a Color Ramp sky with a Math strength; the sky
    image multiplied by a colour through a Noise; the image lighting the scene behind a flat backdrop for camera
    rays, by Light Path > Is Camera Ray), evaluated over an equirectangular image at export
    (export/world.py), seen and lighting the spheres, 1 bounce: per 4 x 4 image cell, every cell able to see a 3 %
    error where it is not dark."""
    from bpy_scenes import world_scene
    ours, ref = path_vs_cycles_cells(f"world_{kind.lower()}_b1", lambda size: world_scene(kind, size), 1,
                                     samples=16 if kind == "GRADIENT" else 64)
    bright = [k for k in range(16) if ref.mean(0)[k] > 0.02]
    assert_cells_match(ours, ref, [f"cell {k}" for k in range(16)], power=bright)


def test_world_in_reservoirs_matches_cycles(addon):
    """The environment-image world of :func:`test_world_light_matches_cycles` with ReSTIR DI holding the world's
    samples in its reservoirs (World Light Resampled, spatial reuse; core/lights/world_points.py), direct light: per 4 x 4
    image cell against Cycles, the same cells able to see a 3 % error."""
    from bpy_scenes import world_scene
    size = (96, 64)
    ours, ref = both("world_image_b0", lambda: world_scene("IMAGE", size, rotation_z=0.8), 0, 32, 128,
                     by_masks(image_cells(size)), direct_method="RESTIR", world_method="RESAMPLED")
    assert_cells_match(ours, ref, [f"cell {k}" for k in range(16)], power=[4, 5, 6] + list(range(8, 16)))


def test_normal_maps_match_cycles(addon):
    """Tangent-space Normal Map nodes (strength 1 on the floor, 0.5 on a wall whose UVs run another way) on
    Principled BSDFs, lit at grazing angles: Cycles' bump-map correction (the diffuse lobe's shadowing term and the
    hemisphere test against the unmapped normal) and its valid-reflection normal for the specular lobes are
    modelled; per 4 x 4 image cell, every cell able to see a 3 % error. (Before those two corrections the cells
    read 2-9 % bright; on a normal-mapped sphere, which this test leaves out, one cell still reads 0.65 % high,
    docs/RESULTS.md.)"""
    from bpy_scenes import normal_map_scene
    assert_cells_match(*path_vs_cycles_cells("normal_maps", normal_map_scene, 0, samples=24), [f"cell {k}" for k in range(16)],
                       power=range(16))


def test_bump_maps_match_cycles(addon):
    """Bump nodes on a height map of ridges (floor: strength 1; wall: strength 0.5, inverted) on Principled BSDFs,
    lit at grazing angles: per 4 x 4 image cell, every cell able to see a 3 % error. Cycles differentiates the
    height over a tenth of a pixel's footprint (Filter Width 0.1), we exactly along the UVs; a central difference
    one texel apart instead (2.5 % weaker slopes at 16 texels per ridge) read up to 2 % off in 5 cells."""
    from bpy_scenes import bump_scene
    assert_cells_match(*path_vs_cycles_cells("bump_maps", bump_scene, 0, samples=16), [f"cell {k}" for k in range(16)], power=range(16))


@pytest.mark.parametrize("integrator,window", [("PATH", False), ("RESTIR", False), ("RESTIR", True)])
def test_smooth_glass_matches_cycles(addon, integrator, window):
    """Smooth glass spheres (a Glass BSDF, a tinted Principled with Transmission 1, a half-transmissive red
    Principled) before a checkered wall, 4 bounces: refraction, reflection, total internal reflection and the
    caustics under them (BSDF paths through delta interfaces hitting the lamp), by the path tracer and by the
    default integrator (camera paths continue through the glass to the surface behind, where resampling runs,
    with the bounces they have left), also with a glass pane across the lower half of the view; per 4 x 4 image
    cell, every cell able to see a 3 % error except cells 8-10 (the spheres' caustics: rel SE 0.4-0.6 %, so
    5 SE + 0.5 % reaches 3 %) and cell 11 (the half-transmissive sphere, whose roughness-0 dielectric layer reads
    0.7-1.0 % low, |z| up to 3.4, not yet explained: inside the bound but too close to it for that power); they
    are held to the bound only. (With Base Color tinting each crossing instead of
    its square root, as Cycles' Principled does, the tinted sphere's cells read 4 % dark.)"""
    from bpy_scenes import glass_scene
    size = (96, 64)
    kw = {"integrator": "PATH"} if integrator == "PATH" else {}
    ours, ref = both("glass_smooth_window" if window else "glass_smooth", lambda: glass_scene(size, window=window), 4,
                     64, 128, by_masks(image_cells(size)), **kw)
    assert_cells_match(ours, ref, [f"cell {k}" for k in range(16)],
                       power=[k for k in range(16) if k not in (8, 9, 10, 11)])


@pytest.mark.parametrize("integrator", ["PATH", "RESTIR"])
def test_rough_glass_matches_cycles(addon, integrator):
    """The glass spheres rough: a Glass BSDF at roughness 0.3, the tinted Principled at 0.2 and the half-transmissive
    one at 0.5 (Multiscatter GGX, Blender's default: the interface scaled by 1/E, its directional albedo), 4 bounces,
    by the path tracer and by the default integrator (camera paths continue through rough glass as through smooth);
    per 4 x 4 image cell, every cell but the caustics' (8-11, rel SE up to 0.8 %) able to see a 3 % error. Without
    the 1/E compensation each crossing would keep only E of the light: 0.86-1.0 at roughness 0.3 and 0.67-0.99 at 0.5
    (entering, IOR 1.45-1.5, from grazing to normal incidence)."""
    from bpy_scenes import glass_scene
    size = (96, 64)
    kw = {"integrator": "PATH"} if integrator == "PATH" else {}
    rough = (0.3, 0.2, 0.5)
    # the path tracer at twice the smooth test's samples (at 64 spp the Glass BSDF sphere's cell had rel SE 0.4 %,
    # where 5 SE + 0.5 % no longer sees a 3 % error); the defaults (ReSTIR DI, whose paths light-sample rough
    # glass) at 64: their power-log share of the allowed SE was 0.41 at 128
    samples = 128 if integrator == "PATH" else 64
    ours, ref = both("glass_rough", lambda: glass_scene(size, roughness=rough), 4, samples, 256,
                     by_masks(image_cells(size)), **kw)
    assert_cells_match(ours, ref, [f"cell {k}" for k in range(16)],
                       power=[k for k in range(16) if k not in (8, 9, 10, 11)])


def test_rough_diffuse_matches_cycles(addon):
    """Diffuse BSDF Roughness 0.3 / 0.6 / 1 and Principled Diffuse Roughness 0.5 / 1: Cycles' energy-preserving
    Oren–Nayar, per sphere, each able to see a 3 % error (rendered as Lambert before: -2.4 % to +3.8 %)."""
    from bpy_scenes import ROUGH_DIFFUSE_GRID
    size = (144, 24)
    masks = sphere_masks(size)[:len(ROUGH_DIFFUSE_GRID[0])]
    ours, ref = both("rough_diffuse", lambda: material_spheres("AREA", size, ROUGH_DIFFUSE_GRID), 0, 8, 64,
                     by_masks(masks), integrator="PATH")
    names = [f"{k} roughness {r} {e}" for k, _c, r, e in ROUGH_DIFFUSE_GRID[0]]
    assert_cells_match(ours, ref, names, power=range(6))


def test_principled_coat_matches_cycles(addon):
    """Principled Coat (tests/bpy_scenes.COAT_GRID: clear, tinted, over metal, the coat alone, IOR 1.3 at half
    weight, inside a Mix shader) per sphere against Cycles, the path tracer and ReSTIR DI unbiased, every sphere able
    to see a 3 % error. Before, the coat was dropped (reported): the coat-only sphere rendered black."""
    from bpy_scenes import COAT_GRID
    size = (144, 24)
    masks = sphere_masks(size)[:len(COAT_GRID[0])]
    names = [str(spec[:2]) for spec in COAT_GRID[0]]
    build = lambda: material_spheres("AREA", size, COAT_GRID)  # noqa: E731
    ours, ref = both("coat", build, 0, 128, 256, by_masks(masks), integrator="PATH")
    assert_cells_match(ours, ref, names, power=range(6))
    ours = ours_cells(build, 0, 64, by_masks(masks), integrator="RESTIR", direct_method="RESTIR",
                      bias_correction="UNBIASED", temporal_reuse=True, spatial_neighbors=5)
    assert_cells_match(ours, ref, names, power=range(6))


def test_coat_graphs_match_cycles(addon):
    """Coats whose inputs come from node graphs or meet other features (tests/bpy_scenes.COAT_GRAPH_GRID: Coat Weight
    and Coat Roughness from Noise Textures, a bumped Normal the coat follows, a bump on the Coat Normal alone,
    emission under a tinted coat, a half-transparent coated base) per sphere against Cycles' path tracer, every
    sphere able to see a 3 % error."""
    from bpy_scenes import COAT_GRAPH_GRID, coat_graph_spheres
    size = (144, 24)
    masks = sphere_masks(size)[:len(COAT_GRAPH_GRID[0])]
    ours, ref = both("coat_graphs", lambda: coat_graph_spheres(size), 0, 64, 256, by_masks(masks),
                     integrator="PATH")
    assert_cells_match(ours, ref, [f"sphere {k}" for k in range(6)], power=range(6))


def test_point_clouds_match_cycles(addon):
    """Point clouds (Geometry Nodes' Mesh to Points, and a PointCloud datablock of three radii where the bpy
    version can make one) render as spheres as in Cycles, with their shadows on the floor: per 4 x 4 image cell
    (the cells that see points or their shadows able to see a 3 % error). Before, a point cloud rendered as
    nothing."""
    from bpy_scenes import point_cloud_scene
    ours, ref = path_vs_cycles_cells("point_clouds", point_cloud_scene, 0, samples=16)
    m = ref.mean(axis=0)
    assert_cells_match(ours, ref, [f"cell {k}" for k in range(16)], power=[k for k in range(16) if m[k] > 0.02])


def test_refraction_bsdf_matches_cycles(addon):
    """Refraction BSDFs (smooth, tinted and rough, IOR 1.2) in front of a checkered wall: the glass interface's
    refraction alone, per 4 x 4 image cell against Cycles (4 bounces, the path tracer); the cells of the spheres
    able to see a 3 % error. Before, a Refraction BSDF rendered as the material's viewport colour."""
    from bpy_scenes import refraction_scene
    size = (96, 64)
    ours, ref = both("refraction", lambda: refraction_scene(size), 4, 128, 256, by_masks(image_cells(size)),
                     integrator="PATH")
    assert_cells_match(ours, ref, [f"cell {k}" for k in range(16)], power=[4, 5, 6, 7, 8, 9, 10, 11])


def test_volume_absorption_matches_cycles(addon):
    """Glass spheres filled with Volume Absorption (amber, blue through a Mix Shader, a dense green inside a
    Principled glass: σa = (1 − Color) x Density per metre, as Cycles), per 4 x 4 image cell against Cycles (4
    bounces, the path tracer; ReSTIR DI as the path tracer treats glass); the cells through the spheres able to see
    a 3 % error. Before, the Volume socket was ignored without a word: the spheres rendered clear."""
    from bpy_scenes import absorbing_glass_scene
    size = (96, 64)
    build = lambda: absorbing_glass_scene(size)  # noqa: E731
    ours, ref = both("volume_absorption", build, 4, 32, 256, by_masks(image_cells(size)), integrator="PATH")
    names = [f"cell {k}" for k in range(16)]
    assert_cells_match(ours, ref, names, power=[4, 5, 6, 7])
    ours = ours_cells(build, 4, 16, by_masks(image_cells(size)), integrator="RESTIR", direct_method="RESTIR",
                      bias_correction="UNBIASED", indirect_method="PATH")
    assert_cells_match(ours, ref, names, power=[5, 6])


def test_beckmann_glass_matches_cycles(addon):
    """Glass BSDFs of the Beckmann distribution (rough 0.3, tinted 0.5, IOR 1.2 at 0.15: Beckmann normals and
    Smith term, no energy compensation, as Cycles), per 4 x 4 image cell (4 bounces, the path tracer), the cells
    through the spheres' upper halves (4-7) able to see a 3 % error (as in the rough glass test, the caustic cells
    8-11 reach rel SE 0.4 %). Before, Beckmann was approximated by Multiscatter GGX (reported)."""
    from bpy_scenes import beckmann_glass_scene
    size = (96, 64)
    # 64 samples: with rough glass light-sampled the power-log share of the allowed SE was 0.42 at 128
    ours, ref = both("glass_beckmann", lambda: beckmann_glass_scene(size), 4, 64, 256, by_masks(image_cells(size)),
                     integrator="PATH")
    assert_cells_match(ours, ref, [f"cell {k}" for k in range(16)], power=[4, 5, 6, 7])


@pytest.mark.parametrize("back", ["AREA", "SUN"])
def test_translucent_bsdf_matches_cycles(addon, back):
    """Translucent BSDFs (white, green, half of a Mix with a Diffuse BSDF, a checker texture) lit from behind by an
    area light the camera does not see or by a sun, and weakly from the front, on a floor lit through them
    (tests/bpy_scenes.translucent_scene), per 4 x 4 image cell against Cycles (2 bounces): with the area light the
    path tracer and ReSTIR DI unbiased, with the sun ReSTIR DI and GI unbiased; the cells of the panels able to see a
    3 % error. Before, a Translucent BSDF rendered as the material's viewport colour, opaque."""
    from bpy_scenes import translucent_scene
    size = (96, 64)
    build = lambda: translucent_scene(size, back)  # noqa: E731
    cells = by_masks(image_cells(size))
    names = [f"cell {k}" for k in range(16)]
    ref = cycles_reference(f"translucent_{back.lower()}", build, 2, 128, cells)
    restir = dict(integrator="RESTIR", direct_method="RESTIR", bias_correction="UNBIASED")
    if back == "AREA":
        assert_cells_match(ours_cells(build, 2, 64, cells, integrator="PATH"), ref, names, power=range(4, 12))
        assert_cells_match(ours_cells(build, 2, 32, cells, indirect_method="PATH", **restir), ref, names,
                           power=range(4, 12))
    else:
        assert_cells_match(ours_cells(build, 2, 16, cells, indirect_method="RESTIR_GI", **restir), ref, names,
                           power=range(4, 12))


def sphere_quadrants(size, count: int):
    """(count * 5, h, w) bool: each of the first ``count`` spheres' pixels (sphere_masks) split into its quadrants
    about the sphere's centre, in the order top-left, top-right, bottom-left, bottom-right (row 0 at the top), then
    the whole spheres."""
    w, h = size
    yy, xx = np.mgrid[0:h, 0:w] + 0.5
    rows = h * COLS // w
    spheres = sphere_masks(size)[:count]
    out = []
    for k, m in enumerate(spheres):
        cy, cx = (k // COLS + 0.5) * h / rows, (k % COLS + 0.5) * w / COLS
        out += [m & ((yy > cy) == bool(qy)) & ((xx > cx) == bool(qx)) for qy in (0, 1) for qx in (0, 1)]
    return np.concatenate([np.array(out), spheres])


def test_anisotropic_ggx_matches_cycles(addon):
    """Anisotropic GGX (tests/bpy_scenes.ANISO_GRID: Principled metals at Anisotropic 0.8 and at 0.5 rotated by
    0.125, a red dielectric at 1, Glossy BSDFs at Anisotropy 0.8 and -0.6 rotated by 0.3, a metal whose Tangent is
    the UV map's) per sphere quadrant (the highlight's shape: ignoring the anisotropy reads 0.17x to 24x Cycles in
    the lit quadrants, as it did before, reported) and per sphere against Cycles, the path tracer and ReSTIR DI
    unbiased (whose target is the isotropic lobe: unbiased all the same), every sphere able to see a 3 % error."""
    from bpy_scenes import ANISO_GRID, aniso_spheres
    size = (288, 48)
    count = len(ANISO_GRID[0])
    cells = by_masks(sphere_quadrants(size, count))
    names = [f"sphere {k // 4} quadrant {k % 4}" for k in range(4 * count)] + [f"sphere {k}" for k in range(count)]
    spheres = range(4 * count, 5 * count)
    build = lambda: aniso_spheres(size)  # noqa: E731
    ours, ref = both("anisotropic", build, 0, 64, 256, cells, integrator="PATH")
    assert_cells_match(ours, ref, names, power=spheres)
    ours = ours_cells(build, 0, 32, cells, integrator="RESTIR", direct_method="RESTIR", bias_correction="UNBIASED",
                      temporal_reuse=True, spatial_neighbors=5)
    assert_cells_match(ours, ref, names, power=spheres)


def test_principled_sheen_matches_cycles_within_its_approximation(addon):
    """Principled Sheen (tests/bpy_scenes.SHEEN_GRID: Weight 1 at Roughness 0.5 and 0.2, a tinted half-weight rough
    sheen, a sheen over a metal, the sheen alone over black, a rough sheen on grey) is core/materials/sheen.py's
    separable lobe of Cycles' measured albedo, layered as Cycles layers it, and named as an approximation. Per
    sphere against Cycles it must stay within the issue's 3 % (+ 5 SE) and recover at least three quarters of what the
    sheen changes (|ours - Cycles| below a quarter of |Cycles without sheen - Cycles|, + 5 SE) on every sphere where
    that change exceeds 3 %. Left out, as before, the spheres read 0.66x to 0.94x Cycles; as a diffuse of the lobe's
    mean albedo up to 1.33x. ReSTIR DI unbiased agrees with our path tracer per sphere (5 SE + 0.5 %)."""
    from bpy_scenes import SHEEN_GRID, sheen_spheres
    size = (144, 24)
    count = len(SHEEN_GRID[0])
    cells = by_masks(sphere_masks(size)[:count])
    ours, ref = both("sheen", lambda: sheen_spheres(size), 0, 128, 64, cells, integrator="PATH")
    bare = cycles_reference("sheen_left_out", lambda: sheen_spheres(size, sheen=False), 0, 64, cells)
    mo, mr, mb = ours.mean(axis=0), ref.mean(axis=0), bare.mean(axis=0)
    se = np.sqrt(ours.var(axis=0, ddof=1) / len(ours) + ref.var(axis=0, ddof=1) / len(ref))
    effect = np.abs(mb - mr)
    matters = effect > 0.03 * mr
    assert matters.sum() >= 4
    report = "\n".join(f"sphere {k}: ours/Cycles {a / c:.4f} (rel SE {e / c:.4f}), without sheen {b / c:.3f}"
                        for k, (a, b, c, e) in enumerate(zip(mo, mb, mr, se)))
    assert (np.abs(mo - mr) < 0.03 * mr + 5 * se).all(), report
    assert (np.abs(mo - mr) < 0.25 * effect + 5 * se)[matters].all(), report
    # power: the sheen left out (Cycles' own image without it) fails the first check on the spheres it matters on
    assert not (np.abs(mb - mr) < 0.03 * mr + 5 * se)[matters].any(), report
    # ReSTIR DI unbiased (its target the lobe's Lambert bound) converges to our path tracer's image of the same lobe
    restir = ours_cells(lambda: sheen_spheres(size), 0, 24, cells, integrator="RESTIR", direct_method="RESTIR",
                        bias_correction="UNBIASED", temporal_reuse=True, spatial_neighbors=5)
    # (power on the sheens over dielectric bases; over the metal (the pick between the two lobes) and alone (its light
    # comes from grazing directions, which neither the light nor the cosine-sampled BSDF candidates favour) both
    # sides keep rel SE 0.5-0.7 % at these samples)
    assert_cells_match(restir, ours, [f"sphere {k}" for k in range(count)], power=[0, 1, 2, 5])


def test_subsurface_matches_cycles(addon):
    """Principled subsurface scattering (tests/bpy_scenes.SSS_GRID: Random Walk spheres of several colours, radii
    and weights, Random Walk (Skin), Subsurface Anisotropy 0.5, a Subsurface Weight from a Noise Texture; each
    Blender series at its own Random Walk, core/integrators/subsurface.py) per sphere against Cycles, with the bound
    of the materials tests (5 SE + 0.5 %) and power on every sphere where the walk changes the image. Rendered as
    the diffuse lobe (the share left in the Base Color, as before) the spheres read 1.03x to 1.75x Cycles (Cycles'
    own image of that) and fail the bound. ReSTIR DI unbiased agrees with Cycles the same way. At two bounces (walks at
    the paths' later vertices too) the path tracer and ReSTIR DI + GI agree with Cycles per image region (the walks'
    light stays outside the reservoirs)."""
    from bpy_scenes import SSS_GRID, subsurface_spheres
    size = (144, 24)
    count = len(SSS_GRID)
    cells = by_masks(sphere_masks(size)[:count])
    names = [f"sphere {k} ({s[-1]})" for k, s in enumerate(SSS_GRID)]
    ours, ref = both("subsurface", lambda: subsurface_spheres(size), 0, 32, 64, cells, integrator="PATH")
    bare = cycles_reference("subsurface_left_out", lambda: subsurface_spheres(size, sss=False), 0, 64, cells)
    mr, mb = ref.mean(axis=0), bare.mean(axis=0)
    matters = np.flatnonzero(np.abs(mb - mr) > 0.03 * mr)
    assert matters.size >= 4
    assert_cells_match(ours, ref, names, power=matters)
    se = np.sqrt(ours.var(axis=0, ddof=1) / len(ours) + ref.var(axis=0, ddof=1) / len(ref))
    assert not (np.abs(mb - mr) < 5 * se + 0.005 * mr)[matters].any()  # the share as diffuse fails
    restir = dict(integrator="RESTIR", direct_method="RESTIR", bias_correction="UNBIASED", temporal_reuse=True,
                  spatial_neighbors=5)
    di = ours_cells(lambda: subsurface_spheres(size), 0, 32, cells, **restir)
    assert_cells_match(di, ref, names, power=matters)
    # two bounces, per image region (the wall sees the spheres' far sides, lit by walks at the path's later
    # vertices; rendering the share there as a diffuse lobe read 0.965x Cycles in the lower regions and 0.98x overall)
    regions = image_cells(size, 4)

    def by_region(images):
        return np.concatenate([images.mean(axis=(1, 2, 3))[:, None], cell_means(images, regions)], axis=1)
    region_names = ["image"] + [f"region {k}" for k in range(len(regions))]
    ours2, ref2 = both("subsurface_bounces", lambda: subsurface_spheres(size), 2, 32, 64, by_region,
                       integrator="PATH")
    assert_cells_match(ours2, ref2, region_names, power=[0, 11, 12, 14, 15, 16])  # where that was 3 % off
    gi = ours_cells(lambda: subsurface_spheres(size), 2, 16, by_region, reps=8, indirect_method="RESTIR_GI",
                    **restir)
    assert_cells_match(gi, ref2, region_names)
