"""Primary rays from Blender's camera model.

Raster coordinates are in pixels of the full render resolution, x to the right and y *up*
(row 0 at the bottom, as Blender stores images). Pixel (i, j) covers [i, i+1) x [j, j+1).
"""
from __future__ import annotations

import numpy as np

from ..scene import Camera


def filter_offsets(cam: Camera):
    """The function taking uniform numbers in [0, 1) to raster offsets from a pixel's corner under the camera's
    film filter (the identity for a one-pixel box)."""
    f = getattr(cam, "pixel_filter", None)
    return (lambda u: u) if f is None else f.offsets


def has_lens(cam: Camera) -> bool:
    """Whether the camera's rays leave from an aperture (depth of field): they take aperture samples."""
    return getattr(cam, "lens", None) is not None


def projected_masks_hold(cam: Camera) -> bool:
    """Whether a pixel's rays stay in the pixel's cone of a perspective or orthographic projection (no lens, no
    panorama), so that masks built from projected boxes hold."""
    return getattr(cam, "lens", None) is None and getattr(cam, "panorama", None) is None


def _panorama_rays(cam: Camera, pano, x, y):
    """Rays of a panoramic camera from its position (advanced by the near clip distance); frame points off the
    projection's image get tmax -1 (they see nothing)."""
    u = np.asarray(x, np.float64) / cam.width
    v = np.asarray(y, np.float64) / cam.height
    dcam, valid = pano.directions(u, v)
    c2w = np.asarray(cam.cam_to_world, np.float64)
    d = (c2w[:3, :3].astype(np.float32) @ dcam).astype(np.float32)
    o = (c2w[:3, 3].astype(np.float32)[:, None] + d * np.float32(cam.clip_start)).astype(np.float32)
    tmax = np.where(valid, np.float32(cam.clip_end - cam.clip_start), np.float32(-1.0)).astype(np.float32)
    return o, d, tmax


def view_depth(cam: Camera, points: np.ndarray) -> np.ndarray:
    """The depth of world points (3, n) as the Depth pass holds it: along the view axis, or for a panorama the
    distance from the camera (its view has no one axis)."""
    rel = np.asarray(points, np.float32) - position(cam)[:, None]
    if getattr(cam, "panorama", None) is not None:
        return np.sqrt((rel * rel).sum(axis=0)).astype(np.float32)
    f = forward(cam)
    return (f[0] * rel[0] + f[1] * rel[1] + f[2] * rel[2]).astype(np.float32)


def filter_margin(cam: Camera) -> float:
    """Pixels by which masks of what camera rays may meet must grow: one, plus the filter's reach."""
    f = getattr(cam, "pixel_filter", None)
    return 1.0 + (0.0 if f is None else float(f.reach))


def _xform(m: np.ndarray, pts: np.ndarray) -> np.ndarray:
    h = pts @ m[:3, :3].T + m[:3, 3]
    w = pts @ m[3, :3] + m[3, 3]
    return h / w[:, None]


def forward(cam: Camera) -> np.ndarray:
    f = -cam.cam_to_world[:3, 2]
    return (f / np.linalg.norm(f)).astype(np.float32)


def position(cam: Camera) -> np.ndarray:
    return cam.cam_to_world[:3, 3].astype(np.float32)


def _clip_planes_affine(cam: Camera):
    """For projections whose inverse keeps w independent of the NDC x and y (perspective and orthographic,
    with lens shift), the points on the near and far clip planes are affine in NDC (x, y): returns
    (origin, d/dnx, d/dny) in world space for each plane as float64 (2, 3, 3), else None."""
    inv = np.asarray(cam.ndc_to_cam, np.float64)
    if abs(inv[3, 0]) > 1e-12 or abs(inv[3, 1]) > 1e-12:
        return None
    c2w = np.asarray(cam.cam_to_world, np.float64)
    out = np.empty((2, 3, 3))
    for i, z in enumerate((-1.0, 1.0)):
        w = inv[3, 2] * z + inv[3, 3]
        base = (inv[:3, 2] * z + inv[:3, 3]) / w
        out[i, 0] = c2w[:3, :3] @ base + c2w[:3, 3]
        out[i, 1] = c2w[:3, :3] @ (inv[:3, 0] / w)
        out[i, 2] = c2w[:3, :3] @ (inv[:3, 1] / w)
    return out


def generate_rays(cam: Camera, x: np.ndarray, y: np.ndarray, lens_uv=None):
    """Rays through raster points (x, y): origins on the near clip plane (3, n), unit directions
    (3, n) and the distance to the far clip plane (n,). With the camera's lens (depth of field) and aperture
    samples ``lens_uv`` ((2, n) uniform), thin-lens rays (geometry/lens.py)."""
    pano = getattr(cam, "panorama", None)
    if pano is not None:
        return _panorama_rays(cam, pano, x, y)
    lens = getattr(cam, "lens", None)
    if lens is not None and lens_uv is not None:
        o, d, tmax = generate_rays(cam, x, y)
        return lens.rays(cam, o, d, tmax, lens_uv[0], lens_uv[1])
    planes = _clip_planes_affine(cam)
    if planes is not None:  # float32 affine maps (the near plane's position error stays below 1e-6 relative)
        nx = (2.0 / cam.width) * x.astype(np.float32) - 1.0
        ny = (2.0 / cam.height) * y.astype(np.float32) - 1.0
        near, far = planes.astype(np.float32)[:, :, :, None]  # (3 terms, 3 coords, 1) each
        span = far - near
        o = near[0] + nx * near[1] + ny * near[2]
        d = span[0] + nx * span[1] + ny * span[2]
        length = np.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        d /= np.maximum(length, np.float32(1e-30))
        return o.astype(np.float32, copy=False), d.astype(np.float32, copy=False), length.astype(np.float32)
    nx = (2.0 * x / cam.width - 1.0).astype(np.float64)
    ny = (2.0 * y / cam.height - 1.0).astype(np.float64)
    ones = np.ones_like(nx)
    near = _xform(cam.ndc_to_cam, np.stack([nx, ny, -ones], axis=-1))
    far = _xform(cam.ndc_to_cam, np.stack([nx, ny, ones], axis=-1))
    c2w = cam.cam_to_world.astype(np.float64)
    near_w = near @ c2w[:3, :3].T + c2w[:3, 3]
    far_w = far @ c2w[:3, :3].T + c2w[:3, 3]
    d = far_w - near_w
    length = np.linalg.norm(d, axis=1)
    d = d / np.maximum(length, 1e-30)[:, None]
    return (np.ascontiguousarray(near_w.T, dtype=np.float32), np.ascontiguousarray(d.T, dtype=np.float32),
            length.astype(np.float32))


def project(cam: Camera, points: np.ndarray):
    """Raster coordinates (n, 2) of world points (3, n) seen by ``cam`` (x right, y up, full-resolution
    pixels) and their planar depth along the camera axis (n,); depth <= 0 means behind the camera. The
    matrices are combined in float64, the points transformed in float32. A panorama: the distance from the camera
    as the depth (-1 where the direction is off its image)."""
    if getattr(cam, "panorama", None) is not None:
        return _project_panorama(cam, points)
    w2c = np.linalg.inv(cam.cam_to_world.astype(np.float64))
    clip = (np.linalg.inv(cam.ndc_to_cam.astype(np.float64)) @ w2c).astype(np.float32)
    zrow = w2c[2].astype(np.float32)
    x, y, z = (np.asarray(points[i], np.float32) for i in range(3))
    h = [clip[i, 0] * x + clip[i, 1] * y + clip[i, 2] * z + clip[i, 3] for i in (0, 1, 3)]
    w = np.where(np.abs(h[2]) > 1e-12, h[2], np.float32(1e-12))
    raster = np.empty((len(x), 2), np.float32)
    raster[:, 0] = (h[0] / w + 1) * np.float32(0.5 * cam.width)
    raster[:, 1] = (h[1] / w + 1) * np.float32(0.5 * cam.height)
    depth = -(zrow[0] * x + zrow[1] * y + zrow[2] * z + zrow[3])
    return raster, depth.astype(np.float32, copy=False)


def _project_panorama(cam: Camera, points: np.ndarray):
    w2c = np.linalg.inv(cam.cam_to_world.astype(np.float64))
    p = np.asarray(points, np.float64)
    rel = w2c[:3, :3] @ p + w2c[:3, 3:4]
    u, v, ok = cam.panorama.frame_points(rel)
    raster = np.stack([u * cam.width, v * cam.height], axis=1).astype(np.float32)
    depth = np.where(ok, np.linalg.norm(rel, axis=0), -1.0).astype(np.float32)
    return raster, depth


def emitter_pixels(cam: Camera, tris: np.ndarray, centers: np.ndarray, radii: np.ndarray,
                   margin: float | None = None) -> np.ndarray:
    """(h, w) bool over the camera's window: the pixels that triangles (k, 3, 3) and spheres (centres (m, 3),
    radii (m,)) may cover, world space. A triangle marks the box of its projected corners, a sphere the box around
    the projections of its centre and of the six points at ± r along the world axes widened by half again (its
    outline lies within it), each widened by ``margin`` pixels; anything reaching behind the camera's plane marks
    the whole window (``margin`` None: filter_margin). Vectorized: the boxes are summed into a difference array."""
    x0, y0, w, h = cam.window
    margin = filter_margin(cam) if margin is None else margin
    boxes = []
    if len(tris):
        box = _projected_boxes(cam, tris, margin)
        if box is None:
            return np.ones((h, w), bool)
        boxes.append(box)
    if len(centers):
        c = np.asarray(centers, np.float32)
        rad = np.asarray(radii, np.float32)
        offs = np.concatenate([np.zeros((1, 3)), np.eye(3), -np.eye(3)]).astype(np.float32)  # (7, 3)
        pts = (c[None, :, :] + offs[:, None, :] * rad[None, :, None]).reshape(-1, 3)
        raster, depth = project(cam, pts.T)
        if (depth <= 1e-6).any():
            return np.ones((h, w), bool)
        raster = raster.reshape(7, len(c), 2)
        lo, hi = raster.min(axis=0), raster.max(axis=0)
        mid, half = (lo + hi) / 2, (hi - lo) / 2 * 1.5 + margin
        boxes.append((mid - half, mid + half))
    if not boxes:
        return np.zeros((h, w), bool)
    return _mark_boxes(cam, np.concatenate([b[0] for b in boxes]), np.concatenate([b[1] for b in boxes]))


def box_pixels(cam: Camera, lo: np.ndarray, hi: np.ndarray, margin: float | None = None) -> np.ndarray:
    """(h, w) bool over the camera's window: the pixels whose camera rays may meet something inside the world-space
    axis-aligned boxes ``lo`` / ``hi`` (k, 3): the box of each one's eight projected corners, widened by ``margin``
    pixels (the whole window when a box reaches behind the camera's plane). Outside, a camera ray meets nothing."""
    x0, y0, w, h = cam.window
    margin = filter_margin(cam) if margin is None else margin
    if len(lo) == 0:
        return np.zeros((h, w), bool)
    lo, hi = np.asarray(lo, np.float32), np.asarray(hi, np.float32)
    sel = np.array([[(i >> a) & 1 for a in range(3)] for i in range(8)], bool)  # (8, 3): which corner takes hi
    corners = np.where(sel[None], hi[:, None, :], lo[:, None, :])             # (k, 8, 3)
    box = _projected_boxes(cam, corners, margin)
    return np.ones((h, w), bool) if box is None else _mark_boxes(cam, *box)


def _projected_boxes(cam: Camera, groups: np.ndarray, margin: float):
    """Raster boxes (lo (k, 2), hi (k, 2)) of point groups (k, m, 3) widened by ``margin``; None when a point is
    not in front of the camera."""
    g = np.asarray(groups, np.float32)
    raster, depth = project(cam, g.reshape(-1, 3).T)
    if (depth <= 1e-6).any():
        return None
    r = raster.reshape(len(g), -1, 2)
    return r.min(axis=1) - margin, r.max(axis=1) + margin


def _mark_boxes(cam: Camera, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(h, w) bool over the window: the pixels touched by raster boxes lo / hi (k, 2), summed into a difference
    array."""
    x0, y0, w, h = cam.window
    bx0 = np.clip(np.floor(lo[:, 0] - x0), 0, w).astype(np.int64)
    bx1 = np.clip(np.ceil(hi[:, 0] - x0), 0, w).astype(np.int64)
    by0 = np.clip(np.floor(lo[:, 1] - y0), 0, h).astype(np.int64)
    by1 = np.clip(np.ceil(hi[:, 1] - y0), 0, h).astype(np.int64)
    ok = (bx1 > bx0) & (by1 > by0)
    diff = np.zeros((h + 1, w + 1), np.int64)
    np.add.at(diff, (by0[ok], bx0[ok]), 1)
    np.add.at(diff, (by0[ok], bx1[ok]), -1)
    np.add.at(diff, (by1[ok], bx0[ok]), -1)
    np.add.at(diff, (by1[ok], bx1[ok]), 1)
    return np.cumsum(np.cumsum(diff, axis=0), axis=1)[:h, :w] > 0


def pixel_spread(camera) -> tuple:
    """A pixel's footprint on a surface at distance t from the camera ≈ a + b t (scene units): the width of a
    pixel on the image plane at unit distance (perspective) or on the view plane (orthographic)."""
    if camera is None:
        return (np.float32(0.0), np.float32(1e-3))
    if getattr(camera, "panorama", None) is not None:  # about a full turn over the frame's width
        return (np.float32(0.0), np.float32(2 * np.pi / max(camera.width, 1)))
    m = np.asarray(camera.ndc_to_cam, np.float64)
    lo, hi = m @ np.array([0.0, -1.0, -1.0, 1.0]), m @ np.array([0.0, 1.0, -1.0, 1.0])
    lo, hi = lo[:3] / lo[3], hi[:3] / hi[3]
    if camera.ortho:
        return (np.float32(abs(hi[1] - lo[1]) / max(camera.height, 1)), np.float32(0.0))
    tan = abs(hi[1] / hi[2] - lo[1] / lo[2]) if abs(hi[2]) > 0 and abs(lo[2]) > 0 else 1.0
    return (np.float32(0.0), np.float32(tan / max(camera.height, 1)))


def pixel_footprint(camera, t) -> np.ndarray:
    """(n,) float32: a pixel's footprint (scene units) at distances ``t`` (n,) from ``camera`` (pixel_spread)."""
    a, b = pixel_spread(camera)
    return a + b * np.asarray(t, np.float32)
