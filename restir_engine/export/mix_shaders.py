"""Mix and Add Shaders -> material rows: a constant-factor tree flattened into weighted component rows (a Transparent
BSDF leaf as the row's cut-out), or a per-hit mix program where a factor varies over the surface; textures as factors.
A mixin of MaterialRegistry (export/materials.py), whose rows, warnings and textures it uses."""
from __future__ import annotations

import dataclasses

import numpy as np

from .coat import base_albedo, coat_factors, coat_row, coat_set
from .sheen import sheen_layer, sheen_set
from .node_graph import GraphCompiler

# Mix/Add shader levels followed; deeper nests (Blender allows any) are cut off with a warning
MAX_MIX_DEPTH = 256


class MixShaderReader:
    """MaterialRegistry's Mix / Add Shader readers."""

    def _mix(self, material, node, depth: int) -> dict:
        """A row whose BSDF is the weighted sum of its flattened components (each its own table row); its emission
        is the weighted sum of theirs. Components without a BSDF (Emission, empty sockets) drop out of the sum.
        A Transparent BSDF leaf becomes the row's alpha cut-out (opacity 1 - its weight) and the other components
        are renormalized (opaque points reflect with the full BSDF; exact for Mix trees, whose weights sum to 1)."""
        if self._mix_varies(node, set()):
            return self._mix_program(material, node, depth)
        parts = self._flatten(material, node, depth, 1.0, -1, 0.0)
        if any(p[0].get("program") is not None and p[0]["program"].has("emission") for p in parts):
            return self._mix_program(material, node, depth)
        comps, emission, emit_tex = [], np.zeros(3, np.float32), -1
        out = {"base_color": (0.0, 0.0, 0.0), "f0": 0.0}
        clear = [p for p in parts if p[0].get("transparent")]
        if any(p[0].get("program") is not None for p in clear):  # a transparent colour that varies per hit
            return self._mix_program(material, node, depth)
        if clear:
            if len(clear) > 1 or node.type == "ADD_SHADER":
                self._warn(material, "transparency added to other shaders or in several places is approximated")
            _row, w, tex, sign = clear[0]
            if tex >= 0 and abs(w - 1) < 1e-6:
                out.update(alpha=1.0, alpha_tex=tex, alpha_sign=-sign)
            else:
                if tex >= 0:
                    self._warn(material, "a textured transparency under a constant Mix factor is approximated")
                out["alpha"] = float(np.clip(1 - w * (0.5 if tex >= 0 else 1.0), 0, 1))
            out["mix_normalize"] = True
        see_through = 0.0  # the share of leaves' own Alpha (Principled): transparent, as a Transparent BSDF's
        for i, (row, weight, tex, sign) in enumerate(parts):
            if row.get("transparent"):
                continue
            a = float(row.get("alpha", 1.0))
            if a < 1:
                if tex >= 0:
                    self._warn(material, "an Alpha under a textured Mix factor is approximated by its value")
                see_through += weight * (1 - a) * (0.5 if tex >= 0 else 1.0)
                weight *= a
            if row.get("alpha_tex", -1) >= 0 or row.get("alpha_program"):
                self._warn(material, "alpha inside a Mix/Add shader is ignored (rendered opaque)")
            e = np.asarray(row.get("emission", (0, 0, 0)), np.float32)
            if e.any():
                if tex >= 0:
                    self._warn(material, "emission under a textured Mix factor is approximated by half its strength")
                emission += e * weight * (0.5 if tex >= 0 else 1.0)
                if row.get("emit_tex", -1) >= 0:
                    emit_tex = row["emit_tex"]
            if _has_bsdf(row):
                comp = dict(row, emission=(0.0, 0.0, 0.0), emit_tex=-1, alpha=1.0, alpha_tex=-1, alpha_program=False,
                            name=f"{material.name} ({len(comps) + 1})")
                comps.append((self.add_row(comp), float(weight), int(tex), float(sign)))
        if see_through > 0:
            out["alpha"] = float(np.clip(out.get("alpha", 1.0) - see_through, 0, 1))
            out["mix_normalize"] = True
        if clear:  # the colour passed: the transparent leaf's, and white for the leaves' own Alpha
            w_clear = clear[0][1] * (0.5 if clear[0][2] >= 0 else 1.0)
            tint = np.asarray(clear[0][0].get("transparent_tint", (1, 1, 1)), np.float64)
            total = w_clear + see_through
            if total > 0 and np.any(np.abs(tint - 1) > 1e-6):
                out["transparent_tint"] = tuple(((w_clear * tint + see_through) / total).tolist())
        out.update(emission=tuple(emission.tolist()), mix=comps)
        if emit_tex >= 0:
            out["emit_tex"] = emit_tex
        return out

    def _mix_varies(self, node, seen: set) -> bool:
        """Whether a Mix/Add tree has a factor that varies over the surface other than a plain Image Texture
        (those go to the fixed texture path)."""
        if coat_set(node) or sheen_set(node):  # a coat / sheen and a base component (export/coat.py, sheen.py)
            return True
        if node.type == "BSDF_PRINCIPLED" and "Alpha" in node.inputs and node.inputs["Alpha"].is_linked:
            return True  # its alpha joins the mix's transparent share per hit
        if node.type not in {"MIX_SHADER", "ADD_SHADER"} or node.name in seen:
            return False
        seen.add(node.name)
        if node.type == "MIX_SHADER":
            fac = node.inputs["Fac"]
            if fac.is_linked and fac.links[0].from_node.type not in {"TEX_IMAGE", "VALUE"}:
                return True
            if fac.is_linked and fac.links[0].from_node.type == "TEX_IMAGE":
                img = fac.links[0].from_node
                if (img.inputs["Vector"].is_linked or img.interpolation not in {"Linear", "Closest"}
                        or img.extension != "REPEAT"):
                    return True
        return any(self._mix_varies(s.links[0].from_node, seen) for s in node.inputs
                   if s.type == "SHADER" and s.is_linked)

    def _mix_program(self, material, node, depth: int) -> dict:
        """A Mix/Add tree whose weights vary over the surface: each leaf's weight (the sum over its paths of the
        product of the factors along them, Fac clamped to [0, 1] as Cycles) and the weighted emission are outputs
        of the mix row's node program ("mix:<k>" for component k, "emission"); components keep weight 1. A coated
        Principled BSDF (``node`` itself, or a leaf) becomes two components, its coat and its base (export/coat.py),
        the base's Coat Tint factor the program's "mix_tint:<k>"; one with a sheen gets a sheen component on top
        (export/sheen.py)."""
        g = self._compiler(material)
        weights: dict = {}
        order: list = []

        def walk(nd, w, level):
            if nd.type not in {"MIX_SHADER", "ADD_SHADER"}:
                if nd.name in weights:
                    weights[nd.name] = (nd, g.emit("add", {}, [weights[nd.name][1], w], ("float",))[0])
                else:
                    weights[nd.name] = (nd, w)
                    order.append(nd.name)
                return
            if level >= MAX_MIX_DEPTH:
                self._warn(material, f"shader mixes nested deeper than {MAX_MIX_DEPTH} levels are cut off")
                return
            shaders = [sk for sk in nd.inputs if sk.type == "SHADER"]
            if nd.type == "ADD_SHADER":
                ws = [w, w]
            else:
                fac = g.emit("saturate", {}, [g.value(nd.inputs["Fac"], "float")], ("float",))[0]
                rest = g.emit("one_minus", {}, [fac], ("float",))[0]
                ws = [g.emit("multiply", {}, [w, rest], ("float",))[0], g.emit("multiply", {}, [w, fac], ("float",))[0]]
            for sk, ww in zip(shaders, ws):
                if sk.is_linked:
                    walk(sk.links[0].from_node, ww, level + 1)
        walk(node, g.constant(1.0, "float"), 0)
        out = {"base_color": (0.0, 0.0, 0.0), "f0": 0.0}
        comps, outputs, emission, clear = [], {}, None, None
        passed, coloured = None, False  # the colour let through, weighted by each transparent share (clear)
        for name in order:
            leaf, w = weights[name]
            if leaf.type == "BSDF_PRINCIPLED" and "Alpha" in leaf.inputs:  # its see-through share, per hit
                a = g.emit("saturate", {}, [g.value(leaf.inputs["Alpha"], "float")], ("float",))[0]
                if a.const is None or a.constant_value() < 1:
                    share = g.emit("multiply", {}, [w, g.emit("one_minus", {}, [a], ("float",))[0]], ("float",))[0]
                    clear = share if clear is None else g.emit("add", {}, [clear, share], ("float",))[0]
                    passed = _add_colour(g, passed, g.constant((1.0, 1.0, 1.0), "color"), share)
                    w = g.emit("multiply", {}, [w, a], ("float",))[0]
            sheen = sheen_layer(self, material, g, leaf) if sheen_set(leaf) else None
            coat = coat_factors(g, leaf) if coat_set(leaf) else None
            row = self._shader(material, leaf, depth + 1, base_only=coat is not None or sheen is not None)
            tint = None
            if sheen is not None:  # the sheen on top of the coat, the base and the emission
                s_row, s_w, s_layer, s_reflectance = sheen
                outputs[f"mix_pick:{len(comps)}"] = s_reflectance
                if coat is None:
                    outputs[f"mix_pick:{len(comps) + 1}"] = g.constant(max(base_albedo(row), 1e-3), "float")
                index = self.add_row(dict(s_row, name=f"{material.name} ({len(comps) + 1}, sheen)"))
                _add_component(comps, outputs, index, g.emit("multiply", {}, [w, s_w], ("float",))[0])
                w = g.emit("multiply", {}, [w, s_layer], ("float",))[0]
            if coat is not None:  # the coat, then the base under it
                coat_w, layer, tint, reflectance = coat
                outputs[f"mix_pick:{len(comps)}"] = reflectance
                outputs[f"mix_pick:{len(comps) + 1}"] = g.constant(max(base_albedo(row), 1e-3), "float")
                index = self.add_row(dict(coat_row(self, material, leaf), name=f"{material.name} ({len(comps) + 1}, coat)"))
                _add_component(comps, outputs, index, g.emit("multiply", {}, [w, coat_w], ("float",))[0])
                w = g.emit("multiply", {}, [w, layer], ("float",))[0]
            if row.get("transparent"):  # opacity 1 - w; summed over transparent leaves
                clear = w if clear is None else g.emit("add", {}, [clear, w], ("float",))[0]
                colour = g.value(leaf.inputs["Color"], "color")
                coloured |= colour.const is None or bool(np.any(np.abs(np.asarray(colour.const) - 1) > 1e-6))
                passed = _add_colour(g, passed, colour, w)
                continue
            e = self._leaf_emission(g, leaf)
            if e is not None:
                e = g.emit("scale", {}, [e, w], ("color",))[0]
                if tint is not None:
                    e = g.emit("multiply", {}, [e, tint], ("color",))[0]
                emission = e if emission is None else g.emit("add", {}, [emission, e], ("color",))[0]
            if _has_bsdf(row):
                comp = dict(row, emission=(0.0, 0.0, 0.0), emit_tex=-1, alpha=1.0, alpha_tex=-1, alpha_program=False,
                            name=f"{material.name} ({len(comps) + 1})")
                prog = comp.get("program")
                if prog is not None and prog.has("emission"):
                    comp["program"] = dataclasses.replace(prog, outputs={k: v for k, v in prog.outputs.items()
                                                                         if k != "emission"})
                if tint is not None:
                    outputs[f"mix_tint:{len(comps)}"] = tint
                _add_component(comps, outputs, self.add_row(comp), w)
        if clear is not None:
            _cut_out_share(g, clear, out, outputs, comps)
            if coloured:
                _transparent_tint(g, passed, clear, out, outputs)
        if emission is not None:
            if emission.const is not None:
                out["emission"] = emission.constant_value()
            else:
                outputs["emission"] = emission
        out["mix"] = comps
        return self._with_program(out, g, outputs, keep=[f for f in outputs if f.startswith("mix_pick:")])

    def _leaf_emission(self, g: GraphCompiler, leaf):
        """The emitted radiance of a Mix leaf as a register of ``g`` (None for a shader that does not emit)."""
        if leaf.type == "EMISSION":
            return g.emit("scale", {}, [g.value(leaf.inputs["Color"], "color"),
                                        g.value(leaf.inputs["Strength"], "float")], ("color",))[0]
        if leaf.type == "BSDF_PRINCIPLED":
            e = g.emit("scale", {}, [g.value(leaf.inputs["Emission Color"], "color"),
                                     g.value(leaf.inputs["Emission Strength"], "float")], ("color",))[0]
            return None if e.const is not None and not np.any(e.const) else e
        return None

    def _flatten(self, material, node, depth: int, weight: float, tex: int, sign: float) -> list:
        """[(row, weight, factor texture, sign)]: the leaves of a Mix/Add tree with the products of their constant
        weights, a leaf reached along several paths once with the sum of their weights; sign +1 weighs a leaf by the
        factor texture t, -1 by 1 - t (0: no texture). One textured factor per leaf is supported; deeper ones use
        their socket's value (reported)."""
        leaves = self._mix_leaves(material, node, weight, tex, sign, {}, 0)
        return [(self._shader(material, leaf, depth + 1), w, tx, sg) for leaf, w, tx, sg in leaves]

    def _mix_leaves(self, material, node, weight: float, tex: int, sign: float, memo: dict, level: int) -> list:
        """[(leaf node, weight, factor texture, sign)] under ``node``; ``memo`` holds each (node, texture, sign)'s
        leaves at weight 1, so a tree that reuses a sub-mix costs its nodes, not its paths."""
        if node.type not in {"MIX_SHADER", "ADD_SHADER"}:
            return [(node, weight, tex, sign)]
        if level >= MAX_MIX_DEPTH:
            self._warn(material, f"shader mixes nested deeper than {MAX_MIX_DEPTH} levels are cut off")
            return []
        key = (node.name, tex, sign)
        if key not in memo:
            memo[key] = self._mix_children(material, node, tex, sign, memo, level)
        return [(leaf, w * weight, tx, sg) for leaf, w, tx, sg in memo[key]]

    def _mix_children(self, material, node, tex: int, sign: float, memo: dict, level: int) -> list:
        shaders = [s for s in node.inputs if s.type == "SHADER"]
        if node.type == "ADD_SHADER":
            ws = [(1.0, tex, sign)] * 2
        else:
            fac_socket = node.inputs["Fac"]
            fac_tex = self._factor_texture(material, fac_socket) if tex < 0 else -1
            if fac_tex >= 0:
                ws = [(1.0, fac_tex, -1.0), (1.0, fac_tex, 1.0)]
            else:
                if fac_socket.is_linked and tex >= 0:
                    self._warn(material, f"'{node.name}': a second textured Mix factor is approximated by its value")
                fac = float(np.clip(self._float_input(material, fac_socket), 0, 1))
                ws = [(1 - fac, tex, sign), (fac, tex, sign)]
        merged: dict = {}  # a leaf reached along several paths: once, with the sum of their weights
        for socket, (w, tx, sg) in zip(shaders, ws):
            if socket.is_linked and w > 0:
                for leaf, lw, ltx, lsg in self._mix_leaves(material, socket.links[0].from_node, w, tx, sg, memo,
                                                            level + 1):
                    key = (leaf.name, ltx, lsg)
                    merged[key] = (leaf, merged[key][1] + lw if key in merged else lw, ltx, lsg)
        return list(merged.values())


def _add_component(comps: list, outputs: dict, index: int, weight) -> None:
    """Append row ``index`` to the mix's components with ``weight`` (a register): its constant, or weight 1 and the
    program's "mix:<k>" output where it varies."""
    if weight.const is not None:
        comps.append((index, weight.constant_value(), -1, 0.0))
    else:
        outputs[f"mix:{len(comps)}"] = weight
        comps.append((index, 1.0, -1, 0.0))


def _add_colour(g: GraphCompiler, passed, colour, share):
    """The register ``passed`` (None: nothing yet) plus ``colour`` weighted by the transparent ``share``."""
    c = g.emit("scale", {}, [colour, share], ("color",))[0]
    return c if passed is None else g.emit("add", {}, [passed, c], ("color",))[0]


def _transparent_tint(g: GraphCompiler, passed, clear, out: dict, outputs: dict) -> None:
    """The colour a mix row's transparent points pass, ``passed`` (the leaves' colours weighted by their shares) per
    unit of its transparent share ``clear``: the row's constant, or the program's "transparent_tint"."""
    tint = g.emit("scale", {}, [passed, g.emit("reciprocal", {}, [clear], ("float",))[0]], ("color",))[0]
    if tint.const is not None:
        out["transparent_tint"] = tuple(float(max(c, 0.0)) for c in tint.constant_value())
    else:
        outputs["transparent_tint"] = tint


def _cut_out_share(g: GraphCompiler, clear, out: dict, outputs: dict, comps: list) -> None:
    """A mix row's transparent share ``clear`` (a register): its opacity as the row's cut-out alpha (constant, or
    the program's "alpha"), and the components' weights (``comps``, the program's "mix:<k>") divided by it, since
    only the opaque points are shaded."""
    opacity = g.emit("saturate", {}, [g.emit("one_minus", {}, [clear], ("float",))[0]], ("float",))[0]
    if opacity.const is not None:
        out["alpha"] = opacity.constant_value()
    else:
        outputs["alpha"] = opacity
        out["alpha_program"] = True
    inv = g.emit("reciprocal", {}, [opacity], ("float",))[0]
    for k, (index, weight, tex, sign) in enumerate(comps):
        w = outputs.get(f"mix:{k}")
        if w is None and inv.const is not None:
            comps[k] = (index, weight * inv.constant_value(), tex, sign)
            continue
        w = g.constant(weight, "float") if w is None else w
        outputs[f"mix:{k}"] = g.emit("multiply", {}, [w, inv], ("float",))[0]
        comps[k] = (index, 1.0, tex, sign)


def _has_bsdf(row: dict) -> bool:
    """Whether a row reflects any light (a black non-metal without specular, e.g. an Emission shader, does not)."""
    if row.get("transparent"):
        return False
    return (row.get("base_tex", -1) >= 0 or any(c > 0 for c in row.get("base_color", (0.8, 0.8, 0.8)))
            or row.get("f0", 0.04) > 0 or row.get("metallic", 0.0) > 0 or bool(row.get("mix"))
            or row.get("transmission", 0.0) > 0)
