"""The work item of a sample pass: one span of window pixels and what the stages compute for its surfaces.

Pixels are row-major indices into the camera window; a chunk's random streams are keyed by (seed, frame, pass,
stream, chunk index), so images do not depend on scheduling. Per-surface rows are (3, n) or (WIDTH, n) float32
columns in the order of ``hits.rows``; ``first`` places them in the frame's whole-image buffers (the G-buffer and
the target terms), which the stages that read other pixels (reuse) work on.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

CHUNK_PIXELS = 32768  # pixels per chunk of work (RenderSettings.tile_pixels)


@dataclass
class Chunk:
    """One span of window pixels through a sample pass: its primary hits and per-surface results."""

    index: int
    pixels: np.ndarray     # window pixel indices (row-major): the chunk's span, ``batch`` times over
    batch: int = 1         # samples of each pixel (sample s + b at pixels[b * span : (b + 1) * span])
    hits: object = None    # camera_paths.PrimaryHits (rows index ``pixels``)                       [primary]
    chain: object = None   # camera_paths.SpecularChains: its surfaces seen through smooth glass      [primary]
    first: int = 0         # index of its first surface in the frame's G-buffer                     [primary]
    count: int = 0         # its surfaces (hit pixels; known for every chunk of the frame, hits only for its own)
    res: object = None     # di.DIReservoirs of its surfaces (initial, then after reuse)             [initial, reuse]
    bsdf_ray: object = None  # the BSDF candidate's traced ray, taken over by the path continuation   [initial]
    direct: np.ndarray = None    # (3, n) direct light: the continuation's part, then the shaded part [paths, shade]
    indirect: np.ndarray = None  # (3, n) indirect light                                              [paths, shade]
    gi_res: object = None  # gi.GIReservoirs of its surfaces                                        [paths, gi reuse]
    path_indirect: np.ndarray = None  # the path tracer's indirect light (kept where a pass skips GI reuse) [paths]
    gi_share: tuple = (0.0, 0.0, 0.0, 0.0)  # indirect_choice.share_sums over its surfaces           [paths]
    glossy: np.ndarray = None  # (n,) bool: GI resamples only the diffuse lobe there (gi.glossy_x1)  [paths]
    direct_g: np.ndarray = None    # (G, 3, n) direct light by light group (lights/groups.py)         [paths, shade]
    indirect_g: np.ndarray = None  # (G, 3, n) indirect light by light group                          [paths, shade]
    path_indirect_g: np.ndarray = None  # path_indirect by light group                                 [paths]
    catcher: np.ndarray = None     # (k,) its surfaces on shadow catchers (shadow_catcher.py)         [primary]
    sc_with: np.ndarray = None     # (3, k) their light with every object                             [shade]
    sc_without: np.ndarray = None  # (3, k) their light in the scene of the catchers alone            [shade]
    sc_behind: np.ndarray = None   # (3, k) the world the catchers hide                               [primary]

    @property
    def surfaces(self) -> slice:
        """Its surfaces' rows in the frame's whole-image buffers."""
        return slice(self.first, self.first + self.count)


def make_chunks(span_list, batch: int) -> list[Chunk]:
    """One chunk per pixel span (a slice, or an increasing array of window pixels: the pixels adaptive sampling
    left active), each holding its span ``batch`` times (one copy per sample of the pass)."""
    def pixels(sl):
        return np.arange(sl.start, sl.stop) if isinstance(sl, slice) else np.asarray(sl, np.int64)
    return [Chunk(i, pixels(sl) if batch == 1 else np.tile(pixels(sl), batch), batch)
            for i, sl in enumerate(span_list)]


def place(chunks: list[Chunk], team) -> int:
    """Give each chunk its surface count and first row in the frame's surface order (chunk order), from the
    primary hits of the chunks this process owns and the team's for the others; returns the surface count."""
    counts = team.table({c.index: len(c.hits.rows) for c in chunks if c.hits is not None}, len(chunks), 1)
    first = 0
    for c, k in zip(chunks, counts[:, 0].astype(np.int64)):
        c.first, c.count = first, int(k)
        first += int(k)
    return first


def own(chunks: list[Chunk], team) -> list[Chunk]:
    """The chunks this process computes."""
    return chunks if team.size == 1 else [c for c in chunks if team.owns_chunk(c.index)]


def frame_array(kind, n: int, team):
    """n reservoirs of ``kind`` for the frame's whole-image stages: empty ones where this process renders alone,
    the team's shared buffers (not initialized: every member writes its own rows) otherwise."""
    return kind.empty(n) if team.size == 1 else kind.allocate(n, team.empty)


def frame_reservoirs(chunks: list[Chunk], field: str, kind, n: int, team):
    """The chunks' reservoirs in ``field`` ("res" or "gi_res") as one frame-wide ``kind`` array of the frame's n
    surfaces (the reuse stages' input; in the team's shared buffers, complete after its barrier); the chunks let go
    of theirs."""
    res = frame_array(kind, n, team)
    for c in own(chunks, team):
        res.assign(c.surfaces, getattr(c, field))
        setattr(c, field, None)  # the frame's array holds them now
    team.barrier()
    return res


def hand_back(chunks: list[Chunk], field: str, res) -> None:
    """Each chunk's rows of the frame-wide reservoirs ``res`` into its ``field`` (for shading and the film)."""
    for c in chunks:
        setattr(c, field, res.take(c.surfaces))
