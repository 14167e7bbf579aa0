"""Presampled light points and light tiles (Wyman & Panteleev 2021, "Rearchitecting spatiotemporal
resampling for production").

A :class:`LightPoints` batch holds points drawn from the triangle-light power table together with
everything the RIS target needs about them (position, unit normal, emitted radiance, area-measure pdf),
so a candidate costs one gather instead of an alias lookup, a barycentric interpolation and a material
read. :class:`LightTiles` draws ``count`` tiles of ``size`` points once per sample pass; every 16 x 16
pixel block takes its candidates from one randomly assigned tile (a cache-sized working set). Each
candidate is still distributed as the power table says (pdf p_select / A, area measure), so RIS over
tile candidates stays unbiased; candidates of one block are merely correlated.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..modes import LightTiles, values

TILE_MODES = values(LightTiles)
BLOCK = 16              # pixels per side of a screen block sharing one tile
AUTO_FACTOR = 8.0       # AUTO: use tiles when candidates per pass exceed this many times the tile points


@dataclass
class LightPoints:
    """SoA light points (n,): light int32, b1, b2 float32, pos (3, n), normal (3, n) unit geometric
    normal, le (3, n) radiance leaving the front face (W·sr⁻¹·m⁻², scene-linear; spot cones not
    applied), pdf (n,) area measure (m⁻²), two_sided bool, spot_tri int32 (lamp triangle with a
    spot cone, else -1). ``block``: the packed (11, n) form when it was built first (see :meth:`packed`)."""

    light: np.ndarray
    b1: np.ndarray
    b2: np.ndarray
    pos: np.ndarray
    normal: np.ndarray
    le: np.ndarray
    pdf: np.ndarray
    two_sided: np.ndarray
    spot_tri: np.ndarray
    block: np.ndarray | None = None

    @property
    def has_spots(self) -> bool:
        return bool((self.spot_tri >= 0).any())

    def packed(self) -> np.ndarray:
        """(11, n) float32 block [pos, normal, le, pdf, two_sided] (rows): one column gather per candidate
        (see :class:`PackedPoints`)."""
        if self.block is not None:
            return self.block
        out = np.empty((11, len(self.light)), np.float32)
        out[0:3] = self.pos
        out[3:6] = self.normal
        out[6:9] = self.le
        out[9] = self.pdf
        out[10] = self.two_sided
        return out


@dataclass
class PackedPoints:
    """Row views of a :meth:`LightPoints.packed` block (or of a gather from it, shape (11, ...)): what the
    target function reads. pos, normal, le are (3, ...), pdf (...) area measure, two_sided (...) bool."""

    pos: np.ndarray
    normal: np.ndarray
    le: np.ndarray
    pdf: np.ndarray
    two_sided: np.ndarray

    @staticmethod
    def of(block: np.ndarray) -> "PackedPoints":
        return PackedPoints(block[0:3], block[3:6], block[6:9], block[9], block[10] > 0)


def light_points(lights, light: np.ndarray, b1: np.ndarray, b2: np.ndarray, out: np.ndarray | None = None) -> LightPoints:
    """The points (b1, b2) of triangle lights ``light`` of a lights.LightTable, built in packed form (column
    gathers from the table's (3, n_tri) corner, edge, normal and radiance rows), into ``out`` ((11, n)) if
    given. Index ``lights.env_index`` is a point of the world (world_points.py) when one is attached."""
    n = len(light)
    env = lights.env_rows(light)
    if lights.n_tri == 0 and env.size < n:  # no triangle lights: every point is an empty placeholder
        z3 = np.zeros((3, n), np.float32)
        return LightPoints(np.full(n, -1, np.int32), np.zeros(n, np.float32), np.zeros(n, np.float32), z3, z3.copy(),
                           z3.copy(), np.zeros(n, np.float32), np.zeros(n, bool), np.full(n, -1, np.int32))
    light = light.astype(np.intp)
    b1 = np.asarray(b1, np.float32)
    b2 = np.asarray(b2, np.float32)
    blk = np.empty((11, n), np.float32) if out is None else out
    if env.size < n:
        _fill_surface(lights, light if not env.size else np.where(light == lights.env_index, 0, light), b1, b2, blk)
    if env.size:  # world points (world_points.py): one-sided, area pdf 0 in the power table
        blk[0:3, env], blk[3:6, env], blk[6:9, env] = lights.env.points(b1[env], b2[env])
        blk[9:11, env] = 0.0
    return LightPoints(light.astype(np.int32), b1, b2, blk[0:3], blk[3:6], blk[6:9], blk[9], blk[10] > 0,
                       lights.spot_lamp_tri(light), block=blk)


def _fill_surface(lights, light: np.ndarray, b1: np.ndarray, b2: np.ndarray, blk: np.ndarray) -> None:
    """The packed rows (11, n) of points (b1, b2) on surface lights ``light``."""
    lights.positions(light, b1, b2, out=blk[0:3])
    lights.normals(light, b1, b2, out=blk[3:6])
    np.take(lights.rows_le, light, axis=1, out=blk[6:9])
    if lights.any_textured:
        tex = np.flatnonzero(lights.tri_textured[light])
        if tex.size:
            blk[6:9, tex] = lights.radiance_of(light[tex], b1[tex], b2[tex], None)
    np.take(lights.tri_pdf_area, light, out=blk[9])
    blk[10] = lights.tri_two_sided[light]


def sample_points(lights, u: np.ndarray) -> LightPoints:
    """Points from the surface-light power table (``u``: (n, 4) uniforms), uniform in area on each light
    (triangles: barycentrics; spheres: sphere coordinates, uniform in area for uniform (b1, b2))."""
    light = lights.tri_alias.sample(u[:, 0], u[:, 1]).astype(np.int32)
    b1, b2 = lights.area_coords(light, u[:, 2], u[:, 3])
    return light_points(lights, light, b1, b2)


@dataclass
class TileSettings:
    """mode: 'AUTO' | 'ON' | 'OFF'; count tiles of size points each."""

    mode: str = "AUTO"
    count: int = 128
    size: int = 1024

    def wanted(self, pixels: int, candidates: int) -> bool:
        """Whether a pass of ``pixels`` pixels drawing ``candidates`` light candidates each uses tiles."""
        if self.mode == "ON":
            return True
        if self.mode == "OFF" or candidates == 0:
            return False
        return pixels * candidates >= AUTO_FACTOR * self.count * self.size


class LightTiles:
    """``count`` x ``size`` presampled points and a tile per 16 x 16 screen block, for one sample pass."""

    def __init__(self, lights, cfg: TileSettings, width: int, height: int, rng: np.random.Generator):
        self.count, self.size = max(1, cfg.count), max(1, cfg.size)
        self.points = sample_points(lights, rng.random((self.count * self.size, 4), dtype=np.float32))
        self.lights = lights
        self.rows = self.points.packed()
        self.blocks_x = (width + BLOCK - 1) // BLOCK
        blocks = self.blocks_x * ((height + BLOCK - 1) // BLOCK)
        self.tile_of_block = rng.integers(0, self.count, blocks).astype(np.int64)

    def tile_base(self, px: np.ndarray, py: np.ndarray) -> np.ndarray:
        """First point index of the tile serving window pixels (px, py) (integers, window coordinates)."""
        block = (py // BLOCK) * self.blocks_x + px // BLOCK
        return self.tile_of_block[block] * self.size

    def pdf_area(self, light: np.ndarray, px: np.ndarray, py: np.ndarray) -> np.ndarray:
        """Area-measure pdf (n,) with which a light candidate of pixel (px, py) is the point on ``light``: the
        power table's, whatever the pixel."""
        return self.lights.tri_pdf_area[light]
