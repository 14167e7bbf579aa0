"""The core's rendering entry points: :func:`render_frame` for one frame, :class:`FrameRenderer` for a renderer kept
alive between sample passes (the viewport), with their settings and results. The frame's pipeline lives in
core/pipeline/ (plan.py lists its stages in order)."""
from __future__ import annotations

from .pipeline.coverage import coverage_samples
from .pipeline.batches import MAX_BATCH
from .pipeline.frame import Cancelled, FrameRenderer, FrameResult
from .pipeline.frame_render import render_frame
from .pipeline.settings import INTEGRATORS, RenderSettings
from .pipeline.work import CHUNK_PIXELS

__all__ = ["CHUNK_PIXELS", "INTEGRATORS", "MAX_BATCH", "Cancelled", "FrameRenderer", "FrameResult", "RenderSettings",
           "coverage_samples", "render_frame"]
