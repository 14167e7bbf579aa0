"""The viewport's renderer on a team of worker processes: what :class:`frame.FrameRenderer` offers the viewport, with
the renderer itself living in every worker of the team (pipeline/worker.py) between passes.

The view's scene is sent once per edit (in shared memory); a camera move, a sample pass, the data passes are one
message each. The film's accumulators are a shared segment this process reads the passes from. The temporal
history stays in the workers: each view's first pass reprojects the newest one, and an edit's new renderer takes it
over, as the viewport does in one process, so the same views give the same images with or without processes.

The team is the caller's alone (parallel.processes.borrow): the workers keep this renderer between its messages.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from ..parallel import wire
from ..parallel.processes import WorkerTeam
from .settings import RenderSettings, validate
from .shared_frame import shared_film, slot_bytes


class SharedViewRenderer:
    """A viewport's renderer of ``scene`` on ``team``: the arena slots are sized for views of up to
    ``view_pixels`` pixels (a larger view rebuilds the renderer, without history); ``carry``: the workers' last
    renderer's newest temporal history goes on into this one (a scene edit)."""

    def __init__(self, team: WorkerTeam, scene, settings: RenderSettings, view_pixels: int, carry: bool = False):
        validate(settings)
        self.team, self.scene, self.settings = team, scene, settings
        self.film = None
        self._data = None
        self._open(max(int(view_pixels), _pixels(scene.camera)), carry)

    def _open(self, view_pixels: int, carry: bool) -> None:
        team, st = self.team, self.settings
        self.view_pixels = view_pixels
        slots = team.ensure_slots(slot_bytes(view_pixels, st))
        film_name = self._new_film()
        seg, packed = wire.pack(self.scene)
        try:
            facts = team.run(("frame", {"scene": packed, "settings": wire.dumps(st), "sender": wire.core_name(),
                                        "history": None, "film": film_name, "slots": slots, "keep_histories": 1,
                                        "keep_history": True, "costs": team.costs_seg.name, "clock": False,
                                        "view": bool(carry)}))[0]
        finally:  # every worker attached (or the team is gone)
            wire.unlink_segments([seg])
        self.build_seconds = facts["build_seconds"]
        self._facts = facts

    def _new_film(self) -> str:
        if self.film is not None:
            self.film.release()
        name, self.film = shared_film(self.team, self.scene, self.settings)
        self._converged = False
        self._data = None
        return name

    # -- what the viewport reads --------------------------------------------------------------------
    @property
    def camera(self):
        return self.scene.camera

    @property
    def instance_matrices(self):
        return getattr(self.scene, "export_stats", {}).get("instance_matrices")

    @property
    def method(self) -> str:
        return self._facts["method"]

    @property
    def resamples_direct(self) -> bool:
        return bool(self._facts["resampled"])

    def reuses_history(self) -> bool:
        return bool(self._facts["reuses"])

    @property
    def samples_done(self) -> int:
        return self.film.samples

    @property
    def converged(self) -> bool:
        return self._converged

    def batch_size(self, remaining: int) -> int:
        """What FrameRenderer.batch_size(remaining) answers in the workers (its choice without a bound, cut)."""
        return max(1, min(int(remaining), int(self._facts["batch"])))

    def has_pass_data(self, key: str) -> bool:
        return self.film.has(key)

    def sums(self, key: str):
        return self.film.acc.get(key)

    def combined(self) -> np.ndarray:
        return self.film.combined()

    def mean(self, key: str) -> np.ndarray:
        return self.film.mean(key)

    def data_passes(self):
        """Depth, Normal and Vector of the current view (rendered by the team's leader once per view)."""
        if self._data is None:
            self._data = self.team.run(("data",))[0]
        return self._data

    # -- what the viewport does -----------------------------------------------------------------------
    def move_camera(self, camera, frame: int) -> None:
        """FrameRenderer.move_camera in the workers: the view ``camera`` as frame ``frame``, accumulation restarted."""
        self.settings = dataclasses.replace(self.settings, frame=int(frame))
        self.scene.camera = camera
        if _pixels(camera) > self.view_pixels:  # the slots cannot hold the view: a new renderer, no history
            self._open(_pixels(camera), carry=False)
            return
        film_name = self._new_film()
        self._facts.update(self.team.run(("view", (wire.dumps({"camera": camera, "frame": int(frame),
                                                                "film": film_name}), wire.core_name())))[0])

    def set_motion(self, motion) -> None:
        self.scene.motion = motion
        self.team.run(("motion", (wire.dumps(motion), wire.core_name())))

    def sample_pass(self, progress=None, should_stop=None, batch: int = 1, light_candidate_cap: int | None = None
                    ) -> bool:
        """One sample pass of ``batch`` samples on the team; False (the film unchanged) when stopped part-way."""
        replies = self.team.run(("pass", int(batch), int(batch), light_candidate_cap), should_stop)
        if replies is None:
            return False
        rendered, converged, next_batch = replies[0][:3]
        self.film.samples += int(rendered)
        self._converged = bool(converged)
        self._facts["batch"] = next_batch
        return True

    def release(self) -> None:
        """Let go of this process's view of the film (the workers' renderer stays until the team is given back)."""
        if self.film is not None:
            self.film.release()


def _pixels(camera) -> int:
    _x0, _y0, w, h = camera.window
    return int(w) * int(h)
