"""8-bit sRGB image textures against Cycles (same bpy, CPU): Cycles keeps such an image sRGB-encoded and decodes
each lookup after interpolating, so where a texel is magnified its edge blends sRGB values, darker than blending the
decoded colours (core/materials/textures.SrgbImage). bpy_scenes.srgb_texture_planes: one small image of saturated
colours and greys, 4 pixels per texel, read with Linear, Cubic and Closest interpolation, through a Mapping node and
as an Emission Strength (the colour as a float); no lights, so each pixel is the texture's radiance.

Per 4 x 4 cells of 4 x 4 pixels and channel, 4 seeds a side at 16 samples: a cell agrees when
|ours - Cycles| <= 5 SE + 0.5 % of Cycles + 1e-3 (as the node pattern tests), and ours scaled by 1.03 fails
somewhere on every plane (power). Decoding the texels before interpolating (as before) read the image 3.4 % brighter
over the plane than Cycles and fails the edges' cells.
"""
import numpy as np
from bpy_scenes import SRGB_READS, srgb_texture_planes
from cycles_compare import cycles_reference, ours_cells
from stats import pattern_agrees, MARGIN, POWER_ERROR, Z_MAX

PX, CELL, COLS = 32, 4, 3
REPS, SAMPLES = 4, 16
FLOAT_TOL = 1e-3


def planes(images):
    """(k, h, w, 3), row 0 at the bottom -> (k, planes x cells x channels)."""
    top = np.asarray(images, np.float64)[:, ::-1]
    k, h, w, _ = top.shape
    blocks = top.reshape(k, h // CELL, CELL, w // CELL, CELL, 3).mean(axis=(2, 4))
    per = PX // CELL
    out = []
    for p in range(len(SRGB_READS)):
        r, c = divmod(p, COLS)
        out.append(blocks[:, r * per:(r + 1) * per, c * per:(c + 1) * per].reshape(k, -1))
    return np.concatenate(out, axis=1)


def within(ours, ref):
    return pattern_agrees(ours, ref, FLOAT_TOL)


def test_srgb_image_textures_match_cycles(addon):
    ours = ours_cells(lambda: srgb_texture_planes(PX), 0, SAMPLES, planes, reps=REPS, integrator="PATH")
    ref = cycles_reference("srgb_textures", lambda: srgb_texture_planes(PX), 0, SAMPLES, planes, reps=REPS)
    per = (PX // CELL) ** 2 * 3
    ok = within(ours, ref)
    bad = [f"{name}: {int((~ok[i * per:(i + 1) * per]).sum())} cells; worst ours "
           f"{ours.mean(0)[i * per + j]:.4f} Cycles {ref.mean(0)[i * per + j]:.4f}"
           for i, name in enumerate(SRGB_READS) for j in [int(np.argmin(ok[i * per:(i + 1) * per]))]
           if not ok[i * per:(i + 1) * per].all()]
    assert not bad, "\n".join(bad)
    scaled = within(ours * (1 + POWER_ERROR), ref)
    blind = [name for i, name in enumerate(SRGB_READS) if scaled[i * per:(i + 1) * per].all()]
    assert not blind, f"cannot see a 3 % error in: {blind}"
