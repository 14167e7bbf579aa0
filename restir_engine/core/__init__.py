"""Pure NumPy + embreex rendering core of restir_engine.

Nothing in this package imports ``bpy``: scenes arrive as flat float32 arrays
(see :mod:`.scene`) and images leave as float32 arrays (see :mod:`.renderer`).
"""
