"""Blender materials -> MaterialTable rows (Principled parameters, emission radiance, Mix/Add components).

Supported exactly: Principled BSDF (Base Color, Metallic, Roughness, IOR, Specular IOR Level, Specular Tint,
Emission Color x Strength, Coat (export/coat.py); Multiscatter GGX or GGX), Diffuse BSDF, Emission, Glossy BSDF, Mix
Shader (constant factor or an Image Texture's Color/Alpha) and Add Shader of these (export/mix_shaders.py), and an
Image Texture (UV) feeding Base Color / Color / Emission Color (export/material_textures.py). Anything else is
approximated by its closest parameters and reported once per render, naming the material and the reason.
"""
from __future__ import annotations

import numpy as np

from ..core.scene import DEFAULT_MATERIAL, MaterialTable
from ..compat import uses_nodes
from . import object_properties
from .coat import coat_set
from .flat_nodes import FlatTree, cycles_output, flat_output
from .subsurface import principled_subsurface
from .sheen import sheen_row, sheen_set
from .limits import clamped_radiance
from .material_normals import NormalReader
from .material_textures import TextureReader
from .mix_shaders import MixShaderReader
from .node_graph import GraphCompiler



#: a Holdout shader: black and emitting nothing; camera rays that meet it leave the pixel transparent (alpha 0)
HOLDOUT_ROW = {"base_color": (0.0, 0.0, 0.0), "f0": 0.0, "metallic": 0.0, "holdout": True}


class MaterialRegistry(MixShaderReader, NormalReader, TextureReader):
    """Assigns table indices to Blender materials (index 0 is Blender's default grey) and
    collects textures; reports approximations through ``warnings``."""

    def __init__(self, warnings: list, camera=None, view_layer=None):
        self.warnings = warnings
        self.camera = camera  # what Texture Coordinate's Camera and Window outputs are relative to (None: unknown)
        self.view_layer = view_layer  # where View Layer attributes are looked up (object_properties.view_layer_places)
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
            if not getattr(material, "use_transparent_shadow", True):
                row["transparent_shadow"] = False
            aov = self._aov_program(material)
            if aov is not None:
                row["aov_program"] = aov
            self.index[key] = len(self.rows)
            self.rows.append(row)
        return self.index[key]

    def add_row(self, row: dict) -> int:
        """A synthetic material (for lamps); returns its index."""
        self.rows.append(row)
        return len(self.rows) - 1

    def uses_normal_maps(self, indices) -> bool:
        def mapped(row: dict) -> bool:
            if row.get("program") is not None and "tangent_uv" in row["program"].reads:
                return True
            return row.get("normal_tex", -1) >= 0 or any(mapped(self.rows[c]) for c, *_r in row.get("mix", ()))
        # (a Bump alone needs no tangents: its surface gradient comes from the triangle's positions and UVs)
        return any(mapped(self.rows[i]) for i in indices)

    def uses_textures(self, indices) -> bool:
        """Whether materials ``indices`` read UVs (an image, or a node program reading the UV map)."""
        def textured(row: dict) -> bool:
            if max(row.get(k, -1) for k in ("base_tex", "emit_tex", "alpha_tex", "normal_tex", "bump_tex")) >= 0:
                return True
            for key in ("program", "aov_program"):
                if row.get(key) is not None and {"uv", "tangent_uv"} & set(row[key].reads):
                    return True
            return any(tex >= 0 or textured(self.rows[comp]) for comp, _w, tex, _s in row.get("mix", ()))
        return any(textured(self.rows[i]) for i in indices)

    def reads_object_space(self, indices) -> bool:
        """Whether the node programs of materials ``indices`` read object or generated coordinates."""
        def reads(row: dict) -> bool:
            prog = row.get("program")
            if prog is not None and {"object", "generated"} & set(prog.reads):
                return True
            return any(reads(self.rows[comp]) for comp, *_r in row.get("mix", ()))
        return any(reads(self.rows[i]) for i in indices)

    def _program_reads(self, indices) -> set:
        """What the node programs (surface and AOV) of materials ``indices`` and their mix components read."""
        reads: set = set()

        def collect(row: dict) -> None:
            for prog in (row.get("program"), row.get("aov_program")):
                if prog is not None:
                    reads.update(prog.reads)
            for comp, *_rest in row.get("mix", ()):
                collect(self.rows[comp])
        for i in indices:
            collect(self.rows[i])
        return reads

    def attribute_names(self, indices) -> set:
        """The colour / geometry attributes the node programs of materials ``indices`` read."""
        return {r.split(":", 1)[1] for r in self._program_reads(indices) if r.startswith("attr")}

    def object_property_keys(self, indices) -> frozenset:
        """The Object / Instancer attribute keys ("KIND:name") the node programs of materials ``indices`` read
        (export/object_properties.py)."""
        keys = map(object_properties.key_of, self._program_reads(indices))
        return frozenset(k for k in keys if k is not None)

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
        out = cycles_output(tree, "OUTPUT_MATERIAL")
        outs = [flat_output(out)] if out is not None else []
        if not outs or not outs[0].inputs["Surface"].is_linked:
            volume_too = bool(outs) and "Volume" in outs[0].inputs and outs[0].inputs["Volume"].is_linked
            self._warn(material, "no surface shader connected to the Material Output; rendered black" +
                       (" (its volume is not rendered)" if volume_too else ""))
            return {"base_color": (0.0, 0.0, 0.0), "f0": 0.0}
        row = self._shader(material, outs[0].inputs["Surface"].links[0].from_node, depth=0)
        volume = outs[0].inputs.get("Volume") if hasattr(outs[0].inputs, "get") else None
        if volume is not None and volume.is_linked:
            sigma = self._absorption(material, volume.links[0].from_node)
            if sigma is not None and max(sigma) > 0:
                row["absorption"] = sigma
        return row

    def _absorption(self, material, node):
        """The Volume Absorption coefficient σa (3,) per scene unit of the shader on a Material Output's Volume
        socket, as Cycles: (1 − Color) x Density, summed over Add Shaders, weighted by Mix Shader factors; what is
        not absorption (scattering, emission, Principled Volume) is named and not rendered."""
        while node is not None and node.type == "REROUTE":
            node = node.inputs[0].links[0].from_node if node.inputs[0].is_linked else None
        if node is None or node.mute:
            return None
        if node.type == "VOLUME_ABSORPTION":
            color = np.maximum(np.array(self._color_input(material, node.inputs["Color"], None, {}, (0.8,) * 3),
                                        np.float64), 0.0)
            density = max(self._float_input(material, node.inputs["Density"]), 0.0)
            return tuple(float(v) for v in (1.0 - color) * density)
        if node.type in {"ADD_SHADER", "MIX_SHADER"}:
            shaders = [i for i in node.inputs if i.type == "SHADER"]
            weights = [1.0, 1.0]
            if node.type == "MIX_SHADER":
                fac = min(max(self._float_input(material, node.inputs[0]), 0.0), 1.0)
                weights = [1.0 - fac, fac]
            total = np.zeros(3)
            for sock, w in zip(shaders, weights):
                if sock.is_linked and w > 0:
                    part = self._absorption(material, sock.links[0].from_node)
                    if part is not None:
                        total += w * np.asarray(part)
            return tuple(float(v) for v in total)
        self._warn(material, f"volume shader '{node.name}' ({node.type}) is not rendered: only Volume Absorption "
                   "inside closed meshes is")
        return None

    def _aov_program(self, material):
        """The material's AOV Output nodes as one program: fields "aov:<name>" (Color) and "aov_value:<name>"
        (Value), constants included; None without AOV outputs."""
        if not uses_nodes(material):
            return None
        flat = FlatTree()
        nodes = [flat.node(n) for n in material.node_tree.nodes if n.type == "OUTPUT_AOV" and not n.mute and n.aov_name]
        if not nodes:
            return None
        g = self._compiler(material)
        outputs = {}
        for node in nodes:
            outputs[f"aov:{node.aov_name}"] = g.value(node.inputs["Color"], "color")
            outputs[f"aov_value:{node.aov_name}"] = g.value(node.inputs["Value"], "float")
        return g.program(outputs, constants=True)

    def _compiler(self, material) -> GraphCompiler:
        """A node-graph compiler for one row of ``material`` (images go to this registry's texture list)."""
        g = GraphCompiler(lambda image, alpha: self._texture(material, image, alpha=alpha),
                          lambda reason: self._warn(material, reason))
        g.camera = self.camera
        g.view_layer = self.view_layer
        g.material_index = float(getattr(material, "pass_index", 0))
        return g

    def _param(self, material, g: GraphCompiler, socket, kind: str, field: str, varying: dict, row: dict | None = None,
               key_tex: str | None = None):
        """A socket's constant (float or RGB tuple); where its graph varies over the surface, its register goes to
        ``varying[field]`` (the row's node program computes it) and a neutral constant is returned. ``key_tex``:
        an Image Texture read plainly (UV, Linear or Closest, Repeat) goes to that row field instead."""
        if key_tex is not None and row is not None:
            tex = self._plain_image(material, socket)
            if tex is not None:
                row[key_tex] = tex
                return (1.0, 1.0, 1.0)
        reg = g.value(socket, kind)
        if reg.const is not None:
            return reg.constant_value()
        varying[field] = reg
        return (1.0, 1.0, 1.0) if kind == "color" else float(getattr(socket, "default_value", 0.0))

    def _color_input(self, material, socket, key_tex: str, row: dict, fallback):
        """Constant colour of a socket (its graph folded), or 1 with a texture index when an Image Texture drives
        it plainly (``key_tex``); a colour that varies otherwise is approximated by the socket's value (reported)."""
        if not socket.is_linked:
            return tuple(socket.default_value[:3])
        if key_tex is not None:
            tex = self._plain_image(material, socket)
            if tex is not None:
                row[key_tex] = tex
                return (1.0, 1.0, 1.0)
        reg = self._compiler(material).value(socket, "color")
        if reg.const is not None:
            return reg.constant_value()
        self._warn(material, f"'{socket.name}' of '{socket.node.name}' varies over the surface; approximated by the "
                   "socket's value")
        return tuple(socket.default_value[:3]) if hasattr(socket, "default_value") else fallback

    def _multiscatter(self, material, node) -> float:
        """1 for Multiscatter GGX (Blender's default), 0 for GGX; other distributions are approximated by one."""
        dist = getattr(node, "distribution", "MULTI_GGX")
        if dist in {"MULTI_GGX", "GGX"}:
            return 1.0 if dist == "MULTI_GGX" else 0.0
        self._warn(material, f"'{node.name}' distribution {dist} is approximated by Multiscatter GGX")
        return 1.0

    def _float_input(self, material, socket) -> float:
        """Constant value of a float socket (its graph folded); one that varies over the surface is approximated by
        the socket's value (reported)."""
        if socket.is_linked:
            reg = self._compiler(material).value(socket, "float")
            if reg.const is not None:
                return reg.constant_value()
            self._warn(material, f"'{socket.name}' of '{socket.node.name}' varies over the surface; approximated by "
                       "the socket's value")
        return float(socket.default_value)

    def _shader(self, material, node, depth: int, base_only: bool = False) -> dict:
        """The row of shader ``node``; ``base_only``: a Principled BSDF without its coat (export/coat.py) and sheen
        (export/sheen.py)."""
        t = node.type
        if t == "BSDF_PRINCIPLED" and not base_only and (coat_set(node) or sheen_set(node)):
            return self._mix_program(material, node, depth)
        if t == "BSDF_PRINCIPLED":
            return self._principled(material, node)
        if t == "BSDF_GLASS":
            c = self._color_input(material, node.inputs["Color"], None, {}, (1, 1, 1))
            ior = self._float_input(material, node.inputs["IOR"])
            rough = float(np.clip(self._float_input(material, node.inputs["Roughness"]), 0, 1))
            beckmann = getattr(node, "distribution", "MULTI_GGX") == "BECKMANN"  # single-scattering, as Cycles
            return {"base_color": (0.0, 0.0, 0.0), "f0": 0.0, "transmission": 1.0, "glass_ior": max(ior, 1e-3),
                    "glass_reflect": tuple(c), "glass_refract": tuple(c), "glass_alpha": rough * rough,
                    "glass_multiscatter": 0.0 if beckmann else self._multiscatter(material, node),
                    "glass_beckmann": float(beckmann)}
        if t == "BSDF_REFRACTION":  # Cycles: microfacet refraction alone, no Fresnel term, no energy compensation
            c = self._color_input(material, node.inputs["Color"], None, {}, (1, 1, 1))
            ior = self._float_input(material, node.inputs["IOR"])
            rough = float(np.clip(self._float_input(material, node.inputs["Roughness"]), 0, 1))
            return {"base_color": (0.0, 0.0, 0.0), "f0": 0.0, "transmission": 1.0, "glass_ior": max(ior, 1e-3),
                    "glass_reflect": (0.0, 0.0, 0.0), "glass_refract": tuple(c), "glass_alpha": rough * rough,
                    "glass_multiscatter": 0.0, "glass_fresnel": 0.0,
                    "glass_beckmann": float(getattr(node, "distribution", "GGX") == "BECKMANN")}
        if t == "HOLDOUT":
            return dict(HOLDOUT_ROW)
        if t == "BSDF_TRANSPARENT":  # a cut-out everywhere; rays through it keep its Color
            g, varying = self._compiler(material), {}
            tint = self._param(material, g, node.inputs["Color"], "color", "transparent_tint", varying)
            row = {"base_color": (0.0, 0.0, 0.0), "f0": 0.0, "transparent": True, "alpha": 0.0,
                   "transparent_tint": tuple(float(max(c, 0.0)) for c in tint)}
            return self._with_program(row, g, varying)
        if t == "BSDF_DIFFUSE":
            row = {"f0": 0.0, "metallic": 0.0}
            g, varying = self._compiler(material), {}
            row["base_color"] = self._param(material, g, node.inputs["Color"], "color", "base_color", varying, row,
                                            "base_tex")
            dr = self._param(material, g, node.inputs["Roughness"], "float", "diffuse_roughness", varying)
            row["diffuse_roughness"] = float(np.clip(dr, 0, 1))
            self._normal(material, node, row, g, varying)
            return self._with_program(row, g, varying)
        if t == "EMISSION":
            row = {"base_color": (0.0, 0.0, 0.0), "f0": 0.0}
            g, varying = self._compiler(material), {}
            self._emission(material, g, node.inputs["Color"], node.inputs["Strength"], row, varying)
            return self._with_program(row, g, varying)
        if t in {"BSDF_GLOSSY", "BSDF_ANISOTROPIC"}:
            # Cycles: GGX with the constant Fresnel "colour" (f0 = 0: no dielectric layer, no diffuse)
            row = {"metallic": 1.0, "f0": 0.0, "metal_f90": 0.0}
            g, varying = self._compiler(material), {}
            row["base_color"] = self._param(material, g, node.inputs["Color"], "color", "base_color", varying, row,
                                            "base_tex")
            row["roughness"] = self._param(material, g, node.inputs["Roughness"], "float", "roughness", varying)
            row["multiscatter"] = self._multiscatter(material, node)
            self._anisotropy(material, node, row, g, varying, "Anisotropy", "Rotation")
            self._normal(material, node, row, g, varying)
            return self._with_program(row, g, varying)
        if t == "BSDF_TRANSLUCENT":
            return self._translucent(material, node)
        if t == "BSDF_SHEEN":
            return sheen_row(self, material, node)
        if t in {"MIX_SHADER", "ADD_SHADER"}:
            return self._mix(material, node, depth)
        if t.startswith("VOLUME_") or t == "PRINCIPLED_VOLUME":  # as Cycles: volume closures add nothing to a surface
            return {"base_color": (0.0, 0.0, 0.0), "f0": 0.0}
        self._warn(material, f"shader '{node.name}' ({t}) is not supported; approximated by the viewport colour")
        return {"base_color": tuple(material.diffuse_color[:3]), "metallic": float(material.metallic),
                "roughness": float(material.roughness), "f0": 0.04}

    def _principled(self, material, node) -> dict:
        """The row of a Principled BSDF without a Coat (a coated one is a mix: export/coat.py)."""
        row: dict = {}
        inp = node.inputs
        g, varying = self._compiler(material), {}
        row["base_color"] = self._param(material, g, inp["Base Color"], "color", "base_color", varying, row,
                                        "base_tex")
        row["metallic"] = self._param(material, g, inp["Metallic"], "float", "metallic", varying)
        row["roughness"] = self._param(material, g, inp["Roughness"], "float", "roughness", varying)
        ior_reg = g.value(inp["IOR"], "float") if "IOR" in inp else g.constant(1.5, "float")
        level = g.value(inp["Specular IOR Level"], "float") if "Specular IOR Level" in inp else \
            g.constant(0.5, "float")
        f0 = g.emit("principled_f0", {}, [ior_reg, level], ("float",))[0]
        if f0.const is not None:
            row["f0"] = f0.constant_value()
        else:
            varying["f0"] = f0
        ior = ior_reg.constant_value() if ior_reg.const is not None else float(inp["IOR"].default_value)
        if "Specular Tint" in inp:
            row["specular_tint"] = self._param(material, g, inp["Specular Tint"], "color", "specular_tint",
                                               varying)
        row["multiscatter"] = self._multiscatter(material, node)
        self._anisotropy(material, node, row, g, varying, "Anisotropic", "Anisotropic Rotation")
        self._emission(material, g, inp["Emission Color"], inp["Emission Strength"], row, varying)
        principled_subsurface(self, material, node, row, g, varying, ior)
        if "Transmission Weight" in inp:
            self._principled_transmission(material, inp, row, ior)
            if row.get("transmission", 0.0) > 0 and ("aniso_aspect" in row or "aniso_aspect" in varying):
                self._warn(material, "Principled 'Anisotropic' applies to reflection here; its transmission is "
                           "rendered isotropic")
        if "Diffuse Roughness" in inp:
            dr = self._param(material, g, inp["Diffuse Roughness"], "float", "diffuse_roughness", varying)
            row["diffuse_roughness"] = float(np.clip(dr, 0, 1))
        if "Alpha" in inp:
            self._alpha(material, inp["Alpha"], row, g, varying)
        self._normal(material, node, row, g, varying)
        self._unmodelled_principled(material, node)
        return self._with_program(row, g, varying)

    def _unmodelled_principled(self, material, node) -> None:
        """Name the Principled BSDF's inputs that are set but not rendered: Thin Film (iridescence), Thin Wall,
        Dispersion (where the Blender version has them)."""
        inp = node.inputs

        def set_(name, off=0.0):
            sock = inp.get(name)
            return sock is not None and (sock.is_linked or float(sock.default_value) != off)
        if set_("Thin Film Thickness"):
            self._warn(material, f"'{node.name}' (Principled) Thin Film is not supported and was ignored (no "
                       "iridescence)")
        if set_("Thin Wall"):
            self._warn(material, f"'{node.name}' (Principled) Thin Wall is not supported: rendered as a solid")
        if set_("Dispersion"):
            self._warn(material, f"'{node.name}' (Principled) Dispersion is not supported: one IOR for every "
                       "colour")

    def _anisotropy(self, material, node, row: dict, g: GraphCompiler, varying: dict, amount: str,
                    rotation: str) -> None:
        """A GGX lobe's anisotropy (socket ``amount``) as Cycles maps it for this node (the Principled's or the
        Glossy's aspect: core/materials/anisotropy.py), its rotation (socket ``rotation``, turns) and Tangent: the
        row's "aniso_aspect" and "aniso_rotation" (or the program's fields where they vary); a linked Tangent
        becomes the program's "tangent" (unlinked: the radial tangent about the object's Z axis)."""
        inp = node.inputs
        if amount not in inp:
            return
        k = g.emit("aniso_aspect", {"glossy": node.type != "BSDF_PRINCIPLED"}, [g.value(inp[amount], "float")],
                   ("float",))[0]
        if k.const is not None:
            if abs(float(k.constant_value()) - 1.0) <= 1e-6:
                return
            row["aniso_aspect"] = float(k.constant_value())
        else:
            varying["aniso_aspect"] = k
        if rotation in inp:
            row["aniso_rotation"] = float(self._param(material, g, inp[rotation], "float", "aniso_rotation", varying))
        tangent = inp.get("Tangent")
        if tangent is not None and tangent.is_linked:
            varying["tangent"] = g.value(tangent, "vector")

    def _translucent(self, material, node) -> dict:
        """A Translucent BSDF: Lambertian transmission as Cycles, Color/π on the side away from the viewer, none
        toward it (its Color and Normal from any graph)."""
        row = {"f0": 0.0, "metallic": 0.0, "translucent": True}
        g, varying = self._compiler(material), {}
        row["base_color"] = self._param(material, g, node.inputs["Color"], "color", "base_color", varying, row,
                                        "base_tex")
        self._normal(material, node, row, g, varying)
        return self._with_program(row, g, varying)

    def _emission(self, material, g: GraphCompiler, color_socket, strength_socket, row: dict, varying: dict) -> None:
        """Emission colour x strength -> the row's constant "emission" (with "emit_tex" for a plain image), or
        the node program's "emission" where either varies over the surface."""
        strength = g.value(strength_socket, "float")
        if strength.const is not None:
            s_val = strength.constant_value()
            c = self._param(material, g, color_socket, "color", "emission_color", varying, row, "emit_tex")
            if "emission_color" not in varying:
                row["emission"] = tuple(float(x) * s_val for x in c)
                if row.get("emit_tex", -1) >= 0 and s_val == 0:
                    row["emit_tex"] = -1
                return
            color = varying.pop("emission_color")
        else:
            color = g.value(color_socket, "color")
        varying["emission"] = g.emit("scale", {}, [color, strength], ("color",))[0]
        row["emission"] = (0.0, 0.0, 0.0)

    @staticmethod
    def _with_program(row: dict, g: GraphCompiler, varying: dict, keep=()) -> dict:
        """The row with its node program (when some field varies; the fields in ``keep`` count as varying, and so
        does a linked Tangent, which the row has no field for)."""
        prog = g.program(varying, keep=tuple(keep) + (("tangent",) if "tangent" in varying else ()))
        if prog is not None:
            row["program"] = prog
        return row

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
    def _alpha(self, material, socket, row: dict, g: GraphCompiler, varying: dict) -> None:
        """Principled Alpha: constant, a plain Image Texture's Alpha (or Color, as luminance) -> row alpha fields;
        any other graph -> the node program's "alpha" (clamped to [0, 1] as Cycles clamps it)."""
        if self._plain_image_node(socket) is not None:
            tex = self._factor_texture(material, socket)
            if tex >= 0:
                row.update(alpha=1.0, alpha_tex=tex, alpha_sign=1.0)
                return
        reg = g.emit("saturate", {}, [g.value(socket, "float")], ("float",))[0]
        if reg.const is None:
            varying["alpha"] = reg
            row["alpha_program"] = True
            return
        a = float(np.clip(reg.constant_value(), 0, 1))
        if a < 1:
            row["alpha"] = a
