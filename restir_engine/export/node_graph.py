"""A material's shader node graph -> a vectorized node program (core/materials/nodes).

:class:`GraphCompiler` follows links back from the sockets a closure reads, through node groups (flattened),
reroutes and muted nodes, and emits one instruction per node output it needs; sockets that are not linked are
constants, and a node whose inputs are all constant is evaluated here (constant folding), so a socket whose graph
does not vary over the surface costs nothing at render time. Socket types convert as Blender converts them
(colour -> float: luminance; vector -> float: the mean; float -> vector / colour: splat). Nodes the evaluator does
not know give their output socket's default value, named in one warning. The node handlers are in
export/node_handlers.py."""
from __future__ import annotations

import numpy as np

from ..core.materials.nodes.program import READS_HITS, Program, evaluate_constant

#: node group levels followed (recursive groups are cut off with a warning)
MAX_GROUP_DEPTH = 64

_KIND = {"VALUE": "float", "INT": "float", "BOOLEAN": "float", "VECTOR": "vector", "RGBA": "color"}


class Reg:
    """A value in a program: its register, kind ("float", "vector", "color") and constant value (or None)."""

    __slots__ = ("index", "kind", "const")

    def __init__(self, index: int, kind: str, const=None):
        self.index, self.kind, self.const = index, kind, const

    def constant_value(self):
        """The constant as a Python float or RGB tuple."""
        c = np.asarray(self.const, np.float32)
        return float(c.reshape(-1)[0]) if self.kind == "float" else tuple(float(x) for x in c.reshape(3))


class Frame:
    """A node group being compiled: the group node (None at the top) and the frame it sits in."""

    def __init__(self, group_node=None, parent=None):
        self.group_node, self.parent = group_node, parent
        self.depth = 0 if parent is None else parent.depth + 1


class GraphCompiler:
    """Compiles sockets of one material's node tree. ``textures(image, alpha)`` returns the texture index of an
    image's colour (or alpha) for the material table; ``warn(reason)`` reports an approximation."""

    def __init__(self, textures, warn):
        self._textures, self._warn = textures, warn
        self.ops: list = []
        self.consts: dict = {}
        self.reads: set = set()
        self._next = 0
        self._vectors: set = set()
        self._memo: dict = {}
        self._frames: dict = {}
        self.top = Frame()
        self.camera = None        # the core Camera of Texture Coordinate's Camera / Window outputs (None: unknown)
        self.material_index = 0.0  # the material's Pass Index (Object Info > Material Index)

    # -- registers --------------------------------------------------------------------------------------------
    def _new(self, kind: str, const=None) -> Reg:
        r = Reg(self._next, kind, const)
        self._next += 1
        if kind != "float":
            self._vectors.add(r.index)
        if const is not None:
            self.consts[r.index] = const
        return r

    def constant(self, value, kind: str) -> Reg:
        if kind == "float":
            return self._new(kind, np.float32(np.asarray(value, np.float32).reshape(-1)[0]))
        v = np.asarray(value, np.float32).reshape(-1)[:3]
        if v.size == 1:
            v = np.repeat(v, 3)
        return self._new(kind, v.reshape(3, 1).copy())

    def emit(self, op: str, params: dict, ins: list, kinds: tuple) -> list:
        """Output registers of one operation; folded into constants when every input is one."""
        if op not in READS_HITS and all(r.const is not None for r in ins):
            got = evaluate_constant(op, params, *[r.const for r in ins])
            got = got if len(kinds) > 1 else (got,)
            return [self._new(k, np.asarray(g, np.float32) if k == "float" else
                              np.asarray(g, np.float32).reshape(3, 1)) for g, k in zip(got, kinds)]
        outs = [self._new(k) for k in kinds]
        self.ops.append((op, tuple(o.index for o in outs), tuple(r.index for r in ins), params))
        return outs

    def attribute(self, name: str, kind: str) -> Reg:
        key = ("attr", name)
        if key not in self._memo:
            self.reads.add(name)
            self._memo[key] = self.emit("attribute", {"name": name}, [], (kind,))[0]
        return self._memo[key]

    def convert(self, reg: Reg, kind: str) -> Reg:
        if reg.kind == kind or {reg.kind, kind} == {"vector", "color"}:
            return reg if reg.kind == kind else Reg(reg.index, kind, reg.const)
        if kind == "float":
            return self.emit("color_to_float" if reg.kind == "color" else "vector_to_float", {}, [reg], ("float",))[0]
        return self.emit("float_to_vector", {}, [reg], (kind,))[0]

    def program(self, outputs: dict, constants: bool = False, keep=()) -> Program | None:
        """A Program computing ``outputs`` (field -> Reg) that vary (all of them with ``constants``, and those named
        in ``keep`` whether they vary or not); None when none is left."""
        varying = {f: r for f, r in outputs.items() if r is not None and (constants or r.const is None or f in keep)}
        if not varying:
            return None
        return Program(ops=list(self.ops), consts=dict(self.consts),
                       outputs={f: (r.index, "float" if r.kind == "float" else "rgb") for f, r in varying.items()},
                       reads=tuple(sorted(self.reads)), vectors=tuple(sorted(self._vectors)))

    # -- sockets ----------------------------------------------------------------------------------------------
    def value(self, socket, kind: str | None = None, default: str | None = None, frame: Frame | None = None) -> Reg:
        """The value arriving at input ``socket`` as ``kind`` (its own kind when None); ``default`` names the hit
        attribute an unlinked socket reads instead of its value (a texture's Vector: "generated" or "uv")."""
        frame = frame or self.top
        kind = kind or _KIND.get(socket.type, "float")
        link = next((lk for lk in socket.links if not lk.is_muted and lk.is_valid), None) if socket.is_linked else None
        if link is None:
            if default is not None:
                return self.convert(self.attribute(default, "vector" if default != "backfacing" else "float"), kind)
            if not hasattr(socket, "default_value"):
                return self.constant(0.0, kind)
            return self.constant(socket_default(socket), kind)
        got = self.output(link.from_node, link.from_socket, frame)
        return self.convert(got, kind)

    def output(self, node, socket, frame: Frame) -> Reg:
        """The value of output ``socket`` of ``node``."""
        key = (id(frame), node.name, socket.identifier)
        if key in self._memo:
            return self._memo[key]
        if node.type == "REROUTE":
            got = self.value(node.inputs[0], None, frame=frame) if node.inputs else self.constant(0.0, "float")
            got = self.convert(got, _KIND.get(socket.type, got.kind)) if socket.type in _KIND else got
        elif node.mute:
            got = self._muted(node, socket, frame)
        elif node.type == "GROUP":
            got = self._group(node, socket, frame)
        elif node.type == "GROUP_INPUT":
            got = self._group_input(socket, frame)
        else:
            from .node_handlers import HANDLERS  # the handlers build on this module's registers
            handler = HANDLERS.get(node.type)
            outs = handler(self, node, frame) if handler is not None else None
            if outs is None or socket.identifier not in outs:
                self._warn(f"'{node.name}' ({node.type}) is not supported here; its output '{socket.name}' is "
                           "approximated by a constant")
                got = self.constant(socket_default(socket) if hasattr(socket, "default_value") else 0.0,
                                    _KIND.get(socket.type, "float"))
            else:
                for ident, reg in outs.items():
                    self._memo[(id(frame), node.name, ident)] = reg
                got = outs[socket.identifier]
        self._memo[key] = got
        return got

    def _muted(self, node, socket, frame):
        for lk in node.internal_links:
            if lk.to_socket.identifier == socket.identifier:
                return self.value(lk.from_socket, _KIND.get(socket.type, "float"), frame=frame)
        return self.constant(0.0, _KIND.get(socket.type, "float"))

    def _group(self, node, socket, frame):
        tree = node.node_tree
        kind = _KIND.get(socket.type, "float")
        if tree is None:
            return self.constant(0.0, kind)
        if frame.depth >= MAX_GROUP_DEPTH:
            self._warn(f"node groups nested deeper than {MAX_GROUP_DEPTH} levels are cut off")
            return self.constant(0.0, kind)
        key = (id(frame), node.name)
        inner = self._frames.get(key)
        if inner is None:
            inner = self._frames[key] = Frame(node, frame)
        outs = [n for n in tree.nodes if n.type == "GROUP_OUTPUT"]
        out = next((n for n in outs if getattr(n, "is_active_output", False)), outs[0] if outs else None)
        if out is None:
            return self.constant(0.0, kind)
        target = next((s for s in out.inputs if s.identifier == socket.identifier), None)
        if target is None:
            return self.constant(0.0, kind)
        return self.value(target, kind, frame=inner)

    def _group_input(self, socket, frame):
        kind = _KIND.get(socket.type, "float")
        group = frame.group_node
        if group is None:
            return self.constant(0.0, kind)
        target = next((s for s in group.inputs if s.identifier == socket.identifier), None)
        if target is None:
            return self.constant(0.0, kind)
        return self.value(target, kind, frame=frame.parent)

    # -- helpers for handlers -----------------------------------------------------------------------------------
    def inp(self, node, ident: str, kind: str | None = None, frame=None, default: str | None = None) -> Reg:
        sock = next((s for s in node.inputs if s.identifier == ident), None)
        if sock is None:
            sock = node.inputs.get(ident)
        if sock is None:
            return self.constant(0.0, kind or "float")
        return self.value(sock, kind, default=default, frame=frame)

    def texture(self, image, alpha: bool) -> int:
        return self._textures(image, alpha)

    def warn(self, reason: str) -> None:
        self._warn(reason)


def socket_default(socket):
    """The constant a socket holds when nothing is linked to it: a float or the first three components."""
    v = socket.default_value
    try:
        return tuple(v)[:3]
    except TypeError:
        return float(v)
