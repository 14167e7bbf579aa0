from . import panels  # noqa: F401

register = panels.register
unregister = panels.unregister
