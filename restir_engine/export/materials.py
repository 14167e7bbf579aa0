"""Blender materials -> MaterialTable rows (Lambert + GGX parameters, emission radiance).

Supported exactly: Principled BSDF (Base Color, Metallic, Roughness, IOR, Specular IOR Level,
Emission Color x Strength), Diffuse BSDF, Emission, Glossy BSDF, and an Image Texture (UV) feeding
Base Color / Color / Emission Color. Anything else is approximated by its closest parameters and
reported once per render, naming the material and the reason.
"""
from __future__ import annotations

import bpy
import numpy as np

from ..core.scene import DEFAULT_MATERIAL, MaterialTable

MAGENTA = (1.0, 0.0, 1.0)


def srgb_to_linear(c: np.ndarray) -> np.ndarray:
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4).astype(np.float32)


def uses_nodes(idblock) -> bool:
    """Whether a material/world is defined by its node tree (always, from Blender 5.0 on)."""
    if idblock.node_tree is None:
        return False
    return True if bpy.app.version >= (5, 0, 0) else bool(idblock.use_nodes)


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

    def uses_textures(self, indices) -> bool:
        return any(self.rows[i].get("base_tex", -1) >= 0 or self.rows[i].get("emit_tex", -1) >= 0 for i in indices)

    def table(self) -> MaterialTable:
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
            row[key_tex] = self._texture(material, node.image)
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
            for name in ("Transmission Weight", "Coat Weight", "Sheen Weight", "Subsurface Weight"):
                if name in inp and (inp[name].is_linked or float(inp[name].default_value) > 0):
                    self._warn(material, f"Principled '{name}' is not supported and was ignored")
            if "Alpha" in inp and (inp["Alpha"].is_linked or float(inp["Alpha"].default_value) < 1):
                self._warn(material, "alpha/transparency is not supported; rendered opaque")
            return row
        if t == "BSDF_DIFFUSE":
            row = {"f0": 0.0, "metallic": 0.0}
            row["base_color"] = self._color_input(material, node.inputs["Color"], "base_tex", row, (0.8, 0.8, 0.8))
            if self._float_input(material, node.inputs["Roughness"]) > 0:
                self._warn(material, "Diffuse BSDF roughness (Oren-Nayar) is approximated as Lambertian")
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
            return row
        if t in {"MIX_SHADER", "ADD_SHADER"} and depth < 8:
            shaders = [s for s in node.inputs if s.type == "SHADER"]
            parts = [self._shader(material, s.links[0].from_node, depth + 1) if s.is_linked
                     else {"base_color": (0, 0, 0), "f0": 0.0} for s in shaders]
            if t == "MIX_SHADER":
                fac = float(node.inputs["Fac"].default_value) if not node.inputs["Fac"].is_linked else 0.5
                weights = (1 - fac, fac)
            else:
                weights = (1.0, 1.0)
            self._warn(material, f"'{node.name}' ({t}) approximated by blending the parameters of its inputs")
            return _blend(parts, weights)
        self._warn(material, f"shader '{node.name}' ({t}) is not supported; approximated by the viewport colour")
        return {"base_color": tuple(material.diffuse_color[:3]), "metallic": float(material.metallic),
                "roughness": float(material.roughness), "f0": 0.04}

    def _texture(self, material, image) -> int:
        key = image.name_full
        if key in self.texture_index:
            return self.texture_index[key]
        w, h = image.size[:]
        data = None
        if w > 0 and h > 0:
            try:
                buf = np.empty(w * h * image.channels, np.float32)
                image.pixels.foreach_get(buf)
                data = buf.reshape(h, w, image.channels)
            except (RuntimeError, ValueError):
                data = None
        if data is None or data.size == 0:
            self._warn(material, f"image '{image.name}' could not be loaded; rendered magenta")
            data = np.array(MAGENTA, np.float32).reshape(1, 1, 3)
        else:
            ch = data.shape[2]
            rgb = data[..., :3] if ch >= 3 else np.repeat(data[..., :1], 3, axis=2)
            space = image.colorspace_settings.name
            if not image.is_float and space in {"sRGB", "sRGB EOTF"}:
                rgb = srgb_to_linear(rgb)
            elif space not in {"sRGB", "sRGB EOTF", "Linear Rec.709", "Linear", "Non-Color", "Raw", "Linear CIE-XYZ E"} \
                    and not image.is_float:
                self._warn(material, f"image '{image.name}' colour space '{space}' treated as sRGB")
                rgb = srgb_to_linear(rgb)
            data = np.ascontiguousarray(rgb, dtype=np.float32)
        self.texture_index[key] = len(self.textures)
        self.textures.append(data)
        return self.texture_index[key]


def _blend(parts: list[dict], weights) -> dict:
    keys = {"base_color": (0.8, 0.8, 0.8), "metallic": 0.0, "roughness": 0.5, "f0": 0.04, "emission": (0, 0, 0),
            "specular_tint": (1, 1, 1), "metal_f90": 1.0, "multiscatter": 1.0}
    out = {}
    wsum = sum(weights) or 1.0
    for k, default in keys.items():
        vals = [np.array(p.get(k, default), np.float32) * w for p, w in zip(parts, weights)]
        total = sum(vals)
        out[k] = tuple(total.tolist()) if np.ndim(total) else float(total)
        if k != "emission":  # reflectance parameters average; emission adds up
            out[k] = tuple((np.array(total) / wsum).tolist()) if np.ndim(total) else float(total / wsum)
    for tex in ("base_tex", "emit_tex"):
        for p in parts:
            if p.get(tex, -1) >= 0:
                out[tex] = p[tex]
    return out
