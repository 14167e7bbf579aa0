"""Render > Motion Blur -> the scene's :class:`~restir_engine.core.geometry.motion_blur.ShutterMotion`.

As Cycles: the shutter lasts Shutter frames and opens at the frame (Position Start), around it (Center) or before
it (End); the instances' and the camera's matrices are evaluated (``engine.frame_set``) at 2^Steps + 1 moments over
it, Steps the largest Object > Motion Blur > Steps of the objects that blur; an object with Object > Motion Blur off
stays where the frame has it, as does the camera when its object's is off. Lights do not blur (as in Cycles).
"""
from __future__ import annotations

import math

import numpy as np

from ..core.geometry.motion_blur import CURVE_SAMPLES, ShutterMotion
from .camera import ExportError, export_camera
from .meshes import instance_matrices

POSITIONS = {"START": 0.5, "CENTER": 0.0, "END": -0.5}  # the shutter's centre after the frame, in shutters


def wanted(scene) -> bool:
    """Whether the scene asks for motion blur (Render > Motion Blur on with a shutter above 0)."""
    render = scene.render
    return bool(getattr(render, "use_motion_blur", False)) and float(render.motion_blur_shutter) > 0.0


def _object_blur(obj) -> tuple[bool, int]:
    """(Object > Motion Blur on, its Steps), Cycles' per-object settings where Cycles is registered."""
    c = getattr(obj, "cycles", None)
    return bool(getattr(c, "use_motion_blur", True)), int(getattr(c, "motion_steps", 1))


def step_times(scene, steps: int) -> np.ndarray:
    """The frame times (float) of the ``steps`` moments from the shutter's opening to its closing."""
    shutter = float(scene.render.motion_blur_shutter)
    position = getattr(scene.render, "motion_blur_position", "CENTER")
    centre = float(scene.frame_current) + float(getattr(scene, "frame_subframe", 0.0)) + \
        POSITIONS.get(position, 0.0) * shutter
    return centre + np.linspace(-0.5, 0.5, steps) * shutter


def shutter_curve(scene) -> np.ndarray | None:
    """Render > Motion Blur > Shutter Curve at CURVE_SAMPLES points over the shutter (None where unreadable)."""
    curve = getattr(scene.render, "motion_blur_shutter_curve", None)
    if curve is None or not len(curve.curves):
        return None
    try:
        curve.initialize()
        return np.array([curve.evaluate(curve.curves[0], x) for x in np.linspace(0.0, 1.0, CURVE_SAMPLES)],
                        np.float64)
    except (AttributeError, RuntimeError, TypeError):
        return None


def export_shutter(engine, depsgraph, scene_out, camera_override=None) -> list[str]:
    """Fill ``scene_out.blur`` (None when nothing moves during the shutter) by evaluating the shutter's step times
    and restoring the frame. Returns warnings for what is not blurred."""
    scene = depsgraph.scene
    stats = scene_out.export_stats
    keys = stats["instance_keys"]
    current = np.asarray(stats["instance_matrices"], np.float64).reshape(-1, 4, 4)
    blur_of, deforming = {}, {}
    for inst in depsgraph.object_instances:
        if not inst.show_self:
            continue
        obj = inst.object
        source = obj.original if obj.original is not None else obj  # the user's settings
        name = source.name
        blur_of.setdefault(name, _object_blur(source))
        c = getattr(source, "cycles", None)
        if blur_of[name][0] and getattr(c, "use_deform_motion", True) and obj.type == "MESH" and \
                obj.original.is_deform_modified(scene, "RENDER"):
            deforming[name] = True
    cam_obj = camera_override or scene.camera
    cam_blurs = _object_blur(cam_obj.original or cam_obj)[0] if cam_obj is not None else False
    level = max([st for on, st in blur_of.values() if on] or [1])
    steps = 2 ** max(1, min(level, 7)) + 1
    frame, subframe = scene.frame_current, float(getattr(scene, "frame_subframe", 0.0))
    mats = np.repeat(current[None], steps, axis=0)
    cams = []
    deform = _DeformSteps(stats, keys, deforming, steps)
    try:
        for i, t in enumerate(step_times(scene, steps)):
            f = math.floor(t)
            engine.frame_set(int(f), subframe=float(t - f))
            found = instance_matrices(depsgraph)
            for k, key in enumerate(keys):
                if key in found and blur_of.get(key[0], (True, 1))[0]:
                    mats[i, k] = found[key]
            if cam_blurs:
                try:
                    cams.append(export_camera(depsgraph, camera_override, []).cam_to_world)
                except ExportError:
                    cams.append(scene_out.camera.cam_to_world)
            if deforming:
                deform.read(depsgraph, i)
    finally:
        engine.frame_set(frame, subframe=subframe)
    camera_steps = None
    if cams:
        camera_steps = np.array(cams, np.float64)
        if np.abs(camera_steps - scene_out.camera.cam_to_world[None]).max() <= 1e-9 * \
                max(1.0, float(np.abs(scene_out.camera.cam_to_world).max())):
            camera_steps = None
    rows, corners = deform.result()
    blur = ShutterMotion(mats, current, camera_steps, shutter_curve(scene), rows, corners)
    scene_out.blur = blur if blur.moves else None
    warnings = list(deform.warnings)
    if getattr(getattr(scene, "cycles", None), "rolling_shutter_type", "NONE") != "NONE":
        warnings.append("Motion blur: the rolling shutter is not rendered (every row sees the whole shutter)")
    return warnings


class _DeformSteps:
    """The corners of deforming instances' triangles at each shutter step (world space), in the exported rows."""

    def __init__(self, stats: dict, keys: list, deforming: dict, steps: int):
        self.keys = {key: k for k, key in enumerate(keys) if key[0] in deforming}
        self.starts, self.kept = stats.get("block_starts"), stats.get("kept")
        self.steps = steps
        self.found: dict = {}  # instance index -> (steps, n, 3, 3) pre-drop corners
        self.warnings: list[str] = []
        self._bad: set = set()

    def read(self, depsgraph, step: int) -> None:
        from .meshes import instance_key, read_corners
        if self.starts is None:
            return
        for inst in depsgraph.object_instances:
            if not inst.show_self or inst.object.type != "MESH":
                continue
            k = self.keys.get(instance_key(inst))
            if k is None or k in self._bad:
                continue
            obj = inst.object
            try:
                mesh = obj.to_mesh()
            except RuntimeError:
                mesh = None
            if mesh is None:
                continue
            try:
                local = read_corners(mesh)
            finally:
                obj.to_mesh_clear()
            n = int(self.starts[k + 1] - self.starts[k])
            if len(local) != n:
                self._bad.add(k)
                self.found.pop(k, None)
                self.warnings.append(f"Motion blur: '{obj.name}' changes its topology during the shutter; its "
                                     "deformation is not blurred (as in Cycles)")
                continue
            m = np.array(inst.matrix_world, np.float64)
            world = (local.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3]).reshape(n, 3, 3).astype(np.float32)
            self.found.setdefault(k, np.zeros((self.steps, n, 3, 3), np.float32))[step] = world

    def result(self):
        """(rows (d,) int64, corners (steps, d, 3, 3)) of the exported triangles that deform, or (None, None)."""
        if not self.found or self.kept is None:
            return None, None
        post = np.cumsum(self.kept) - 1  # exported row of each triangle before the drop
        rows, corners = [], []
        for k, steps in sorted(self.found.items()):
            s, e = int(self.starts[k]), int(self.starts[k + 1])
            keep = self.kept[s:e]
            moved = np.abs(steps - steps[:1]).max() > 0 if len(steps) else False
            if not moved or not keep.any():
                continue
            rows.append(post[s:e][keep])
            corners.append(steps[:, keep])
        if not rows:
            return None, None
        return np.concatenate(rows).astype(np.int64), np.concatenate(corners, axis=1)
