"""Camera rays of their own for passes that need only what the camera sees first (Cryptomatte, shader AOVs): k rays
per pixel of the camera window, placed as the frame's are (a Sobol pass sequence shifted per pixel, the film's
pixel filter, the lens's aperture) but on their own random streams, so the frame's image does not change."""
from __future__ import annotations

import numpy as np

from ..geometry import camera as camera_mod
from ..sampling import pass_jitter, rng


def camera_ray_sets(cam, k: int, seed: int, frame: int, streams: tuple, pixels: np.ndarray | None = None):
    """Yields k times (origins (3, n), directions (3, n), tmax (n,)) for the window's pixels in row-major order, or
    for the window pixels ``pixels`` (the same rays as for the whole window); ``streams``: the pass kind's
    (per-pixel shift, aperture) random streams (sampling.STREAM_*_RAYS)."""
    x0, y0, w, h = cam.window
    shift = rng(seed, frame, 0, streams[0]).bit_generator.random_raw(w * h).view(np.uint32)
    shift = shift.reshape(-1, 2)
    pix = np.arange(w * h) if pixels is None else np.asarray(pixels, np.int64)
    if pixels is not None:
        shift = shift[pix]
    n = len(pix)
    land = camera_mod.filter_offsets(cam)
    lens = None
    if camera_mod.has_lens(cam):  # a stream per block of pixels, keyed by its first pixel
        lens = rng(seed, frame, 0, streams[1], int(pix[0]) if n else 0)
    for s in range(max(1, int(k))):
        j = pass_jitter(shift, s)
        x = (x0 + pix % w).astype(np.float32) + land(j[:, 0])
        y = (y0 + pix // w).astype(np.float32) + land(j[:, 1])
        o, d, tmax = camera_mod.generate_rays(cam, x, y, None if lens is None else
                                              lens.random((2, n), dtype=np.float32))
        yield o, d, np.where(tmax < 0, np.float32(0), tmax)
