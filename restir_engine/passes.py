"""The one table of render passes: what update_render_passes registers, the UI shows and the
writer fills. Each row: (Blender pass name, channel ids, channel type, enabled(view_layer),
core pass name). Combined is always on; the others follow the view layer's checkboxes."""
from __future__ import annotations

PASSES = (
    ("Combined", "RGBA", "COLOR", lambda vl: True, "Combined"),
    ("Depth", "Z", "VALUE", lambda vl: vl.use_pass_z, "Depth"),
    ("Normal", "XYZ", "VECTOR", lambda vl: vl.use_pass_normal, "Normal"),
    ("Direct", "RGB", "COLOR", lambda vl: vl.restir.use_pass_direct, "Direct"),
    ("Indirect", "RGB", "COLOR", lambda vl: vl.restir.use_pass_indirect, "Indirect"),
    ("Emission", "RGB", "COLOR", lambda vl: vl.restir.use_pass_emission, "Emission"),
)


def enabled_passes(view_layer):
    """Rows of :data:`PASSES` enabled on this view layer (stateless: safe on throwaway engines)."""
    return [row for row in PASSES if row[3](view_layer)]


def register_passes(engine, scene, view_layer):
    for name, chans, ctype, _enabled, _core in enabled_passes(view_layer):
        engine.register_pass(scene, view_layer, name, len(chans), chans, ctype)
