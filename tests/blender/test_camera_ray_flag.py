"""Light Path > Is Camera Ray in a BSDF's inputs at the camera's first hits of a scene with glass: 1 where the camera
sees a surface directly, 0 where it sees it through glass (as Cycles: a ray that passed a transmission is no
camera ray)."""
import math

import numpy as np
from bpy_scenes import configure_restir, glass_material, render_passes
from harness.scenes import black_world, camera, diffuse, light, plane, reset
from node_graphs import light_path


def test_is_camera_ray_is_one_for_direct_hits_and_zero_behind_glass(addon):
    scene = reset()
    wall = diffuse("Wall", (1, 1, 1))
    tree = wall.node_tree
    light_path()(tree, tree.nodes["Diffuse BSDF"].inputs["Color"])  # camera rays: blue, others: red
    plane("Wall", 4, (0, 2, 0), (math.pi / 2, 0, 0), material=wall)
    plane("Pane", 1, (-1, 0, 0), (math.pi / 2, 0, 0), material=glass_material("Pane", "GLASS", ior=1.01))
    light("SUN", (0, -3, 0), (math.radians(90), 0, 0), energy=3.0)
    camera((0, -4, 0), (math.radians(90), 0, 0), ortho_scale=4.0)
    black_world(scene)
    scene.render.resolution_x, scene.render.resolution_y = 32, 16
    configure_restir(scene, 4, 4, 0, integrator="PATH")
    img = render_passes(scene)["Combined"][..., :3]
    direct = img[4:12, 20:28].mean(axis=(0, 1))   # the right half: the wall seen directly
    behind = img[4:12, 4:12].mean(axis=(0, 1))    # the left: through the pane
    assert direct[2] > 2 * direct[0], direct      # blue: a camera ray's colour
    assert behind[0] > 2 * behind[2], behind      # red: not a camera ray
