"""ReSTIR render engine for Blender (extension ``restir_engine``).

Only registration lives here; see engine.py (glue), export/ (depsgraph -> arrays) and core/
(pure NumPy + Embree renderer).
"""
from __future__ import annotations


def register():
    import bpy

    from . import denoise, engine, presets, properties, ui
    properties.register()
    presets.register()
    for cls in denoise.CLASSES:
        bpy.utils.register_class(cls)
    bpy.utils.register_class(engine.RestirRenderEngine)
    ui.register()


def unregister():
    import bpy

    from . import denoise, engine, presets, properties, ui
    from .core.parallel import processes
    processes.shutdown()  # the render worker processes end with the add-on
    ui.unregister()
    bpy.utils.unregister_class(engine.RestirRenderEngine)
    for cls in reversed(denoise.CLASSES):
        bpy.utils.unregister_class(cls)
    presets.unregister()
    properties.unregister()
