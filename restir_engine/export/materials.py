"""Blender materials -> MaterialTable rows (Principled parameters, emission radiance, Mix/Add components).

Supported exactly: Principled BSDF (Base Color, Metallic, Roughness, IOR, Specular IOR Level, Specular Tint,
Emission Color x Strength; Multiscatter GGX or GGX), Diffuse BSDF, Emission, Glossy BSDF, Mix Shader (constant
factor or an Image Texture's Color/Alpha) and Add Shader of these, and an Image Texture (UV) feeding Base Color /
Color / Emission Color. Anything else is approximated by its closest parameters and reported once per render,
naming the material and the reason.
"""
from __future__ import annotations

import numpy as np

from ..core.scene import DEFAULT_MATERIAL, MaterialTable
from ..compat import uses_nodes
from ..core.materials.textures import NearestImage
from .images import TEXTURES, srgb_bytes_to_linear, unreadable_file
from .limits import clamped_radiance

# Mix/Add shader levels followed; deeper nests (Blender allows any) are cut off with a warning
MAX_MIX_DEPTH = 256

MAGENTA = (1.0, 0.0, 1.0)


class MaterialRegistry:
    """Assigns table indices to Blender materials (index 0 is Blender's default grey) and
    collects textures; reports approximations through ``warnings``."""

    def __init__(self, warnings: list):
        self.warnings = warnings
        self.rows: list[dict] = [dict(DEFAULT_MATERIAL)]
        self.index: dict = {}
        self.textures: list[np.ndarray] = []
        self.texture_index: dict = {}

    # -- public -------------------------------------------------------------------------
    def material_index(self, material) -> int:
        if material is None:
            return 0
        key = material.name_full
        if key not in self.index:
            row = self._convert(material)
            row["name"] = material.name
            self.index[key] = len(self.rows)
            self.rows.append(row)
        return self.index[key]

    def add_row(self, row: dict) -> int:
        """A synthetic material (for lamps); returns its index."""
        self.rows.append(row)
        return len(self.rows) - 1

    def uses_normal_maps(self, indices) -> bool:
        def mapped(row: dict) -> bool:
            return row.get("normal_tex", -1) >= 0 or any(mapped(self.rows[c]) for c, *_r in row.get("mix", ()))
        # (a Bump alone needs no tangents: its surface gradient comes from the triangle's positions and UVs)
        return any(mapped(self.rows[i]) for i in indices)

    def uses_textures(self, indices) -> bool:
        def textured(row: dict) -> bool:
            if max(row.get(k, -1) for k in ("base_tex", "emit_tex", "alpha_tex", "normal_tex", "bump_tex")) >= 0:
                return True
            return any(tex >= 0 or textured(self.rows[comp]) for comp, _w, tex, _s in row.get("mix", ()))
        return any(textured(self.rows[i]) for i in indices)

    def table(self) -> MaterialTable:
        for row in self.rows:
            if "emission" in row:
                row["emission"] = tuple(clamped_radiance(row["emission"], f"Material '{row.get('name', '?')}' "
                                                         "emission", self.warnings).tolist())
        return MaterialTable.build(self.rows, self.textures)

    # -- conversion ---------------------------------------------------------------------
    def _warn(self, material, reason: str):
        self.warnings.append(f"Material '{material.name}': {reason}")

    def _convert(self, material) -> dict:
        if not uses_nodes(material):
            return {"base_color": tuple(material.diffuse_color[:3]), "metallic": float(material.metallic),
                    "roughness": float(material.roughness), "f0": 0.04}
        tree = material.node_tree
        outs = [n for n in tree.nodes if n.type == "OUTPUT_MATERIAL" and n.is_active_output
                and n.target in {"ALL", "CYCLES"}] or [n for n in tree.nodes if n.type == "OUTPUT_MATERIAL"]
        if not outs or not outs[0].inputs["Surface"].is_linked:
            self._warn(material, "no surface shader connected to the Material Output; rendered black")
            return {"base_color": (0.0, 0.0, 0.0), "f0": 0.0}
        return self._shader(material, outs[0].inputs["Surface"].links[0].from_node, depth=0)

    def _color_input(self, material, socket, key_tex: str, row: dict, fallback):
        """Constant colour of a socket, or 1 with a texture index when an Image Texture drives it."""
        if not socket.is_linked:
            return tuple(socket.default_value[:3])
        node = socket.links[0].from_node
        if node.type == "TEX_IMAGE" and node.image is not None and key_tex is not None:
            if node.inputs["Vector"].is_linked:
                self._warn(material, f"'{node.name}' has a mapped vector input; the active UV map is used instead")
            row[key_tex] = self._texture(material, node.image, closest=node.interpolation == "Closest")
            return (1.0, 1.0, 1.0)
        if node.type == "RGB":
            return tuple(node.outputs[0].default_value[:3])
        self._warn(material, f"'{node.name}' ({node.type}) drives '{socket.name}'; approximated by the socket's value")
        return tuple(socket.default_value[:3]) if hasattr(socket, "default_value") else fallback

    def _multiscatter(self, material, node) -> float:
        """1 for Multiscatter GGX (Blender's default), 0 for GGX; other distributions are approximated by one."""
        dist = getattr(node, "distribution", "MULTI_GGX")
        if dist in {"MULTI_GGX", "GGX"}:
            return 1.0 if dist == "MULTI_GGX" else 0.0
        self._warn(material, f"'{node.name}' distribution {dist} is approximated by Multiscatter GGX")
        return 1.0

    def _float_input(self, material, socket) -> float:
        if socket.is_linked:
            node = socket.links[0].from_node
            if node.type == "VALUE":
                return float(node.outputs[0].default_value)
            self._warn(material, f"'{node.name}' ({node.type}) drives '{socket.name}'; approximated by the socket's value")
        return float(socket.default_value)

    def _shader(self, material, node, depth: int) -> dict:
        t = node.type
        if t == "BSDF_PRINCIPLED":
            row: dict = {}
            inp = node.inputs
            row["base_color"] = self._color_input(material, inp["Base Color"], "base_tex", row, (0.8, 0.8, 0.8))
            row["metallic"] = self._float_input(material, inp["Metallic"])
            row["roughness"] = self._float_input(material, inp["Roughness"])
            ior = self._float_input(material, inp["IOR"]) if "IOR" in inp else 1.5
            level = self._float_input(material, inp["Specular IOR Level"]) if "Specular IOR Level" in inp else 0.5
            row["f0"] = float(np.clip(((ior - 1) / (ior + 1)) ** 2 * 2 * max(level, 0.0), 0, 1))
            if "Specular Tint" in inp:
                row["specular_tint"] = self._color_input(material, inp["Specular Tint"], None, row, (1, 1, 1))
            row["multiscatter"] = self._multiscatter(material, node)
            if "Anisotropic" in inp and (inp["Anisotropic"].is_linked or float(inp["Anisotropic"].default_value) > 0):
                self._warn(material, "Principled 'Anisotropic' is not supported; rendered isotropic")
            strength = self._float_input(material, inp["Emission Strength"])
            ec = self._color_input(material, inp["Emission Color"], "emit_tex", row, (0, 0, 0))
            row["emission"] = tuple(np.array(ec, np.float32) * strength)
            if row.get("emit_tex", -1) >= 0 and strength == 0:
                row["emit_tex"] = -1
            for name in ("Coat Weight", "Sheen Weight", "Subsurface Weight"):
                if name in inp and (inp[name].is_linked or float(inp[name].default_value) > 0):
                    self._warn(material, f"Principled '{name}' is not supported and was ignored")
            if "Transmission Weight" in inp:
                self._principled_transmission(material, inp, row, ior)
            if "Diffuse Roughness" in inp:
                row["diffuse_roughness"] = float(np.clip(self._float_input(material, inp["Diffuse Roughness"]), 0, 1))
            if "Alpha" in inp:
                self._alpha(material, inp["Alpha"], row)
            self._normal(material, node, row)
            return row
        if t == "BSDF_GLASS":
            c = self._color_input(material, node.inputs["Color"], None, {}, (1, 1, 1))
            ior = self._float_input(material, node.inputs["IOR"])
            rough = float(np.clip(self._float_input(material, node.inputs["Roughness"]), 0, 1))
            return {"base_color": (0.0, 0.0, 0.0), "f0": 0.0, "transmission": 1.0, "glass_ior": max(ior, 1e-3),
                    "glass_reflect": tuple(c), "glass_refract": tuple(c), "glass_alpha": rough * rough,
                    "glass_multiscatter": self._multiscatter(material, node)}
        if t == "BSDF_TRANSPARENT":
            c = self._color_input(material, node.inputs["Color"], None, {}, (1, 1, 1))
            if min(c) < 0.999:
                self._warn(material, "a coloured Transparent BSDF is approximated by a white one (a cut-out)")
            return {"base_color": (0.0, 0.0, 0.0), "f0": 0.0, "transparent": True, "alpha": 0.0}
        if t == "BSDF_DIFFUSE":
            row = {"f0": 0.0, "metallic": 0.0}
            row["base_color"] = self._color_input(material, node.inputs["Color"], "base_tex", row, (0.8, 0.8, 0.8))
            row["diffuse_roughness"] = float(np.clip(self._float_input(material, node.inputs["Roughness"]), 0, 1))
            self._normal(material, node, row)
            return row
        if t == "EMISSION":
            row = {"base_color": (0.0, 0.0, 0.0), "f0": 0.0}
            c = self._color_input(material, node.inputs["Color"], "emit_tex", row, (1, 1, 1))
            row["emission"] = tuple(np.array(c, np.float32) * self._float_input(material, node.inputs["Strength"]))
            return row
        if t in {"BSDF_GLOSSY", "BSDF_ANISOTROPIC"}:
            # Cycles: GGX with the constant Fresnel "colour" (f0 = 0: no dielectric layer, no diffuse)
            row = {"metallic": 1.0, "f0": 0.0, "metal_f90": 0.0}
            row["base_color"] = self._color_input(material, node.inputs["Color"], "base_tex", row, (0.8, 0.8, 0.8))
            row["roughness"] = self._float_input(material, node.inputs["Roughness"])
            row["multiscatter"] = self._multiscatter(material, node)
            if "Anisotropy" in node.inputs and (node.inputs["Anisotropy"].is_linked
                                                or abs(float(node.inputs["Anisotropy"].default_value)) > 1e-4):
                self._warn(material, "Glossy BSDF anisotropy is not supported; rendered isotropic")
            self._normal(material, node, row)
            return row
        if t in {"MIX_SHADER", "ADD_SHADER"}:
            return self._mix(material, node, depth)
        self._warn(material, f"shader '{node.name}' ({t}) is not supported; approximated by the viewport colour")
        return {"base_color": tuple(material.diffuse_color[:3]), "metallic": float(material.metallic),
                "roughness": float(material.roughness), "f0": 0.04}

    def _principled_transmission(self, material, inp, row: dict, ior: float) -> None:
        """Principled Transmission Weight t: a smooth glass closure with probability (1 - Metallic) t (untinted
        reflection; refraction tinted by the square root of Base Color, as Cycles: a pass through a solid object
        crosses two interfaces); the rest of the row becomes the remaining BSDF, whose metallic share is
        Metallic / (1 - (1 - Metallic) t) so that the two add up to Cycles' mix."""
        sock = inp["Transmission Weight"]
        if sock.is_linked:
            self._warn(material, "Principled 'Transmission Weight' from a texture is not supported; its default "
                       "value is used")
        t = float(np.clip(sock.default_value, 0, 1))
        if t <= 0:
            return
        m = float(np.clip(row.get("metallic", 0.0), 0, 1))
        share = (1 - m) * t
        row["transmission"] = share
        row["metallic"] = m / (1 - share) if share < 1 else 0.0
        row["glass_ior"] = max(ior, 1e-3)
        row["glass_reflect"] = (1.0, 1.0, 1.0)
        row["glass_refract"] = tuple(float(np.sqrt(np.clip(c, 0.0, 1.0))) for c in row["base_color"])
        if min(row.get("specular_tint", (1.0, 1.0, 1.0))) < 0.999:
            self._warn(material, "Specular Tint does not tint the reflection of Principled transmission here")
        if row.get("base_tex", -1) >= 0:
            self._warn(material, "a textured Base Color tints refraction by its constant colour, not the image")
        rough = float(np.clip(row.get("roughness", 0.5), 0, 1))
        row["glass_alpha"] = rough * rough
        row["glass_multiscatter"] = row.get("multiscatter", 1.0)

    # -- Mix and Add shaders: a weighted sum of BSDFs, one picked per hit (core/materials/mix.py) ---------
    def _normal(self, material, node, row: dict) -> None:
        """A BSDF's Normal input: a tangent-space Normal Map node on an Image Texture -> normal_tex and
        normal_strength; a Bump node whose Height is an Image Texture -> bump_tex, bump_strength, bump_distance
        (its own Normal input may hold such a Normal Map); anything else is reported and ignored."""
        socket = node.inputs.get("Normal")
        if socket is None or not socket.is_linked:
            return
        src = socket.links[0].from_node
        if src.type == "BUMP":  # its height (if supported), then what its own Normal input holds
            self._bump(material, src, row)
            inner = src.inputs.get("Normal")
            if inner is None or not inner.is_linked:
                return
            src = inner.links[0].from_node
        if src.type == "NORMAL_MAP" and src.space == "TANGENT":
            col = src.inputs["Color"]
            img = col.links[0].from_node if col.is_linked else None
            if img is not None and img.type == "TEX_IMAGE" and img.image is not None:
                if src.uv_map:
                    self._warn(material, f"'{src.name}' names UV map '{src.uv_map}'; the render UV map is used")
                row["normal_tex"] = self._texture(material, img.image, closest=img.interpolation == "Closest")
                row["normal_strength"] = self._float_input(material, src.inputs["Strength"])
                return
        self._warn(material, f"'{src.name}' ({src.type}) on the Normal input is not supported; the mesh normal is "
                   "used (supported: a tangent-space Normal Map of an Image Texture, a Bump of an Image Texture)")

    def _bump(self, material, node, row: dict) -> bool:
        """A Bump node with an Image Texture on Height (Color as luminance, or Alpha) -> row fields; False (with a
        warning) when its height is anything else."""
        height = node.inputs["Height"]
        link = height.links[0] if height.is_linked else None
        img = link.from_node if link is not None else None
        if img is None or img.type != "TEX_IMAGE" or img.image is None:
            what = "nothing" if img is None else f"'{img.name}' ({img.type})"
            self._warn(material, f"Bump '{node.name}': its Height is {what}; the bump is ignored (supported: an "
                       "Image Texture)")
            return False
        sign = -1.0 if getattr(node, "invert", False) else 1.0
        alpha = link.from_socket.name == "Alpha"
        row["bump_tex"] = self._texture(material, img.image, alpha=alpha, luminance=not alpha,
                                        closest=img.interpolation == "Closest")
        row["bump_strength"] = max(0.0, self._float_input(material, node.inputs["Strength"]))
        row["bump_distance"] = sign * self._float_input(material, node.inputs["Distance"])
        return True

    def _alpha(self, material, socket, row: dict) -> None:
        """Principled Alpha: constant, or an Image Texture's Alpha (or Color, as luminance) -> row alpha fields."""
        tex = self._factor_texture(material, socket)
        if tex >= 0:
            row.update(alpha=1.0, alpha_tex=tex, alpha_sign=1.0)
            return
        a = float(np.clip(self._float_input(material, socket), 0, 1))
        if a < 1:
            row["alpha"] = a

    def _mix(self, material, node, depth: int) -> dict:
        """A row whose BSDF is the weighted sum of its flattened components (each its own table row); its emission
        is the weighted sum of theirs. Components without a BSDF (Emission, empty sockets) drop out of the sum.
        A Transparent BSDF leaf becomes the row's alpha cut-out (opacity 1 - its weight) and the other components
        are renormalized (opaque points reflect with the full BSDF; exact for Mix trees, whose weights sum to 1)."""
        parts = self._flatten(material, node, depth, 1.0, -1, 0.0)
        comps, emission, emit_tex = [], np.zeros(3, np.float32), -1
        out = {"base_color": (0.0, 0.0, 0.0), "f0": 0.0}
        clear = [p for p in parts if p[0].get("transparent")]
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
        for row, weight, tex, sign in parts:
            if row.get("transparent"):
                continue
            if row.get("alpha", 1.0) < 1 or row.get("alpha_tex", -1) >= 0:
                self._warn(material, "alpha inside a Mix/Add shader is ignored (rendered opaque)")
            e = np.asarray(row.get("emission", (0, 0, 0)), np.float32)
            if e.any():
                if tex >= 0:
                    self._warn(material, "emission under a textured Mix factor is approximated by half its strength")
                emission += e * weight * (0.5 if tex >= 0 else 1.0)
                if row.get("emit_tex", -1) >= 0:
                    emit_tex = row["emit_tex"]
            if _has_bsdf(row):
                comp = dict(row, emission=(0.0, 0.0, 0.0), emit_tex=-1, alpha=1.0, alpha_tex=-1,
                            name=f"{material.name} ({len(comps) + 1})")
                comps.append((self.add_row(comp), float(weight), int(tex), float(sign)))
        out.update(emission=tuple(emission.tolist()), mix=comps)
        if emit_tex >= 0:
            out["emit_tex"] = emit_tex
        return out

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

    def _factor_texture(self, material, socket) -> int:
        """Texture index of an Image Texture driving a float socket (its Color as luminance, or its Alpha), or -1."""
        if not socket.is_linked:
            return -1
        link = socket.links[0]
        node = link.from_node
        if node.type != "TEX_IMAGE" or node.image is None:
            return -1
        if node.inputs["Vector"].is_linked:
            self._warn(material, f"'{node.name}' has a mapped vector input; the active UV map is used instead")
        closest = node.interpolation == "Closest"
        if link.from_socket.name == "Alpha":
            return self._texture(material, node.image, alpha=True, closest=closest)
        return self._texture(material, node.image, luminance=True, closest=closest)

    def _texture(self, material, image, alpha: bool = False, luminance: bool = False, closest: bool = False) -> int:
        """Index of an image in the texture list: its RGB (scene-linear), or its alpha / luminance replicated to
        three channels; sampled bilinearly, or by the nearest texel with ``closest`` (other interpolations:
        bilinear)."""
        key = (image.name_full, "alpha" if alpha else "luminance" if luminance else "rgb", closest)
        if key in self.texture_index:
            return self.texture_index[key]
        kept = TEXTURES.key(image, key)
        data = TEXTURES.get(kept)
        if data is None:
            data = self._read_texture(material, image, alpha, luminance)
            TEXTURES.put(kept, data)
        self.texture_index[key] = len(self.textures)
        self.textures.append(data.view(NearestImage) if closest else data)
        return self.texture_index[key]

    def _read_texture(self, material, image, alpha: bool, luminance: bool) -> np.ndarray:
        """The image's pixels as (h, w, 3) float32, scene-linear (magenta where it cannot be read)."""
        unreadable = unreadable_file(image)
        if unreadable:  # asking Blender for its size would open it (a FIFO blocks the export for ever)
            self._warn(material, f"image '{image.name}': {unreadable}; rendered magenta")
            w = h = 0
        else:
            w, h = image.size[:]
        data = None
        if w > 0 and h > 0:
            try:
                buf = np.empty(w * h * image.channels, np.float32)
                image.pixels.foreach_get(buf)
                data = buf.reshape(h, w, image.channels)
            except (RuntimeError, ValueError):
                data = None
        if unreadable:
            data = np.array(MAGENTA, np.float32).reshape(1, 1, 3)
        elif data is None or data.size == 0:
            self._warn(material, f"image '{image.name}' could not be loaded; rendered magenta")
            data = np.array(MAGENTA, np.float32).reshape(1, 1, 3)
        elif alpha:
            a = data[..., 3:4] if data.shape[2] == 4 else np.ones(data.shape[:2] + (1,), np.float32)
            data = np.ascontiguousarray(np.repeat(a, 3, axis=2), dtype=np.float32)
        else:
            ch = data.shape[2]
            rgb = data[..., :3] if ch >= 3 else np.repeat(data[..., :1], 3, axis=2)
            space = image.colorspace_settings.name
            if not image.is_float and space in {"sRGB", "sRGB EOTF"}:
                rgb = srgb_bytes_to_linear(rgb)
            elif space not in {"sRGB", "sRGB EOTF", "Linear Rec.709", "Linear", "Non-Color", "Raw", "Linear CIE-XYZ E"} \
                    and not image.is_float:
                self._warn(material, f"image '{image.name}' colour space '{space}' treated as sRGB")
                rgb = srgb_bytes_to_linear(rgb)
            if luminance:  # Blender's implicit colour -> float conversion
                rgb = np.repeat((rgb @ np.array([0.2126, 0.7152, 0.0722], np.float32))[..., None], 3, axis=2)
            data = np.ascontiguousarray(rgb, dtype=np.float32)
        return data


def _has_bsdf(row: dict) -> bool:
    """Whether a row reflects any light (a black non-metal without specular, e.g. an Emission shader, does not)."""
    if row.get("transparent"):
        return False
    return (row.get("base_tex", -1) >= 0 or any(c > 0 for c in row.get("base_color", (0.8, 0.8, 0.8)))
            or row.get("f0", 0.04) > 0 or row.get("metallic", 0.0) > 0 or bool(row.get("mix"))
            or row.get("transmission", 0.0) > 0)
