"""A material's node tree seen with its node groups and reroutes dissolved: read-only proxies of Blender's nodes and
sockets whose links lead straight to the node that computes a value, wherever it sits.

An input socket's link is followed through reroutes, into a group node's active Group Output and out of a Group
Input to the socket of the group node it stands for, so the shader readers (export/materials.py,
export/mix_shaders.py, export/coat.py) and the node-graph compiler (export/node_graph.py) meet shader nodes and
texture nodes inside groups as if they were in the material's own tree. A socket whose chain ends unlinked holds the
value of the last group socket on the way (a group's interface default, or the value typed on the group node),
converted to the socket's own type as Blender converts it (colour -> float: luminance; vector -> float: mean; float
-> colour/vector: splat). A node inside a group has the name "<group node>/<node>" (unique per group instance).
Everything else is read from the Blender node or socket itself.
"""
from __future__ import annotations

#: group levels followed (a group that contains itself is cut off there, as the node compiler does)
MAX_DEPTH = 64

_SCALAR = {"VALUE", "INT", "BOOLEAN"}
_LUMA = (0.2126, 0.7152, 0.0722)


class FlatTree:
    """The proxies of one material's node tree, one per (group path, node), so that identity and names are stable."""

    def __init__(self):
        self._nodes: dict = {}

    def node(self, real, path: tuple = ()) -> "FlatNode":
        key = (tuple(n.as_pointer() for n in path), real.as_pointer())
        got = self._nodes.get(key)
        if got is None:
            got = self._nodes[key] = FlatNode(self, real, path)
        return got


def cycles_output(tree, node_type: str):
    """The output node of type ``node_type`` ("OUTPUT_MATERIAL", "OUTPUT_WORLD", "OUTPUT_LIGHT") that Cycles renders:
    one whose target is Cycles rather than All, then the active one; never an EEVEE-only output. None if there is
    none."""
    best = None
    for node in tree.nodes:
        if node.type != node_type or getattr(node, "target", "ALL") not in {"ALL", "CYCLES"}:
            continue
        key = (getattr(node, "target", "ALL") == "CYCLES", bool(getattr(node, "is_active_output", False)))
        if best is None or key > best[0]:
            best = (key, node)
    return None if best is None else best[1]


def flat_output(material_output) -> "FlatNode":
    """The proxy of a material's (or world's, or light's) output node, the root the shader readers start from."""
    return FlatTree().node(material_output)


class FlatNode:
    """A node of the dissolved tree: its inputs' links resolved; any other attribute is the Blender node's."""

    __slots__ = ("_tree", "_node", "_path", "name", "_inputs")

    def __init__(self, tree: FlatTree, real, path: tuple):
        self._tree, self._node, self._path = tree, real, path
        self.name = "/".join([n.name for n in path] + [real.name])
        self._inputs = None

    def __getattr__(self, attr):
        return getattr(self._node, attr)

    def __repr__(self):
        return f"FlatNode({self.name!r}, {self._node.type})"

    @property
    def real(self):
        """The Blender node."""
        return self._node

    @property
    def inputs(self) -> "FlatInputs":
        if self._inputs is None:
            self._inputs = FlatInputs([FlatInput(self, s) for s in self._node.inputs])
        return self._inputs

    @property
    def internal_links(self) -> list:
        """A muted node's pass-throughs, their from-sockets resolved as this node's inputs."""
        by_id = {s.identifier: s for s in self.inputs}
        return [_InternalLink(by_id.get(lk.from_socket.identifier, lk.from_socket), lk.to_socket)
                for lk in self._node.internal_links]


class FlatInputs:
    """A node's input sockets by index, name or identifier, as Blender's collection is read."""

    __slots__ = ("_items",)

    def __init__(self, items: list):
        self._items = items

    def __iter__(self):
        return iter(self._items)

    def __len__(self):
        return len(self._items)

    def __getitem__(self, key):
        if isinstance(key, int):
            return self._items[key]
        got = self.get(key)
        if got is None:
            raise KeyError(key)
        return got

    def get(self, key, default=None):
        for s in self._items:
            if s.name == key:
                return s
        for s in self._items:
            if s.identifier == key:
                return s
        return default

    def __contains__(self, key):
        return self.get(key) is not None


class FlatInput:
    """An input socket whose link (at most one) leads to the node computing its value, wherever it is."""

    __slots__ = ("node", "_sock", "_resolved")

    def __init__(self, node: FlatNode, sock):
        self.node, self._sock, self._resolved = node, sock, None

    def __getattr__(self, attr):
        return getattr(self._sock, attr)

    def _resolve(self):
        if self._resolved is None:
            self._resolved = _resolve(self.node._tree, self._sock, self.node._path, self)
        return self._resolved

    @property
    def is_linked(self) -> bool:
        return self._resolve()[0] is not None

    @property
    def links(self) -> list:
        link = self._resolve()[0]
        return [link] if link is not None else []

    @property
    def default_value(self):
        source = self._resolve()[1]
        if source is self._sock:
            return self._sock.default_value
        return _converted(source.default_value, source.type, self._sock.type)


class FlatLink:
    """A resolved link: from a (proxied) node's output socket to a proxied input."""

    __slots__ = ("from_node", "from_socket", "to_node", "to_socket")
    is_muted = False
    is_valid = True

    def __init__(self, from_node, from_socket, to_socket):
        self.from_node, self.from_socket = from_node, from_socket
        self.to_node, self.to_socket = to_socket.node, to_socket


class _InternalLink:
    __slots__ = ("from_socket", "to_socket")

    def __init__(self, from_socket, to_socket):
        self.from_socket, self.to_socket = from_socket, to_socket


def _first_link(sock):
    if not sock.is_linked:
        return None
    return next((lk for lk in sock.links if not lk.is_muted and lk.is_valid), None)


def _active_group_output(tree):
    outs = [n for n in tree.nodes if n.type == "GROUP_OUTPUT"]
    return next((n for n in outs if getattr(n, "is_active_output", False)), outs[0] if outs else None)


def _resolve(tree: FlatTree, sock, path: tuple, asker: FlatInput):
    """(FlatLink or None, the socket whose value an unlinked chain takes) for Blender input ``sock`` in ``path``
    (the socket behind ``asker``)."""
    value = sock
    for _step in range(4 * MAX_DEPTH):
        link = _first_link(sock)
        if link is None:
            return None, value
        node, out = link.from_node, link.from_socket
        if node.type == "REROUTE":
            sock = node.inputs[0]
            continue
        if node.type == "GROUP" and not node.mute and node.node_tree is not None and len(path) < MAX_DEPTH:
            gout = _active_group_output(node.node_tree)
            target = None if gout is None else next((s for s in gout.inputs if s.identifier == out.identifier), None)
            if target is None:
                return None, value
            sock, value, path = target, target, path + (node,)
            continue
        if node.type == "GROUP_INPUT":
            if not path:
                return None, value
            target = next((s for s in path[-1].inputs if s.identifier == out.identifier), None)
            if target is None:
                return None, value
            sock, value, path = target, target, path[:-1]
            continue
        return FlatLink(tree.node(node, path), out, asker), None
    return None, value


def _converted(v, source_type: str, target_type: str):
    """A group socket's value ``v`` as an input of ``target_type`` reads it (Blender's implicit conversions)."""
    if source_type == target_type:
        return v
    if source_type in _SCALAR:
        x = float(v)
        if target_type == "RGBA":
            return (x, x, x, 1.0)
        if target_type == "VECTOR":
            return (x, x, x)
        return x
    comps = tuple(float(c) for c in v)
    if target_type in _SCALAR:
        if source_type == "RGBA":
            return sum(w * c for w, c in zip(_LUMA, comps[:3]))
        return sum(comps[:3]) / 3.0
    if target_type == "RGBA":
        return comps[:3] + (1.0,)
    if target_type == "VECTOR":
        return comps[:3]
    return v
