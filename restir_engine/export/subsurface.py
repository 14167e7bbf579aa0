"""The Principled BSDF's subsurface fields of a material row (core/integrators/subsurface.py walks them): the
Subsurface Weight (constant or from any graph: the program's "subsurface"), Radius x Scale, the method, the entry's
IOR and the phase function's anisotropy, as the running Blender's Cycles reads them (compat.RANDOM_WALK_MFP)."""
from __future__ import annotations

import numpy as np

from ..compat import RANDOM_WALK_MFP
from ..core.integrators.subsurface import WALK_CHIANG, WALK_SKIN, WALK_VAN_DE_HULST


def _method(node) -> int:
    """The walk (subsurface.WALK_*) Cycles runs for the node's Subsurface Method."""
    name = getattr(node, "subsurface_method", "RANDOM_WALK")
    if name == "RANDOM_WALK_SKIN":
        return WALK_SKIN
    if name == "RANDOM_WALK" and RANDOM_WALK_MFP:
        return WALK_VAN_DE_HULST
    return WALK_CHIANG  # Random Walk before 5.2, Random Walk (Legacy), and Christensen-Burley (reported)


def principled_subsurface(registry, material, node, row: dict, g, varying: dict, ior: float) -> None:
    """Fill ``row``'s subsurface fields from Principled ``node`` (``ior``: its IOR); nothing where the weight is 0.
    ``registry``: the MaterialRegistry (its _param and _warn)."""
    inp = node.inputs
    sock = inp.get("Subsurface Weight")
    if sock is None or not (sock.is_linked or float(sock.default_value) > 0):
        return
    weight = registry._param(material, g, sock, "float", "subsurface", varying)
    if "subsurface" not in varying and not weight > 0:
        return
    row["subsurface"] = float(np.clip(weight, 0, 1))
    method = _method(node)
    if getattr(node, "subsurface_method", "") == "BURLEY":
        registry._warn(material, "Christensen-Burley subsurface scattering is rendered as a random walk")
    radius = _constant(registry, material, g, inp["Subsurface Radius"], "vector")
    scale = _constant(registry, material, g, inp["Subsurface Scale"], "float")
    row["sss_radius"] = tuple(float(max(r * scale, 0.0)) for r in radius[:3])
    row["sss_method"] = method
    if method == WALK_SKIN:
        ior = _constant(registry, material, g, inp["Subsurface IOR"], "float") if "Subsurface IOR" in inp else 1.4
    row["sss_ior"] = float(np.clip(ior, 1.01, 3.8))
    aniso = _constant(registry, material, g, inp["Subsurface Anisotropy"], "float") \
        if "Subsurface Anisotropy" in inp else 0.0
    low = -0.99 if RANDOM_WALK_MFP else 0.0
    high = 0.99 if method == WALK_VAN_DE_HULST else 0.9
    row["sss_anisotropy"] = float(np.clip(aniso, low, high))


def _constant(registry, material, g, socket, kind: str):
    """A socket's value (its graph folded); one that varies over the surface is its unlinked value (reported)."""
    if kind == "float":
        return registry._float_input(material, socket)
    reg = g.value(socket, kind)
    if reg.const is not None:
        v = reg.constant_value()
    else:
        registry._warn(material, f"'{socket.name}' of '{socket.node.name}' varies over the surface; approximated "
                       "by the socket's value")
        v = socket.default_value
    return tuple(v)
