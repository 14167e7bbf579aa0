"""Small analytic scenes built directly as core arrays (no bpy)."""
from __future__ import annotations

import numpy as np

from restir_engine.core.scene import Camera, Lamps, MaterialTable, Scene, TriangleSet


def quad(center, u, v):
    """Two triangles spanning center ± u ± v, wound so the normal is u x v."""
    c, u, v = (np.asarray(a, np.float32) for a in (center, u, v))
    p = [c - u - v, c + u - v, c + u + v, c - u + v]
    return np.array([[p[0], p[1], p[2]], [p[0], p[2], p[3]]], np.float32)


def tris(verts: np.ndarray, material: int) -> TriangleSet:
    ng = np.cross(verts[:, 1] - verts[:, 0], verts[:, 2] - verts[:, 0])
    ng /= np.linalg.norm(ng, axis=1)[:, None]
    return TriangleSet(verts, np.repeat(ng[:, None], 3, axis=1).astype(np.float32),
                       np.full(len(verts), material, np.int32))


def concat(sets):
    return TriangleSet(np.concatenate([s.verts for s in sets]), np.concatenate([s.normals for s in sets]),
                       np.concatenate([s.material for s in sets]))


def top_down_camera(width=32, height=32, height_above=2.0, half_extent=1.0) -> Camera:
    """Orthographic camera looking down -Z from z = height_above, seeing [-e, e]² of the z=0 plane."""
    c2w = np.eye(4, dtype=np.float64)
    c2w[2, 3] = height_above
    # orthographic projection inverse: ndc (x, y, z) -> camera (x e, y e, -(near..far))
    near, far = 0.01, 100.0
    ndc_to_cam = np.array([[half_extent, 0, 0, 0], [0, half_extent, 0, 0],
                           [0, 0, -(far - near) / 2, -(far + near) / 2], [0, 0, 0, 1]], np.float64)
    return Camera(c2w, ndc_to_cam, width, height, (0, 0, width, height), ortho=True, clip_start=near, clip_end=far)


def plane_under_world(albedo=0.5, world=1.0, width=32) -> Scene:
    """A large diffuse floor under a constant world: direct radiance = albedo * world exactly."""
    mats = MaterialTable.build([{"base_color": (albedo,) * 3, "f0": 0.0}])
    floor = tris(quad((0, 0, 0), (50, 0, 0), (0, 50, 0)), 0)
    return Scene(floor, mats, Lamps.empty(), top_down_camera(width, width),
                 world_radiance=np.full(3, world, np.float32))


def small_plane_under_world(width=32) -> Scene:
    """A diffuse square (albedo 0.5) seen from above, covering the middle quarter of the view, under a constant
    world of radiance 1: the other pixels see the world."""
    mats = MaterialTable.build([{"base_color": (0.5,) * 3, "f0": 0.0}])
    return Scene(tris(quad((0, 0, 0), (0.5, 0, 0), (0, 0.5, 0)), 0), mats, Lamps.empty(), top_down_camera(width, width),
                 world_radiance=np.full(3, 1.0, np.float32))


def floor_with_emitter(albedo=0.5, le=4.0, height=1.0, half=0.5, width=32, two_sided=True) -> Scene:
    """A diffuse floor under an emissive square (facing down) of half size ``half`` at ``height``."""
    mats = MaterialTable.build([{"base_color": (albedo,) * 3, "f0": 0.0},
                                {"base_color": (0, 0, 0), "f0": 0.0, "emission": (le,) * 3,
                                 "two_sided_emission": two_sided}])
    floor = tris(quad((0, 0, 0), (50, 0, 0), (0, 50, 0)), 0)
    light = tris(quad((0, 0, height), (0, half, 0), (half, 0, 0)), 1)  # normal -z
    return Scene(concat([floor, light]), mats, Lamps.empty(), top_down_camera(width, width, height_above=0.5 * height))


def add_emitters(scene: Scene, emissions) -> list[int]:
    """Append black emissive materials of RGB radiance ``emissions`` (W·sr⁻¹·m⁻², two-sided) to the scene's
    table (kept: base colour, f0, emission, two-sidedness of the existing ones); returns their indices."""
    mats = scene.materials
    rows = [{"base_color": tuple(mats.base_color[i]), "f0": float(mats.f0[i]), "emission": tuple(mats.emission[i]),
             "two_sided_emission": bool(mats.two_sided_emission[i])} for i in range(len(mats.names))]
    first = len(rows)
    rows += [{"base_color": (0, 0, 0), "f0": 0.0, "emission": tuple(e)} for e in emissions]
    scene.materials = MaterialTable.build(rows)
    return list(range(first, len(rows)))


def irradiance_square(h: float, a: float) -> float:
    """Irradiance / radiance at the point under the centre of a 2a x 2a square at height h:
    E = L * 4 * (a/√(a²+h²)) * atan(a/√(a²+h²)) (unit-radiance square, standard form factor)."""
    s = np.sqrt(a * a + h * h)
    return 4 * (a / s) * np.arctan(a / s)


def emissive_furnace(albedo=0.5, le=1.0, width=24) -> Scene:
    """Inside a closed cube whose walls all emit ``le`` (two-sided) and reflect ``albedo`` (Lambert):
    radiance with k bounces is le * sum_{j=0}^{k+1} albedo^j (emission, direct, indirect ...)."""
    mats = MaterialTable.build([{"base_color": (albedo,) * 3, "f0": 0.0, "emission": (le,) * 3}])
    faces = [quad((0, 0, -1), (1, 0, 0), (0, 1, 0)), quad((0, 0, 1), (0, 1, 0), (1, 0, 0)),
             quad((0, -1, 0), (0, 0, 1), (1, 0, 0)), quad((0, 1, 0), (1, 0, 0), (0, 0, 1)),
             quad((-1, 0, 0), (0, 1, 0), (0, 0, 1)), quad((1, 0, 0), (0, 0, 1), (0, 1, 0))]
    box = concat([tris(f, 0) for f in faces])
    cam = top_down_camera(width, width, height_above=0.5, half_extent=0.9)
    cam.clip_start = 0.01
    return Scene(box, mats, Lamps.empty(), cam)


def perspective_camera(eye, target, width=48, height=36, fov_y_deg=50.0, near=0.05, far=100.0) -> Camera:
    """Pinhole camera at ``eye`` looking at ``target`` (+Z up), OpenGL-style projection as Blender's."""
    eye, target = np.asarray(eye, np.float64), np.asarray(target, np.float64)
    fwd = target - eye
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, (0.0, 0.0, 1.0))
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    c2w = np.eye(4)
    c2w[:3, 0], c2w[:3, 1], c2w[:3, 2], c2w[:3, 3] = right, up, -fwd, eye
    f = 1.0 / np.tan(np.radians(fov_y_deg) / 2)
    proj = np.array([[f * height / width, 0, 0, 0], [0, f, 0, 0],
                     [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)], [0, 0, -1, 0]])
    return Camera(c2w, np.linalg.inv(proj), width, height, (0, 0, width, height), clip_start=near, clip_end=far)


def regression_room(width=48, height=36) -> Scene:
    """A small room with every feature the integrators branch on: a glossy Principled-like floor, a metal
    block, diffuse walls with an image texture (one open side to a grey world), an occluder, three coloured
    emitters (one tiny and bright, one with an emission texture) and a sun. Used for fixed-seed before/after
    image comparisons."""
    mats = MaterialTable.build([
        {"base_color": (0.6, 0.6, 0.55), "roughness": 0.3, "f0": 0.04},               # 0 glossy floor
        {"base_color": (1.0, 1.0, 1.0), "roughness": 1.0, "f0": 0.0, "base_tex": 0},  # 1 textured diffuse wall
        {"base_color": (0.9, 0.8, 0.5), "roughness": 0.2, "metallic": 1.0},            # 2 metal block
        {"base_color": (0, 0, 0), "f0": 0.0, "emission": (6.0, 5.0, 4.0), "emit_tex": 1},  # 3 textured panel
        {"base_color": (0, 0, 0), "f0": 0.0, "emission": (1.0, 2.0, 6.0)},             # 4 blue strip
        {"base_color": (0, 0, 0), "f0": 0.0, "emission": (3000.0, 3000.0, 3000.0)},    # 5 tiny bright
    ], textures=_checker_textures())
    parts = [tris(quad((0, 0, 0), (2, 0, 0), (0, 2, 0)), 0),
             tris(quad((0, 2, 1), (2, 0, 0), (0, 0, 1)), 1),
             tris(quad((-2, 0, 1), (0, 0, 1), (0, 2, 0)), 1),
             tris(quad((0.5, 0.6, 0.4), (0.3, 0, 0), (0, 0, 0.4)), 2),   # block front face (normal -y)
             tris(quad((0.5, 0.6, 0.8), (0.3, 0, 0), (0, 0.3, 0)), 2),   # block top
             tris(quad((0, 0.5, 1.9), (0, 0.5, 0), (0.5, 0, 0)), 3),     # ceiling panel facing down
             tris(quad((-1.95, 1.0, 1.0), (0, 0.6, 0), (0, 0, 0.05)), 4),  # strip on the left wall
             tris(quad((-0.6, -0.3, 0.5), (0, 0.01, 0), (0.01, 0, 0)), 5)]  # tiny light facing down
    lamps = Lamps.empty()
    d = np.array([[0.4, -0.3, 0.86]], np.float32)
    lamps.sun_dir = d / np.linalg.norm(d)
    lamps.sun_cos = np.array([np.cos(0.02)], np.float32)
    lamps.sun_irradiance = np.array([[1.5, 1.4, 1.2]], np.float32)
    cam = perspective_camera((0.3, -2.6, 1.3), (0.0, 0.6, 0.5), width, height)
    geometry = concat(parts)
    geometry.uvs = _quad_uvs(len(geometry))
    return Scene(geometry, mats, lamps, cam, world_radiance=np.full(3, 0.2, np.float32))


def _checker_textures():
    """A 4x4 red/blue checker (wall albedo) and a 2x2 bright/dim pattern (panel emission), scene-linear."""
    checker = np.where((np.add.outer(np.arange(4), np.arange(4)) % 2)[..., None] == 0, (0.7, 0.3, 0.2), (0.2, 0.3, 0.7))
    pattern = np.array([[[1.5, 1.5, 1.5], [0.5, 0.5, 0.5]], [[0.5, 0.5, 0.5], [1.5, 1.5, 1.5]]])
    return [checker.astype(np.float32), pattern.astype(np.float32)]


def _quad_uvs(n: int) -> np.ndarray:
    """UVs of quads built by :func:`quad` (two triangles each) spanning the unit square."""
    pair = np.array([[[0, 0], [1, 0], [1, 1]], [[0, 0], [1, 1], [0, 1]]], np.float32)
    return np.tile(pair, (n // 2, 1, 1))


def bounce_room(floor: dict, wall: dict, width=40, height=30, divider=False, look_at=(0.0, 0.5, 0.6)) -> Scene:
    """A closed 3 x 3 x 2 m room lit by a panel lying on the floor (its light reaches the floor only after a bounce
    off the ceiling or the walls); the floor and wall materials are given, material 3 is a grey Lambert for
    additions. ``divider``: a 1 mm wall splits the room, open at the top, and the camera looks at the unlit side;
    else the camera looks from the front wall at ``look_at``."""
    mats = MaterialTable.build([floor, wall, {"base_color": (0, 0, 0), "f0": 0.0, "emission": (10.0, 10.0, 10.0)},
                                {"base_color": (0.7, 0.7, 0.7), "roughness": 1.0, "f0": 0.0}])
    parts = [tris(quad((0, 0, 0), (1.5, 0, 0), (0, 1.5, 0)), 0),                    # floor (normal +z)
             tris(quad((0, 0, 2), (0, 1.5, 0), (1.5, 0, 0)), 1),                    # ceiling (normal -z)
             tris(quad((0, 1.5, 1), (0, 0, 1), (1.5, 0, 0)), 1),                    # back wall
             tris(quad((0, -1.5, 1), (1.5, 0, 0), (0, 0, 1)), 1),                   # front wall
             tris(quad((-1.5, 0, 1), (0, 1.5, 0), (0, 0, 1)), 1),                   # left wall
             tris(quad((1.5, 0, 1), (0, 0, 1), (0, 1.5, 0)), 1),                    # right wall
             tris(quad((0.8, 0.8, 0.05), (0.25, 0, 0), (0, 0.25, 0)), 2)]           # panel on the floor facing up
    cam = perspective_camera((0.0, -1.45, 1.0), look_at, width, height, fov_y_deg=70)
    if divider:  # x = 0.3 .. 0.301, open above z = 1.8; the camera stands in the dark half
        parts.append(tris(quad((0.3, 0, 0.9), (0, 1.5, 0), (0, 0, 0.9)), 3))
        parts.append(tris(quad((0.301, 0, 0.9), (0, 0, 0.9), (0, 1.5, 0)), 3))
        cam = perspective_camera((-0.8, -1.4, 1.0), (0.3, 0.6, 0.5), width, height, fov_y_deg=70)
    return Scene(concat(parts), mats, Lamps.empty(), cam, world_radiance=np.zeros(3, np.float32))


def one_moving_instance(scene: Scene, instances: int, moving: int, dx: float) -> None:
    """Give ``scene`` Blender-style instance motion: ``instances`` identity world matrices, instance ``moving``
    displaced by ``dx`` along x in the previous frame (its position then minus now); the camera does not move."""
    from restir_engine.core.scene import Motion
    current = np.repeat(np.eye(4)[None], instances, axis=0)
    prev = current.copy()
    prev[moving, 0, 3] = dx
    scene.motion = Motion(current, prev, current.copy(), scene.camera, scene.camera)
