"""The film's pixel filter against Cycles (same bpy, CPU): emission checkers with hard edges, rendered with
Blackman-Harris and Gaussian filters in both engines, compared pixel by pixel.

Each pixel agrees when |ours - Cycles| <= 5 SE + 0.5 % of Cycles + 1e-3 (SE: Welch over the seeds: ours 16 seeds
at 16 samples, Cycles 4 at 256, as Cycles' own sample pattern is off on pixel-aligned edges at 16 samples; 1e-3:
float32 arithmetic). Power: our one-pixel box image must fail against each filtered reference in at least a tenth
of the pixels, so the test sees the filter.
"""
import numpy as np
import pytest
from bpy_scenes import node_planes
from cycles_compare import cycles_reference, ours_cells
from node_graphs import checker
from stats import MARGIN, Z_MAX

FLOAT_TOL = 1e-3
FILTERS = [("BLACKMAN_HARRIS", 1.5), ("GAUSSIAN", 2.0), ("BLACKMAN_HARRIS", 3.0)]


def _pixels(images):
    return np.asarray(images, np.float64).mean(axis=3).reshape(len(images), -1)


def _within(ours, ref):
    ma, mb = ours.mean(axis=0), ref.mean(axis=0)
    se = np.sqrt(ours.var(axis=0, ddof=1) / len(ours) + ref.var(axis=0, ddof=1) / len(ref))
    return np.abs(ma - mb) <= Z_MAX * se + MARGIN * np.abs(mb) + FLOAT_TOL


def _build():
    return node_planes([checker(3.0), checker(5.0)], 2, 24, name="Film")


@pytest.mark.parametrize("kind,width", FILTERS)
def test_pixel_filter_matches_cycles(addon, kind, width):
    def build():
        scene = _build()
        scene.cycles.pixel_filter_type = kind
        scene.cycles.filter_width = width
        return scene
    ours = ours_cells(build, 0, 16, _pixels, reps=16, integrator="PATH", pixel_filter=kind, filter_width=width)
    ref = _filtered_cycles(f"film_{kind.lower()}_{width}", build, kind, width)
    ok = _within(ours, ref)
    assert ok.all(), f"{(~ok).sum()} of {ok.size} pixels differ; worst |Δ| {np.abs(ours.mean(0) - ref.mean(0)).max():.4f}"
    box = ours_cells(build, 0, 16, _pixels, reps=16, integrator="PATH", pixel_filter="BOX")
    seen = ~_within(box, ref)
    assert seen.mean() > 0.1, f"a box filter differs from {kind} {width} in only {seen.mean():.1%} of the pixels"


def _filtered_cycles(case, build, kind, width):
    """Cycles' renders (4 seeds, 256 samples) with the filter set after configure_cycles' box."""
    import cycles_reference as refs
    from bpy_scenes import configure_cycles, render_passes

    def configure(scene, seed):
        configure_cycles(scene, 256, 0, seed)
        scene.cycles.pixel_filter_type = kind
        scene.cycles.filter_width = width
    return refs.cycles_cells(case, build, configure, lambda s: render_passes(s)["Combined"][..., :3], _pixels, 4,
                             256, 0)


DOF_CASES = {"disk": dict(blades=0, rotation=0.0, ratio=1.0), "hexagon": dict(blades=6, rotation=0.4, ratio=1.6)}


def dof_scene(size, aperture):
    """The lit node-materials scene (bpy_scenes.node_materials_scene) through a 35 mm lens at f/0.1 focused on
    the left sphere: the floor's checker, the other sphere and the textured quad light blur."""
    from bpy_scenes import node_materials_scene
    scene = node_materials_scene(size)
    dof = scene.camera.data.dof
    dof.use_dof = True
    dof.focus_distance = 3.6
    dof.aperture_fstop = 0.1
    dof.aperture_blades = aperture["blades"]
    dof.aperture_rotation = aperture["rotation"]
    dof.aperture_ratio = aperture["ratio"]
    return scene


@pytest.mark.parametrize("aperture", sorted(DOF_CASES))
@pytest.mark.parametrize("method", ["PATH", "RESTIR_DI"])
def test_depth_of_field_matches_cycles(addon, method, aperture):
    """Thin-lens depth of field (disk, and a rotated hexagon squeezed by the aperture ratio), 1 bounce, 8 x 8
    image cells against Cycles with the materials tests' bound (tests/stats.py); ReSTIR DI in its unbiased mode
    with temporal and spatial reuse; the pinhole image must fail in 3 cells or more (the test sees the blur)."""
    from stats import assert_cells_match, cell_means, image_cells
    size = (96, 64)
    masks = image_cells(size, 8)
    shape = DOF_CASES[aperture]
    settings = {"integrator": "PATH"} if method == "PATH" else {
        "integrator": "RESTIR", "direct_method": "RESTIR", "bias_correction": "UNBIASED", "temporal_reuse": True,
        "spatial_neighbors": 5}
    reduce = lambda im: cell_means(im, masks)  # noqa: E731
    ours = ours_cells(lambda: dof_scene(size, shape), 1, 32, reduce, **settings)
    ref = cycles_reference(f"dof_{aperture}_b1", lambda: dof_scene(size, shape), 1, 128, reduce)
    names = [f"cell {i}" for i in range(len(masks))]
    lit = [i for i in range(len(masks)) if ref.mean(0)[i] > 0.02]
    assert_cells_match(ours[:, lit], ref[:, lit], [names[i] for i in lit])
    if method == "PATH":
        def pinhole():
            scene = dof_scene(size, shape)
            scene.camera.data.dof.use_dof = False
            return scene
        sharp = ours_cells(pinhole, 1, 32, reduce, **settings)  # 16 seeds: 4 leave the count near its bound
        se = np.sqrt(sharp.var(0, ddof=1) / len(sharp) + ref.var(0, ddof=1) / len(ref))
        with np.errstate(invalid="ignore", divide="ignore"):  # black cells (outside ``lit``) read 0 / 0
            z = np.abs(sharp.mean(0) - ref.mean(0)) / se
        assert (z[lit] > Z_MAX).sum() >= 3, "the pinhole image is not told apart from the blurred one"
