"""Denoising F12 and animation frames inside the engine (Render Properties > Sampling > Denoise, on in a new scene as
in Cycles): Open Image Denoise from the library Blender ships, on Combined, guided by the Denoising Albedo and
Normal; the user's compositor is not touched. With the view layer's Denoising Data passes on, the image before
denoising is written as Noisy Image (as Cycles does).

A compositor set up by an older version of this add-on (its "ReSTIR Denoise" node) denoises already: such a file
is not denoised twice, and the panel offers to take that node out."""
from __future__ import annotations

import os
import sys

import bpy
import numpy as np

from .compat import compositor_output, compositor_tree
from .core.pipeline.denoiser import DenoiserUnavailable, DenoiseSettings, shared_denoiser
from .core.pipeline.memory import DENOISER_SCRATCH

LEGACY_NODE = "ReSTIR Denoise"   # the compositor node older versions wired in
# OIDN's scratch memory for a frame, so that a 4K frame's denoising stays within its render's memory bound (OIDN's
# own default grows with the image; beyond this it works in overlapping tiles, at some extra time)
MAX_MEMORY_MB = DENOISER_SCRATCH >> 20
# the Rendered viewport's denoising: Cycles' viewport defaults (albedo-guided, fast prefilter, balanced quality)
VIEWPORT_SETTINGS = DenoiseSettings(input_passes="RGB_ALBEDO", prefilter="FAST", quality="BALANCED",
                                    max_memory_mb=MAX_MEMORY_MB)


def library_candidates() -> list[str]:
    """Where the OIDN library Blender ships can be: its soname first (Blender links it, so on Linux it is
    already loaded), then the files beside Blender's binary and the bpy module."""
    if sys.platform.startswith("win"):
        names = ["OpenImageDenoise.dll"]
    elif sys.platform == "darwin":
        names = ["libOpenImageDenoise.2.dylib", "libOpenImageDenoise.dylib"]
    else:
        names = ["libOpenImageDenoise.so.2", "libOpenImageDenoise.so"]
    folders = []
    binary = getattr(bpy.app, "binary_path", "") or ""
    if binary:
        base = os.path.dirname(binary)
        folders += [base, os.path.join(base, "lib"), os.path.join(base, "blender.shared"),
                    os.path.join(os.path.dirname(base), "Resources", "lib")]
    folders.append(os.path.join(os.path.dirname(os.path.abspath(bpy.__file__)), "lib"))
    return names + [os.path.join(f, n) for f in folders for n in names if os.path.isfile(os.path.join(f, n))]


_LIBRARY: list = []   # [path] of the library that loaded, or [None] when none did (looked up once per session)


def denoiser():
    """The process's Denoiser, or raises DenoiserUnavailable naming where it looked."""
    if not _LIBRARY:
        for candidate in library_candidates():
            try:
                shared_denoiser(candidate)
            except DenoiserUnavailable:
                continue
            _LIBRARY.append(candidate)
            break
        else:
            _LIBRARY.append(None)
    if _LIBRARY[0] is None:
        raise DenoiserUnavailable("Open Image Denoise was not found in this Blender (looked for "
                                  f"{', '.join(library_candidates()[:2])}); the frame is not denoised")
    return shared_denoiser(_LIBRARY[0])


def settings_of(scene) -> DenoiseSettings:
    s = scene.restir
    threads = int(scene.render.threads) if scene.render.threads_mode == "FIXED" else 0
    return DenoiseSettings(input_passes=s.denoising_input_passes, prefilter=s.denoising_prefilter,
                           quality=s.denoising_quality, threads=threads, max_memory_mb=MAX_MEMORY_MB)


def legacy_compositor_denoise(scene) -> bool:
    """Whether the compositor holds the Denoise node an older version of the add-on wired in."""
    tree = compositor_tree(scene, create=False)
    return tree is not None and tree.nodes.get(LEGACY_NODE) is not None


def wanted(scene) -> bool:
    """Whether this scene's F12 and animation frames are denoised by the engine (not when an older version's
    compositor node denoises them already)."""
    return bool(scene.restir.use_denoising) and not legacy_compositor_denoise(scene)


def denoise_combined(passes: dict, settings: DenoiseSettings) -> np.ndarray:
    """Replace ``passes["Combined"]`` (h, w, 4) by its denoised image (alpha kept); returns the noisy Combined."""
    noisy = passes["Combined"]
    passes["Combined"] = denoiser().denoise_rgba(noisy, passes.get("Denoising Albedo"), passes.get("Denoising Normal"),
                                                 settings)
    return noisy


def remove_legacy(scene) -> None:
    """Take an older version's Denoise node out of the compositor: the Render Layers image goes straight to the
    output again (an output left unconnected would make Blender write black frames)."""
    tree = compositor_tree(scene, create=False)
    if tree is None:
        return
    den = tree.nodes.get(LEGACY_NODE)
    if den is not None:
        tree.nodes.remove(den)
    layers = tree.nodes.get(f"{LEGACY_NODE} Layers")
    if layers is not None:
        _out, socket = compositor_output(tree)
        tree.links.new(layers.outputs["Image"], socket)


class RESTIR_OT_remove_compositor_denoising(bpy.types.Operator):
    """Take out the compositor's Denoise node that an older version of the add-on set up (the engine denoises
    itself now)"""

    bl_idname = "restir.remove_compositor_denoising"
    bl_label = "Remove Compositor Denoising"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        remove_legacy(context.scene)
        return {"FINISHED"}


CLASSES = (RESTIR_OT_remove_compositor_denoising,)
