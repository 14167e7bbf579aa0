"""Temporal history: what the next frame's temporal reuse reads, kept between frames by the caller.

Reservoirs index lights of the frame's light table; when the next frame's table differs only by lights
switched on or off or re-powered, the reservoirs are remapped through stable light ids (scene triangle or
lamp triangle index) instead of being dropped."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from .gbuffer import GBuffer
from .reservoir import Reservoirs


@dataclass
class TemporalHistory:
    """The previous frame's G-buffer, its final DI reservoirs (confidence capped; None when DI was not reused),
    its camera and the light-table signature the reservoirs index into."""

    gbuf: GBuffer
    res: Reservoirs
    camera: object
    light_signature: tuple
    frame: int = 0
    light_uid: np.ndarray | None = None  # (n_tri [+ 1 world],) stable id of each light (lights.LightTable.light_uid)
    uid_space: tuple = ()                # (scene triangles, lamp triangles) the ids index into
    had_light: np.ndarray | None = None  # after remapping to a new light table: (n_tri,) bool, lights of the
    #                                      current table that were lights in this history's frame
    gi_res: Reservoirs | None = None     # ReSTIR GI: the frame's final GI reservoirs (aged, confidence capped)
    gi_terms: object = None              # their target terms (target.ShadingTerms; the G-buffer's are DI's)
    gi_key: bytes | None = None          # fingerprint of everything that emits: any change drops the GI history

    def fits(self, camera) -> bool:
        """Whether this history can serve a frame seen by ``camera`` (same window and resolution)."""
        return (self.camera.window[2:] == camera.window[2:]
                and (self.camera.width, self.camera.height) == (camera.width, camera.height))

    def remapped(self, lights) -> "TemporalHistory | None":
        """This history for the light table ``lights`` of the next frame: identical tables keep it as it is;
        tables over the same triangles (lights switched on/off or re-powered) get the reservoirs' light
        indices remapped through the stable ids (a light that went out leaves an empty reservoir) and
        ``had_light`` set; anything else cannot be mapped (None)."""
        if self.light_signature == lights.signature:
            return self
        if self.res is None:  # no DI reservoirs to remap (the GI history is checked by its own key)
            return dataclasses.replace(self, light_signature=lights.signature)
        if self.light_uid is None or self.uid_space != lights.uid_space:
            return None
        ids = int(sum(self.uid_space)) + 1  # the last id: the world's points (lights.LightTable.attach_world)
        uid_to_light = np.full(ids, -1, np.int64)
        uid_to_light[lights.light_uid] = np.arange(len(lights.light_uid))
        old = self.res.light
        live = old >= 0
        light = np.full(len(old), -1, np.int32)
        light[live] = uid_to_light[self.light_uid[old[live]]]
        res = self.res.replace(light=light, W=self.res.W.copy(), p_hat=self.res.p_hat.copy())
        res.clear(live & (light < 0))
        had = np.zeros(ids, bool)
        had[self.light_uid] = True
        return dataclasses.replace(self, res=res, light_signature=lights.signature, light_uid=lights.light_uid,
                                   had_light=had[lights.light_uid])
