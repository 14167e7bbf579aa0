"""What crosses between the rendering process and its worker processes: pickles whose classes are named after the
core package as each side imports it, and objects whose arrays live in a shared-memory segment.

The core is one package imported under two names: the add-on's (``restir_engine.core``, inside Blender
``bl_ext.<repository>.restir_engine.core``) in the rendering process, ``restir_core`` in a worker (which must not
import the add-on: its ``__init__`` imports bpy). :func:`loads` renames the classes a pickle refers to from the
sender's name to the receiver's.

:func:`pack` pickles an object (protocol 5) with its contiguous arrays' bytes out of band in one new segment;
:func:`unpack` rebuilds it in another process with those arrays as read-only views of the segment (no copy).
"""
from __future__ import annotations

import io
import pickle
from multiprocessing import shared_memory

ALIGN = 64


def core_name() -> str:
    """The name this process imports the core package under."""
    return __name__.rsplit(".parallel.", 1)[0]


class _Unpickler(pickle.Unpickler):
    def __init__(self, data: bytes, sender: str, buffers=None):
        super().__init__(io.BytesIO(data), buffers=buffers)
        self.sender, self.receiver = sender, core_name()

    def find_class(self, module, name):
        if module == self.sender or module.startswith(self.sender + "."):
            module = self.receiver + module[len(self.sender):]
        return super().find_class(module, name)


def dumps(obj) -> bytes:
    return pickle.dumps(obj, protocol=5)


def loads(data: bytes, sender: str, buffers=None):
    """Unpickle ``data`` written by a process whose core package is named ``sender``."""
    return _Unpickler(data, sender, buffers).load()


def create_segment(size: int) -> shared_memory.SharedMemory:
    """A new zero-filled segment of at least ``size`` bytes (the creating process unlinks it)."""
    return shared_memory.SharedMemory(create=True, size=max(int(size), ALIGN))


def attach_segment(name: str) -> shared_memory.SharedMemory:
    """An existing segment by name (a worker attaches; only its creator unlinks)."""
    return shared_memory.SharedMemory(name=name)


def release_segment(seg: shared_memory.SharedMemory) -> None:
    """Close this process's handle of ``seg``. Where arrays still view it, the mapping stays with them (it goes
    with the last of them) and the handle forgets it, so that closing again (SharedMemory.__del__) is quiet."""
    try:
        seg.close()
    except BufferError:
        seg._buf = seg._mmap = None


def unlink_segments(segs) -> None:
    """Close and unlink segments this process created (names already gone are fine)."""
    for seg in segs:
        release_segment(seg)
        try:
            seg.unlink()
        except OSError:  # FileNotFoundError included
            pass


def pack(obj):
    """(segment, description) of ``obj``: the description (bytes and names only) goes to the workers, the
    segment stays with the caller until no worker needs the object."""
    buffers = []
    head = pickle.dumps(obj, protocol=5, buffer_callback=buffers.append)
    raws = [b.raw() for b in buffers]
    layout, offset = [], 0
    for r in raws:
        layout.append((offset, r.nbytes))
        offset = -(-(offset + r.nbytes) // ALIGN) * ALIGN
    seg = create_segment(offset)
    for (start, n), r in zip(layout, raws):
        seg.buf[start:start + n] = r
    return seg, (head, seg.name, layout, core_name())


def unpack(description, keep: list):
    """The object of a :func:`pack` description; the attached segment is appended to ``keep`` (it must stay open
    while the object's arrays are used)."""
    head, name, layout, sender = description
    seg = attach_segment(name)
    keep.append(seg)
    view = seg.buf
    return loads(head, sender, [view[start:start + n].toreadonly() for start, n in layout])
