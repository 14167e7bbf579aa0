"""A BSDF's Normal input -> the material row: a tangent-space Normal Map of an Image Texture and a Bump of an Image
Texture as the row's own texture fields (read at render time without a node program, core/materials/image_normals.py),
any other graph as the node program's normal. A mixin of MaterialRegistry (export/materials.py)."""
from __future__ import annotations

from .node_graph import GraphCompiler


class NormalReader:
    """MaterialRegistry's normal readers (``self._texture``, ``self._float_input``, ``self._warn``)."""

    def _normal(self, material, node, row: dict, g: GraphCompiler | None = None, varying: dict | None = None,
                socket=None) -> None:
        """A BSDF's Normal input (or ``socket``). A tangent-space Normal Map of an Image Texture and a Bump of an
        Image Texture (over nothing or such a Normal Map) -> the row's normal_tex / bump_tex fields (read at render
        time without a node program); any other graph -> ``varying["normal"]``, the node program's normal (Normal
        Map and Bump of any input)."""
        socket = node.inputs.get("Normal") if socket is None else socket
        if socket is None or not socket.is_linked:
            return
        if self._image_normal(material, socket.links[0].from_node, row):
            return
        if g is None:
            self._warn(material, f"the Normal input of '{node.name}' is not supported here; the mesh normal is used")
            return
        reg = g.value(socket, "vector", default="normal")
        if reg.const is None:
            varying["normal"] = reg

    def _image_normal(self, material, src, row: dict) -> bool:
        """Normal Map / Bump of plain Image Textures -> row fields; False (row unchanged) for anything else."""
        bump = None
        if src.type == "BUMP":
            bump = src
            inner = src.inputs.get("Normal")
            src = inner.links[0].from_node if inner is not None and inner.is_linked else None
            height = bump.inputs["Height"]
            img = height.links[0].from_node if height.is_linked else None
            if img is None or img.type != "TEX_IMAGE" or img.image is None or img.inputs["Vector"].is_linked:
                return False
        nmap = None
        if src is not None:
            col = src.inputs.get("Color") if src.type == "NORMAL_MAP" else None
            img = col.links[0].from_node if col is not None and col.is_linked else None
            if (src.type != "NORMAL_MAP" or src.space != "TANGENT" or img is None or img.type != "TEX_IMAGE"
                    or img.image is None or img.inputs["Vector"].is_linked or src.inputs["Strength"].is_linked
                    or src.uv_map):  # a named UV map's tangents: the node program reads them
                return False
            nmap = (src, img)
        if bump is not None and not self._bump(material, bump, row):
            return False
        if nmap is not None:
            src, img = nmap
            row["normal_tex"] = self._texture(material, img.image, closest=img.interpolation == "Closest")
            row["normal_strength"] = self._float_input(material, src.inputs["Strength"])
        return True

    def _bump(self, material, node, row: dict) -> bool:
        """A Bump node with an Image Texture on Height (Color as luminance, or Alpha) -> row fields; False when
        its height is anything else or its inputs are linked."""
        height = node.inputs["Height"]
        link = height.links[0] if height.is_linked else None
        img = link.from_node if link is not None else None
        if img is None or img.type != "TEX_IMAGE" or img.image is None:
            return False
        if node.inputs["Strength"].is_linked or node.inputs["Distance"].is_linked:
            return False
        sign = -1.0 if getattr(node, "invert", False) else 1.0
        alpha = link.from_socket.name == "Alpha"
        row["bump_tex"] = self._texture(material, img.image, alpha=alpha, luminance=not alpha,
                                        closest=img.interpolation == "Closest")
        row["bump_strength"] = max(0.0, self._float_input(material, node.inputs["Strength"]))
        row["bump_distance"] = sign * self._float_input(material, node.inputs["Distance"])
        return True
