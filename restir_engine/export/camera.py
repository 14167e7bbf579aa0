"""Blender camera -> core Camera (pinhole or orthographic, sensor fit, shift, border)."""
from __future__ import annotations

import numpy as np

from ..core.geometry.lens import Lens
from ..core.geometry.panorama import KINDS as PANORAMAS, Panorama
from ..core.geometry.pixel_filter import PixelFilter
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
    c2w, blind = _orthonormal_camera_matrix(np.array(cam_obj.matrix_world, dtype=np.float64))
    if blind:
        warnings.append(f"Camera '{cam_obj.name}' is scaled to zero on two or more axes: it has no orientation "
                        "and sees nothing, so the frame is black (as in Cycles)")
    if ortho and float(cam_obj.data.ortho_scale) <= 0.0:
        warnings.append(f"Camera '{cam_obj.name}': an orthographic scale of 0 sends every pixel's ray from the same "
                        "point, so the image is one colour; set Orthographic Scale above 0")
    proj = _well_conditioned_depth(proj, ortho, clip_start, clip_end)
    try:
        ndc_to_cam = np.linalg.inv(proj)
    except np.linalg.LinAlgError as exc:
        if ortho and float(cam_obj.data.ortho_scale) <= 0.0:
            raise ExportError(f"Camera '{cam_obj.name}' has an orthographic scale of 0: set Orthographic Scale "
                              "above 0") from exc
        raise ExportError(f"Camera '{cam_obj.name}' has a degenerate projection (zero focal length or size?)") from exc
    if not np.isfinite(c2w).all() or not np.isfinite(ndc_to_cam).all():
        raise ExportError(f"Camera '{cam_obj.name}' has a non-finite transform")
    return Camera(cam_to_world=c2w, ndc_to_cam=ndc_to_cam, width=width, height=height,
                  window=border_window(render, width, height), ortho=ortho,
                  clip_start=clip_start, clip_end=clip_end, blind=blind, pixel_filter=film_filter(scene),
                  lens=None if blind else thin_lens(scene, cam_obj, c2w, warnings),
                  panorama=panorama(cam_obj, width, height, warnings))


def panorama(cam_obj, width: int, height: int, warnings: list) -> Panorama | None:
    """Camera > Panoramic as a Panorama (geometry/panorama.py), the sensor fitted to the frame as Blender fits it;
    None for other cameras."""
    if cam_obj.type != "CAMERA" or cam_obj.data.type != "PANO":
        return None
    data = cam_obj.data
    kind = getattr(data, "panorama_type", "EQUIRECTANGULAR")
    if kind not in PANORAMAS:
        warnings.append(f"Camera '{cam_obj.name}': the {kind} panorama is not supported; rendered as "
                        "equirectangular")
        kind = "EQUIRECTANGULAR"
    fit, sw, sh = data.sensor_fit, float(data.sensor_width), float(data.sensor_height)
    if fit == "VERTICAL":
        sensor = (sh * width / height, sh)
    elif fit == "HORIZONTAL" or width >= height:
        sensor = (sw, sw * height / width)
    else:
        sensor = (sw * width / height, sw)
    return Panorama(kind=kind, fov=float(data.fisheye_fov), lens=float(data.fisheye_lens), sensor=sensor,
                    latitude=(float(data.latitude_min), float(data.latitude_max)),
                    longitude=(float(data.longitude_min), float(data.longitude_max)),
                    polynomial=tuple(float(getattr(data, f"fisheye_polynomial_k{i}")) for i in range(5)),
                    cylinder=(float(data.central_cylindrical_range_u_min), float(data.central_cylindrical_range_u_max),
                              float(data.central_cylindrical_range_v_min), float(data.central_cylindrical_range_v_max),
                              float(data.central_cylindrical_radius)))


def thin_lens(scene, cam_obj, c2w: np.ndarray, warnings: list) -> Lens | None:
    """Camera > Depth of Field as a thin lens (as Cycles): the aperture radius is the focal length / (2 F-stop)
    in metres (orthographic: 1 / (2 F-stop)), in scene units through the scene's Unit Scale; the focus distance
    is the Focus Object's depth along the view axis, else Focus Distance. None without depth of field."""
    if cam_obj.type != "CAMERA":
        return None
    data = cam_obj.data
    dof = data.dof
    if not dof.use_dof or float(dof.aperture_fstop) <= 0:
        return None
    unit = float(getattr(scene.unit_settings, "scale_length", 1.0)) or 1.0
    if data.type == "ORTHO":
        radius = 1.0 / (2.0 * float(dof.aperture_fstop))
    else:
        radius = float(data.lens) * 1e-3 / (2.0 * float(dof.aperture_fstop)) / unit
    if radius <= 0 or not np.isfinite(radius):
        return None
    focus = float(dof.focus_distance)
    if dof.focus_object is not None:
        target = np.array(dof.focus_object.matrix_world.translation, np.float64)
        focus = abs(float(np.dot(-c2w[:3, 2], target - c2w[:3, 3])))
        if getattr(dof, "focus_subtarget", ""):
            warnings.append(f"Camera '{cam_obj.name}': the focus bone '{dof.focus_subtarget}' is not read; "
                            "the focus object's origin is used")
    if data.type == "PANO":
        warnings.append(f"Camera '{cam_obj.name}': depth of field of a panoramic camera is not supported; "
                        "rendered as a pinhole")
        return None
    return Lens(radius=radius, focus=max(focus, 1e-6), blades=int(dof.aperture_blades),
                rotation=float(dof.aperture_rotation), ratio=max(float(dof.aperture_ratio), 1e-6))


def film_filter(scene) -> PixelFilter | None:
    """The scene's pixel filter (Film > Pixel Filter); None for a one-pixel box."""
    s = getattr(scene, "restir", None)
    if s is None:
        return None
    f = PixelFilter(s.pixel_filter, s.filter_width)
    return None if f.box else f


def _orthonormal_camera_matrix(m: np.ndarray) -> tuple[np.ndarray, bool]:
    """(camera matrix with unit axes, whether its orientation is lost). A scaled camera object must not scale
    rays, so each axis is normalized; one axis scaled to zero is rebuilt from the other two (right-handed, as a
    camera frame is); with two or three at zero the orientation is gone (the identity stands in, flagged)."""
    m = m.copy()
    lengths = np.linalg.norm(m[:3, :3], axis=0)
    usable = lengths > 1e-12 * max(1.0, float(np.abs(m[:3, 3]).max()))
    for k in np.flatnonzero(usable):
        m[:3, k] /= lengths[k]
    if usable.sum() == 2:
        k = int(np.flatnonzero(~usable)[0])
        m[:3, k] = np.cross(m[:3, (k + 1) % 3], m[:3, (k + 2) % 3])
        m[:3, k] /= np.linalg.norm(m[:3, k])
    elif usable.sum() < 2:
        m[:3, :3] = np.eye(3)
        return m, True
    return m, False


def _well_conditioned_depth(proj: np.ndarray, ortho: bool, near: float, far: float) -> np.ndarray:
    """``proj`` with its depth rows rebuilt in float64 from the clip range. Blender hands the projection over in
    float32, where -(far + near) / (far - near) rounds to -1 once near/far is below about 1e-7 (a Clip Start of
    1e-6, what typing 0 stores) and the inverse then puts the near plane at infinity; OpenGL's depth mapping
    (NDC z = -1 at the near plane, +1 at the far plane) written in float64 keeps it finite down to Blender's
    minimum."""
    if not (0.0 < near < far) or not np.isfinite(far):
        return proj
    proj = proj.copy()
    if ortho:
        proj[2, :] = (0.0, 0.0, -2.0 / (far - near), -(far + near) / (far - near))
    elif abs(proj[3, 2] + 1.0) < 1e-6 and abs(proj[3, 3]) < 1e-6:  # the usual perspective w = -z
        proj[2, 2:] = (-(far + near) / (far - near), -2.0 * far * near / (far - near))
    return proj
