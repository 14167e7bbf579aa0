"""Shader AOVs (View Layer > Shader AOV): what each material's AOV Output nodes compute at the surface the camera
sees first, averaged over k camera rays per pixel of their own (pipeline/own_rays.py); 0 where a ray meets
nothing or a material without that AOV, as Cycles. Colours are scene-linear RGB, values floats."""
from __future__ import annotations

import numpy as np

from ..materials.nodes.attributes import HitAttributes
from ..sampling import STREAM_AOV_RAYS, cols
from .own_rays import camera_ray_sets


def render_aovs(ctx, aovs, samples: int, seed: int = 0, frame: int = 0) -> dict:
    """{name: (h, w, 3) for a "COLOR" AOV or (h, w, 1) for a "VALUE" one, row 0 at the bottom} of ``aovs``
    [(name, kind)]."""
    cam = ctx.scene.camera
    _x0, _y0, w, h = cam.window
    n = w * h
    mats, geom = ctx.scene.materials, ctx.scene.geometry
    index = getattr(mats, "aov_program", None)
    sums = {name: np.zeros((3 if kind == "COLOR" else 1, n), np.float64) for name, kind in aovs}
    k = max(1, int(samples))
    if index is not None and (index >= 0).any():
        fields = {name: (f"aov:{name}" if kind == "COLOR" else f"aov_value:{name}") for name, kind in aovs}
        for o, d, tmax in camera_ray_sets(cam, k, seed, frame, STREAM_AOV_RAYS):
            hits = ctx.geom_accel.intersect(o, d, tmax, camera=True)
            rows = np.flatnonzero(hits.prim >= 0)
            prog = index[geom.material[hits.prim[rows]]]
            for p in np.unique(prog[prog >= 0]):
                program = mats.aov_programs[int(p)]
                sel = rows[prog == p]
                wanted = [f for f in fields.values() if program.has(f)]
                if not wanted:
                    continue
                attrs = HitAttributes(geom, hits.prim[sel], hits.u[sel], hits.v[sel], mats.textures, wo=-cols(d, sel))
                out = program.run(attrs, wanted)
                for name, field in fields.items():
                    if field in out:
                        v = out[field]
                        sums[name][:, sel] += v if v.ndim == 2 else v[None]
    return {name: np.ascontiguousarray((s / k).T.reshape(h, w, -1), dtype=np.float32) for name, s in sums.items()}
