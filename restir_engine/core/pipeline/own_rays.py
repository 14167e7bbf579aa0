"""Camera rays of their own for passes that need only what the camera sees first (Cryptomatte, shader AOVs): k rays
per pixel of the camera window, placed as the frame's are (a Sobol pass sequence shifted per pixel, the film's
pixel filter, the lens's aperture) but on their own random streams, so the frame's image does not change."""
from __future__ import annotations

import numpy as np

from ..geometry import camera as camera_mod
from ..sampling import STREAM_LENS, STREAM_PIXEL_OFFSET, pass_jitter, rng


def camera_ray_sets(cam, k: int, seed: int, frame: int, salt: int):
    """Yields k times (origins (3, n), directions (3, n), tmax (n,)) for the window's n pixels in row-major order;
    ``salt`` keys the streams (one per pass kind)."""
    x0, y0, w, h = cam.window
    n = w * h
    pix = np.arange(n)
    shift = rng(seed, frame, 0, STREAM_PIXEL_OFFSET + salt).bit_generator.random_raw(n).view(np.uint32).reshape(-1, 2)
    land = camera_mod.filter_offsets(cam)
    lens = rng(seed, frame, 0, STREAM_LENS + salt) if camera_mod.has_lens(cam) else None
    for s in range(max(1, int(k))):
        j = pass_jitter(shift, s)
        x = (x0 + pix % w).astype(np.float32) + land(j[:, 0])
        y = (y0 + pix // w).astype(np.float32) + land(j[:, 1])
        o, d, tmax = camera_mod.generate_rays(cam, x, y, None if lens is None else
                                              lens.random((2, n), dtype=np.float32))
        yield o, d, np.where(tmax < 0, np.float32(0), tmax)
