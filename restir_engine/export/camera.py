"""Blender camera -> core Camera (pinhole or orthographic, sensor fit, shift, border)."""
from __future__ import annotations

import numpy as np

from ..core.scene import Camera


class ExportError(RuntimeError):
    """The scene cannot be rendered; the message says why, in words a user understands."""


def render_size(render) -> tuple[int, int]:
    """Full output resolution in pixels after the percentage."""
    pct = render.resolution_percentage / 100.0
    return max(1, int(render.resolution_x * pct)), max(1, int(render.resolution_y * pct))


def border_window(render, width: int, height: int) -> tuple[int, int, int, int]:
    """(x0, y0, w, h) of the region to render, y0 from the bottom row (Blender's rounding)."""
    if not render.use_border:
        return 0, 0, width, height
    x0 = int(round(render.border_min_x * width))
    x1 = int(round(render.border_max_x * width))
    y0 = int(round(render.border_min_y * height))
    y1 = int(round(render.border_max_y * height))
    x0, x1 = sorted((min(max(x0, 0), width), min(max(x1, 0), width)))
    y0, y1 = sorted((min(max(y0, 0), height), min(max(y1, 0), height)))
    if x1 - x0 < 1 or y1 - y0 < 1:
        return 0, 0, width, height
    return x0, y0, x1 - x0, y1 - y0


def export_camera(depsgraph, camera_override, warnings: list) -> Camera:
    scene = depsgraph.scene
    cam_obj = camera_override or scene.camera
    if cam_obj is None:
        raise ExportError("No camera: add a camera to the scene and make it active (Scene Properties > Camera)")
    cam_obj = cam_obj.evaluated_get(depsgraph)
    if cam_obj.type != "CAMERA":
        warnings.append(f"Active camera '{cam_obj.name}' is a {cam_obj.type.lower()} object; "
                        "using its transform as a 50 mm camera")
    render = scene.render
    width, height = render_size(render)
    proj = cam_obj.calc_matrix_camera(depsgraph, x=width, y=height,
                                      scale_x=render.pixel_aspect_x, scale_y=render.pixel_aspect_y)
    proj = np.array(proj, dtype=np.float64)
    ortho = False
    clip_start, clip_end = 0.1, 1000.0
    if cam_obj.type == "CAMERA":
        data = cam_obj.data
        ortho = data.type == "ORTHO"
        clip_start, clip_end = float(data.clip_start), float(data.clip_end)
        if data.type == "PANO":
            warnings.append(f"Camera '{cam_obj.name}': panoramic cameras are not supported; rendered as perspective")
        if data.dof.use_dof:
            warnings.append(f"Camera '{cam_obj.name}': depth of field is not supported; rendered as a pinhole")
    c2w = np.array(cam_obj.matrix_world, dtype=np.float64)
    # normalize axes: a scaled camera object must not scale rays
    for k in range(3):
        n = np.linalg.norm(c2w[:3, k])
        if n > 0:
            c2w[:3, k] /= n
    try:
        ndc_to_cam = np.linalg.inv(proj)
    except np.linalg.LinAlgError as exc:
        raise ExportError(f"Camera '{cam_obj.name}' has a degenerate projection (zero focal length or size?)") from exc
    if not np.isfinite(c2w).all() or not np.isfinite(ndc_to_cam).all():
        raise ExportError(f"Camera '{cam_obj.name}' has a non-finite transform")
    return Camera(cam_to_world=c2w, ndc_to_cam=ndc_to_cam, width=width, height=height,
                  window=border_window(render, width, height), ortho=ortho,
                  clip_start=clip_start, clip_end=clip_end)
