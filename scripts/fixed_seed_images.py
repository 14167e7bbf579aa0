"""Fixed-seed images of the core (no bpy) over the integrators' branches, for before/after comparisons of changes
that must not change any image (restructuring, speed work).

    python scripts/fixed_seed_images.py out.npz               # render every configuration, save its passes
    python scripts/fixed_seed_images.py --compare a.npz b.npz  # per pass: bit-identical, or the largest difference

Scenes: tests/scenes_core.py's regression room (glossy floor, metal, textured walls, coloured emitters, a sun, an
open side to a grey world), the same room with a glass pane, the bounce room (indirect light only) and a plane under
an environment world; each configuration renders 2 frames (the second with the first's temporal history).
"""
from __future__ import annotations

import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [ROOT, os.path.join(ROOT, "tests")]


def _glass_room(w, h):
    """The bounce room's box with a ceiling lamp and a smooth glass pane and a rough glass pane before the camera."""
    from restir_engine.core.scene import Lamps, MaterialTable, Scene
    from scenes_core import concat, perspective_camera, quad, tris
    mats = MaterialTable.build([{"base_color": (0.7, 0.7, 0.7), "roughness": 1.0, "f0": 0.0},
                                {"base_color": (0.8, 0.4, 0.3), "roughness": 0.4, "f0": 0.04},
                                {"base_color": (0, 0, 0), "f0": 0.0, "emission": (8.0, 8.0, 8.0)},
                                {"base_color": (0.9, 1.0, 0.9), "roughness": 0.0, "transmission": 1.0, "glass_ior": 1.5},
                                {"base_color": (1.0, 1.0, 1.0), "roughness": 0.3, "transmission": 1.0,
                                 "glass_ior": 1.45}])
    parts = [tris(quad((0, 0, 0), (1.5, 0, 0), (0, 1.5, 0)), 0), tris(quad((0, 0, 2), (0, 1.5, 0), (1.5, 0, 0)), 0),
             tris(quad((0, 1.5, 1), (0, 0, 1), (1.5, 0, 0)), 1), tris(quad((-1.5, 0, 1), (0, 1.5, 0), (0, 0, 1)), 1),
             tris(quad((0, 0, 1.98), (0.3, 0, 0), (0, 0.3, 0)), 2),
             tris(quad((-0.4, -0.6, 0.7), (0.35, 0, 0), (0, 0, 0.5)), 3),
             tris(quad((0.4, -0.6, 0.7), (0.35, 0, 0), (0, 0, 0.5)), 4)]
    cam = perspective_camera((0.0, -1.45, 1.0), (0.0, 0.5, 0.6), w, h, fov_y_deg=70)
    return Scene(concat(parts), mats, Lamps.empty(), cam, world_radiance=np.full(3, 0.1, np.float32))


def scenes(w=48, h=36):
    from scenes_core import bounce_room, plane_under_world, regression_room
    out = {"room": lambda: regression_room(w, h),
           "bounce": lambda: bounce_room({"base_color": (0.7, 0.7, 0.7), "roughness": 1.0, "f0": 0.0},
                                         {"base_color": (0.6, 0.5, 0.4), "roughness": 0.6, "f0": 0.04}, w, h),
           "world": lambda: plane_under_world(0.5, 1.0, 32), "glass": lambda: _glass_room(w, h)}
    return out


CONFIGS = {
    "path": ("room", dict(integrator="PATH", max_bounces=2, samples=2)),
    "path_batch": ("room", dict(integrator="PATH", max_bounces=1, samples=5, tile_pixels=512)),
    "path_coverage": ("room", dict(integrator="PATH", max_bounces=1, samples=2, coverage_samples=4)),
    "light_sampling": ("room", dict(integrator="RESTIR", direct_method="LIGHT_SAMPLING", max_bounces=1, samples=2)),
    "ris": ("room", dict(integrator="RESTIR", direct_method="RIS", max_bounces=0, samples=2, light_candidates=8)),
    "restir": ("room", dict(integrator="RESTIR", direct_method="RESTIR", max_bounces=1, samples=2,
                            light_candidates=8, spatial_radius=8.0)),
    "restir_unbiased": ("room", dict(integrator="RESTIR", direct_method="RESTIR", bias_correction="UNBIASED",
                                     max_bounces=1, samples=2, denoise_data=True)),
    "restir_biased": ("room", dict(integrator="RESTIR", direct_method="RESTIR", bias_correction="NONE",
                                   boiling_filter=True, light_tiles="ON", light_tile_count=8, light_tile_size=64,
                                   max_bounces=0, samples=1, light_candidates=8, spatial_radius=8.0,
                                   spatial_passes=2)),
    "power_tiles": ("room", dict(integrator="RESTIR", direct_method="RESTIR", light_tiles="ON", light_sampler="POWER",
                                 max_bounces=0, samples=1)),
    "defaults": ("room", dict(integrator="RESTIR", direct_method="AUTO", indirect_method="AUTO", samples=3)),
    "gi": ("bounce", dict(integrator="RESTIR", direct_method="RESTIR", indirect_method="RESTIR_GI", max_bounces=2,
                          samples=2, bias_correction="UNBIASED")),
    "gi_biased": ("bounce", dict(integrator="RESTIR", direct_method="AUTO", indirect_method="RESTIR_GI",
                                 max_bounces=2, samples=2, bias_correction="NONE")),
    "gi_auto": ("bounce", dict(integrator="RESTIR", direct_method="AUTO", indirect_method="AUTO", max_bounces=3,
                               samples=2)),
    "gi_room_auto": ("room", dict(integrator="RESTIR", indirect_method="AUTO", max_bounces=2, samples=2,
                                  reservoir_passes=True, gi_reservoir_passes=True)),
    "world_resampled": ("world", dict(integrator="RESTIR", direct_method="RESTIR", world_method="RESAMPLED",
                                      world_candidates=1, max_bounces=1, samples=2)),
    "glass_path": ("glass", dict(integrator="PATH", max_bounces=4, samples=2)),
    "glass_restir": ("glass", dict(integrator="RESTIR", direct_method="RESTIR", indirect_method="AUTO",
                                   max_bounces=4, samples=2)),
    "glass_gi": ("glass", dict(integrator="RESTIR", direct_method="RESTIR", indirect_method="RESTIR_GI",
                               max_bounces=3, samples=2, bias_correction="UNBIASED")),
    "world_path": ("world", dict(integrator="PATH", max_bounces=1, samples=2)),
}


def render_all(frames: int = 2) -> dict:
    from restir_engine.core.renderer import RenderSettings, render_frame
    out = {}
    builders = scenes()
    for name, (scene_name, cfg) in CONFIGS.items():
        scene = builders[scene_name]()
        hist = None
        for f in range(frames):
            r = render_frame(scene, RenderSettings(seed=7, frame=f, **cfg), history=hist)
            hist = r.history
            for pass_name, img in r.passes.items():
                out[f"{name}/{f}/{pass_name}"] = np.asarray(img)
    return out


def compare(a_path: str, b_path: str) -> int:
    a, b = np.load(a_path), np.load(b_path)
    keys = sorted(set(a.files) | set(b.files))
    differ = 0
    for k in keys:
        if k not in a.files or k not in b.files:
            print(f"{k}: only in {'b' if k not in a.files else 'a'}")
            differ += 1
            continue
        x, y = a[k], b[k]
        if x.shape != y.shape:
            print(f"{k}: shapes {x.shape} / {y.shape}")
            differ += 1
        elif not np.array_equal(x, y):
            d = np.abs(x.astype(np.float64) - y)
            print(f"{k}: differs, max |d| {d.max():.3g}, mean |a| {np.abs(x).mean():.3g}")
            differ += 1
    print(f"{len(keys) - differ} of {len(keys)} passes bit-identical")
    return 1 if differ else 0


if __name__ == "__main__":
    if sys.argv[1] == "--compare":
        sys.exit(compare(sys.argv[2], sys.argv[3]))
    np.savez_compressed(sys.argv[1], **render_all())
