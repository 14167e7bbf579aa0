from . import panels

register = panels.register
unregister = panels.unregister
