"""Draw the add-on's Render Properties panels without a UI: a stand-in layout records every ``prop()`` call."""
from __future__ import annotations


class RecordingLayout:
    """Stands in for a UILayout: records (data, property name) of each prop() call, checking the property exists;
    every other call (row(), column(), label(), operator() ...) returns another recording layout."""

    def __init__(self, seen: list):
        object.__setattr__(self, "seen", seen)

    def __setattr__(self, name, value):
        pass

    def prop(self, data, name, **_kw):
        assert hasattr(data, name), name
        self.seen.append((data, name))
        return RecordingLayout(self.seen)

    def __getattr__(self, name):
        return lambda *a, **k: RecordingLayout(self.seen)


def drawn_properties(scene, view_layer) -> list:
    """(data, property name) of everything the panels draw (draw and draw_header) for ``scene``'s settings."""
    from restir_engine.ui import panels
    seen: list = []

    class Ctx:
        engine = "RESTIR"
    Ctx.scene, Ctx.view_layer = scene, view_layer
    for cls in panels.PANELS:
        holder = type("Holder", (), {"layout": RecordingLayout(seen), "split_layout": panels.RestirPanel.split_layout})()
        cls.draw(holder, Ctx)
        if hasattr(cls, "draw_header"):
            cls.draw_header(holder, Ctx)
    return seen
