"""The one table of render passes: what update_render_passes registers, the UI shows and the
writer fills. Each row: (Blender pass name, channel ids, channel type, enabled(scene, view_layer),
core pass name). Combined is always on; the others follow the view layer's checkboxes, and the
reservoir passes exist only when the integrator produces reservoirs (never as placeholders)."""
from __future__ import annotations

from .core.pipeline import methods


def has_reservoirs(scene) -> bool:
    return methods.resamples_direct(scene.restir)


def has_gi_reservoirs(scene) -> bool:
    return methods.gi_possible(scene.restir)


def light_group_names(view_layer) -> list:
    """The view layer's light groups (View Layer Properties > Light Groups), in order."""
    return [g.name for g in getattr(view_layer, "lightgroups", None) or ()]


PASSES = (
    ("Combined", "RGBA", "COLOR", lambda sc, vl: True, "Combined"),
    ("Depth", "Z", "VALUE", lambda sc, vl: vl.use_pass_z, "Depth"),
    ("Normal", "XYZ", "VECTOR", lambda sc, vl: vl.use_pass_normal, "Normal"),
    ("Vector", "XYZW", "VECTOR", lambda sc, vl: vl.use_pass_vector, "Vector"),
    ("Direct", "RGB", "COLOR", lambda sc, vl: vl.restir.use_pass_direct, "Direct"),
    ("Indirect", "RGB", "COLOR", lambda sc, vl: vl.restir.use_pass_indirect, "Indirect"),
    ("Emission", "RGB", "COLOR", lambda sc, vl: vl.restir.use_pass_emission, "Emission"),
    ("Reservoir M", "X", "VALUE", lambda sc, vl: vl.restir.use_pass_reservoir_m and has_reservoirs(sc), "Reservoir M"),
    ("Reservoir UCW", "X", "VALUE", lambda sc, vl: vl.restir.use_pass_reservoir_ucw and has_reservoirs(sc),
     "Reservoir UCW"),
    ("GI Reservoir M", "X", "VALUE", lambda sc, vl: vl.restir.use_pass_gi_reservoir_m and has_gi_reservoirs(sc),
     "GI Reservoir M"),
    ("GI Reservoir UCW", "X", "VALUE", lambda sc, vl: vl.restir.use_pass_gi_reservoir_ucw and has_gi_reservoirs(sc),
     "GI Reservoir UCW"),
    ("Denoising Albedo", "RGB", "COLOR", lambda sc, vl: vl.restir.use_pass_denoising_data, "Denoising Albedo"),
    ("Denoising Normal", "XYZ", "VECTOR", lambda sc, vl: vl.restir.use_pass_denoising_data, "Denoising Normal"),
    ("Noisy Image", "RGBA", "COLOR", lambda sc, vl: vl.restir.use_pass_denoising_data and sc.restir.use_denoising,
     "Noisy Image"),
    ("Shadow Catcher", "RGB", "COLOR", lambda sc, vl: vl.restir.use_pass_shadow_catcher, "Shadow Catcher"),
    ("Sample Count", "X", "VALUE", lambda sc, vl: vl.restir.use_pass_sample_count and sc.restir.use_adaptive_sampling,
     "Sample Count"),
)


def cryptomatte_kinds(view_layer) -> list:
    """The Cryptomatte layers the view layer asks for (View Layer Properties > Passes > Cryptomatte)."""
    return [k for k in ("object", "material", "asset") if getattr(view_layer, f"use_pass_cryptomatte_{k}", False)]


def cryptomatte_rows(view_layer) -> list:
    """Pass rows of the Cryptomatte layers: ceil(Levels / 2) RGBA passes each (two ranks of (id, coverage))."""
    from .core.pipeline.cryptomatte import PASS_PREFIX
    levels = int(getattr(view_layer, "pass_cryptomatte_depth", 6))
    return [(f"{PASS_PREFIX[k]}{i:02d}", "rgba", "COLOR", lambda sc, vl: True, f"{PASS_PREFIX[k]}{i:02d}")
            for k in cryptomatte_kinds(view_layer) for i in range((levels + 1) // 2)]


def shader_aovs(view_layer) -> list:
    """(name, "COLOR" | "VALUE") of the view layer's Shader AOVs (View Layer Properties > Shader AOV)."""
    return [(a.name, a.type) for a in getattr(view_layer, "aovs", ()) if a.name and getattr(a, "is_valid", True)]


def aov_rows(view_layer) -> list:
    return [(name, "RGB" if kind == "COLOR" else "X", "COLOR" if kind == "COLOR" else "VALUE", lambda sc, vl: True,
             f"AOV {name}") for name, kind in shader_aovs(view_layer)]


def light_group_rows(view_layer) -> list:
    """One "Combined_<group>" pass per light group (Cycles' names): the light of the group's lamps, emissive objects
    and world, by every path."""
    return [(f"Combined_{name}", "RGB", "COLOR", lambda sc, vl: True, f"Combined_{name}")
            for name in light_group_names(view_layer)]


def enabled_passes(scene, view_layer):
    """Rows of :data:`PASSES` enabled for this scene and view layer, then its light group, Cryptomatte and Shader
    AOV passes (stateless: safe on throwaway engines)."""
    return [row for row in PASSES if row[3](scene, view_layer)] + light_group_rows(view_layer) + \
        cryptomatte_rows(view_layer) + aov_rows(view_layer)


def register_passes(engine, scene, view_layer):
    for name, chans, ctype, _enabled, _core in enabled_passes(scene, view_layer):
        engine.register_pass(scene, view_layer, name, len(chans), chans, ctype)
