"""Flat scene description handed from the exporter to the renderer.

Conventions: world space is Blender's (right-handed, +Z up, metres as the scene unit);
colours are scene-linear RGB; radiance is W·sr⁻¹·m⁻² (Cycles' emission colour x strength);
all arrays are float32 unless stated.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class TriangleSet:
    """Triangles as flat arrays.

    verts    (n, 3, 3)  world-space corner positions
    normals  (n, 3, 3)  per-corner unit shading normals (Blender's smooth/flat/auto-smooth result)
    uvs      (n, 3, 2)  per-corner UVs, or None when no material needs a texture
    material (n,) int32 index into :class:`MaterialTable`
    """

    verts: np.ndarray
    normals: np.ndarray
    material: np.ndarray
    uvs: np.ndarray | None = None
    instance: np.ndarray | None = None  # (n,) int32 index into Scene.motion's instance matrices
    tangents: np.ndarray | None = None  # (n, 3, 4) per-corner UV tangent (xyz, world space) and bitangent sign,
    #                                     or None when no material has a normal map
    objects: "ObjectTable | None" = None  # per instance: what node programs read of the object (or None)
    attributes: dict | None = None  # colour attributes node programs read: name -> (n, 3 corners, 4) RGBA, linear
    local_verts: np.ndarray | None = None  # (n, 3, 3) object-space corners, where node programs read object or
    #                                        generated coordinates (or None)

    @staticmethod
    def empty() -> TriangleSet:
        return TriangleSet(np.zeros((0, 3, 3), np.float32), np.zeros((0, 3, 3), np.float32),
                           np.zeros(0, np.int32))

    def __len__(self) -> int:
        return len(self.verts)


@dataclass
class ObjectTable:
    """What shader nodes read of each instance (index: TriangleSet.instance).

    world_to_object (k, 3, 4)  the inverse of the instance's world matrix (affine rows), float64
    texspace_lo, texspace_size (k, 3)  its texture space: Generated = (object position - lo) / size
    location (k, 3) world-space origin; color (k, 4) the object's Color (RGBA); random (k,) Object Info Random
    names, assets (k,) the instance's object name and its top-most parent's (Cryptomatte)
    holdout (k,) bool: Object > Visibility > Holdout (transparent and black to camera rays, lit and lighting as usual)
    """

    world_to_object: np.ndarray
    texspace_lo: np.ndarray
    texspace_size: np.ndarray
    location: np.ndarray
    color: np.ndarray
    random: np.ndarray
    names: tuple = ()
    assets: tuple = ()
    holdout: np.ndarray = None
    pass_index: np.ndarray = None  # (k,) float32 the object's Pass Index (Object Info > Object Index)
    shadow_catcher: np.ndarray = None  # (k,) bool: Object > Visibility > Mask > Shadow Catcher (pipeline/shadow_catcher.py)
    casts_shadow: np.ndarray = None  # (k,) bool: Object > Visibility > Ray Visibility > Shadow (off: shadow rays pass)
    camera_visible: np.ndarray = None  # (k,) bool: ... > Ray Visibility > Camera (off: camera rays pass)
    properties: dict = None  # {"KIND:name": (k, 4) float32}: the Attribute node's Object / Instancer values (RGBA)


@dataclass
class MaterialTable:
    """Per-material parameters of the Lambert + GGX model (see :mod:`.bsdf`).

    base_color  (m, 3)  linear albedo
    metallic    (m,)    0..1
    roughness   (m,)    0..1 (GGX alpha = roughness²)
    f0          (m,)    dielectric normal-incidence reflectance (0.04 for IOR 1.5; Specular IOR Level applied;
                        0 = no dielectric specular lobe)
    specular_tint (m, 3) Principled Specular Tint: tints the dielectric f0 and is the metals' F82 tint (white)
    metal_f90   (m,)    1: the metal lobe's Fresnel rises to white at grazing (Principled), 0: constant colour
                        (Glossy BSDF)
    multiscatter (m,)   1: multiscatter GGX energy compensation (Blender's default), 0: single-scatter GGX
    emission    (m, 3)  emitted radiance, W·sr⁻¹·m⁻² (colour x strength)
    base_tex    (m,) int32  index into ``textures`` multiplying base_color, -1 = none
    emit_tex    (m,) int32  index into ``textures`` multiplying emission, -1 = none
    two_sided_emission (m,) bool  mesh emission leaves both faces (Cycles); lamps emit from the front only
    mix_first, mix_count (m,) int32  a Mix/Add shader: its components are entries mix_first .. + mix_count of
                        the mix_* arrays (-1, 0: not a mix; its own BSDF parameters are then unused)
    mix_normalize (m,) bool  the components' weights are renormalized to sum 1 (a Mix with a Transparent BSDF:
                        the cut-out takes the transparent share)
    mix_comp    (k,) int32  component material (never itself a mix)
    mix_weight  (k,) constant weight of the component (product of the Mix factors on its path; Add: 1)
    mix_tex     (k,) int32  texture index whose value t (first channel) further weighs it, -1 = none
    mix_sign    (k,) +1: weight x t, -1: weight x (1 - t)
    diffuse_roughness (m,) Oren–Nayar σ of the diffuse lobe (Principled Diffuse Roughness, Diffuse BSDF Roughness;
                        0 = Lambert)
    normal_tex  (m,) int32  tangent-space normal map texture (a Normal Map node on the BSDF's Normal), -1 = none
    normal_strength (m,) its Strength
    bump_tex    (m,) int32  height map of a Bump node on the BSDF's Normal (its luminance, on top of a Normal Map
                        when the Bump's own Normal input has one), -1 = none
    bump_strength, bump_distance (m,) the Bump's Strength and Distance (negative: Invert), in scene units
    transmission (m,)   probability that a hit uses the smooth glass closure (Glass BSDF: 1; Principled: (1 - Metallic)
                        x Transmission Weight; the row's other parameters are then the rest of the BSDF)
    glass_ior   (m,)    its index of refraction (inside over outside, the geometric normal pointing outside)
    glass_reflect, glass_refract (m, 3) the tints of its reflection and its refraction
    glass_alpha (m,)    its GGX α (roughness²; below glass.ROUGH_ALPHA_MIN smooth, a delta closure)
    glass_multiscatter (m,) 1: Multiscatter GGX (energy compensated, Blender's default), 0: GGX
    glass_beckmann (m,) 1: Beckmann's microfacet distribution (the Refraction BSDF's default), 0: GGX
    glass_fresnel (m,)  1: the Fresnel term chooses reflection or refraction (Glass BSDF, Principled); 0: it always
                        refracts, untinted by Fresnel (Refraction BSDF; total internal reflection absorbs)
    absorption  (m, 3)  the material's Volume Absorption coefficient σa, per scene unit of length ((1 − Color) x Density,
                        as Cycles): a ray that travels inside the closed mesh and leaves it through its surface keeps
                        exp(−σa · distance) of its light (0: no volume)
    aniso_aspect (m,)   the specular lobes' anisotropic aspect k (αx = α/k, αy = α k; 1: isotropic) from Principled
                        Anisotropic or Glossy Anisotropy (core/materials/anisotropy.py); the node program's
                        "aniso_aspect" replaces it per hit
    sheen_roughness (m,) > 0: a sheen lobe (Sheen BSDF, a Principled BSDF's Sheen component) of this roughness, whose
                        base_color is its Color (core/materials/sheen.py); 0: none
    aniso_rotation (m,) the tangent's rotation about the normal, in turns (program field "aniso_rotation"); the
                        tangent is the radial one about the object's Z axis unless the program gives "tangent"
    subsurface (m,)     Principled Subsurface Weight (0..1; program field "subsurface"): that share of the diffuse
                        lobe scatters beneath the surface (core/integrators/subsurface.py)
    sss_radius (m, 3)   its mean free path per channel in scene units (Subsurface Radius x Scale, before the
                        method's own scaling)
    sss_method (m,) int32  the random walk's coefficients and entry (subsurface.WALK_*: 0 none)
    sss_ior (m,)        the entry's index of refraction (the Principled IOR; Random Walk (Skin): Subsurface IOR)
    sss_anisotropy (m,) the Henyey–Greenstein g of the medium's phase function (Subsurface Anisotropy, clamped)
    translucent (m,) bool  a Translucent BSDF: Lambertian transmission, base_color/π toward the side away from the
                        viewer and nothing back toward it (Surface turns such hits' frame away from the viewer)
    alpha       (m,)    opacity of an alpha cut-out (1 = opaque; Principled Alpha, Mix with a Transparent BSDF)
    alpha_tex   (m,) int32  texture whose value t further scales alpha, -1 = none
    alpha_sign  (m,)    +1: alpha x t, -1: alpha x (1 - t)
    transparent_shadow (m,) bool  shadow rays pass the cut-out's transparent points (Material > Settings >
                        Transparent Shadows); off: the surface shadows as if opaque
    transparent_tint (m, 3) the colour a ray keeps where it passes a cut-out's transparent point (a Transparent BSDF's
                        Color; white for Principled Alpha); the node program's "transparent_tint" replaces it per hit
    alpha_program (m,) bool  the node program's "alpha" field (0..1, per hit) further scales alpha (an Alpha or a
                        Transparent BSDF's Mix factor from any node graph)
    program     (m,) int32  index into ``programs`` of the material's node program (-1 = none): fields that vary
                        per hit ("base_color", "metallic", "roughness", "f0", "specular_tint", "diffuse_roughness",
                        "emission", "mix:<k>" the weight of Mix component k, "aniso_aspect", "aniso_rotation",
                        "tangent", "sheen_roughness", "subsurface") evaluated at the hits
                        (core/materials/nodes), replacing the row's constants
    programs    list of nodes.program.Program
    textures    list of (h, w, 3) float32 linear images, row 0 at the bottom (Blender's order)
    names       material names, for messages
    """

    base_color: np.ndarray
    metallic: np.ndarray
    roughness: np.ndarray
    f0: np.ndarray
    emission: np.ndarray
    specular_tint: np.ndarray
    metal_f90: np.ndarray
    multiscatter: np.ndarray
    base_tex: np.ndarray
    emit_tex: np.ndarray
    two_sided_emission: np.ndarray
    diffuse_roughness: np.ndarray = None
    normal_tex: np.ndarray = None
    normal_strength: np.ndarray = None
    bump_tex: np.ndarray = None
    bump_strength: np.ndarray = None
    bump_distance: np.ndarray = None
    transmission: np.ndarray = None
    glass_ior: np.ndarray = None
    glass_reflect: np.ndarray = None
    glass_refract: np.ndarray = None
    glass_alpha: np.ndarray = None
    glass_multiscatter: np.ndarray = None
    glass_fresnel: np.ndarray = None
    glass_beckmann: np.ndarray = None
    alpha: np.ndarray = None
    alpha_tex: np.ndarray = None
    alpha_sign: np.ndarray = None
    alpha_program: np.ndarray = None
    transparent_shadow: np.ndarray = None
    transparent_tint: np.ndarray = None
    mix_normalize: np.ndarray = None
    mix_first: np.ndarray = None
    mix_count: np.ndarray = None
    mix_comp: np.ndarray = None
    mix_weight: np.ndarray = None
    mix_tex: np.ndarray = None
    mix_sign: np.ndarray = None
    absorption: np.ndarray = None
    holdout: np.ndarray = None  # (m,) bool: a Holdout shader (camera rays meeting it give alpha 0, black)
    translucent: np.ndarray = None  # (m,) bool: a Translucent BSDF (Lambertian transmission of base_color)
    aniso_aspect: np.ndarray = None
    sheen_roughness: np.ndarray = None
    aniso_rotation: np.ndarray = None
    subsurface: np.ndarray = None
    sss_radius: np.ndarray = None
    sss_method: np.ndarray = None
    sss_ior: np.ndarray = None
    sss_anisotropy: np.ndarray = None
    program: np.ndarray = None
    programs: list = field(default_factory=list)
    aov_program: np.ndarray = None  # (m,) index into aov_programs (the material's AOV Output nodes) or -1
    aov_programs: list = field(default_factory=list)
    textures: list = field(default_factory=list)
    names: list = field(default_factory=list)

    @staticmethod
    def build(rows: list[dict], textures: list | None = None) -> MaterialTable:
        """From a list of dicts with the field names above (missing fields take defaults)."""
        def col(key, default, dtype=np.float32):
            return np.array([r.get(key, default) for r in rows], dtype=dtype).reshape(len(rows), *np.shape(default))
        return MaterialTable(
            base_color=col("base_color", (0.8, 0.8, 0.8)), metallic=col("metallic", 0.0),
            roughness=col("roughness", 0.5), f0=col("f0", 0.04), emission=col("emission", (0.0, 0.0, 0.0)),
            specular_tint=col("specular_tint", (1.0, 1.0, 1.0)), metal_f90=col("metal_f90", 1.0),
            multiscatter=col("multiscatter", 1.0),
            base_tex=col("base_tex", -1, np.int32), emit_tex=col("emit_tex", -1, np.int32),
            two_sided_emission=col("two_sided_emission", True, bool),
            alpha=col("alpha", 1.0), alpha_tex=col("alpha_tex", -1, np.int32), alpha_sign=col("alpha_sign", 1.0),
            alpha_program=col("alpha_program", False, bool),
            transparent_shadow=col("transparent_shadow", True, bool),
            transparent_tint=col("transparent_tint", (1.0, 1.0, 1.0)),
            mix_normalize=col("mix_normalize", False, bool),
            normal_tex=col("normal_tex", -1, np.int32), normal_strength=col("normal_strength", 1.0),
            bump_tex=col("bump_tex", -1, np.int32), bump_strength=col("bump_strength", 1.0),
            bump_distance=col("bump_distance", 1.0),
            transmission=col("transmission", 0.0), glass_ior=col("glass_ior", 1.5),
            glass_reflect=col("glass_reflect", (1.0, 1.0, 1.0)), glass_refract=col("glass_refract", (1.0, 1.0, 1.0)),
            glass_alpha=col("glass_alpha", 0.0), glass_multiscatter=col("glass_multiscatter", 1.0),
            glass_fresnel=col("glass_fresnel", 1.0), glass_beckmann=col("glass_beckmann", 0.0),
            diffuse_roughness=col("diffuse_roughness", 0.0), holdout=col("holdout", False, bool),
            translucent=col("translucent", False, bool),
            aniso_aspect=col("aniso_aspect", 1.0), sheen_roughness=col("sheen_roughness", 0.0),
            aniso_rotation=col("aniso_rotation", 0.0),
            subsurface=col("subsurface", 0.0), sss_radius=col("sss_radius", (0.0, 0.0, 0.0)),
            sss_method=col("sss_method", 0, np.int32), sss_ior=col("sss_ior", 1.5),
            sss_anisotropy=col("sss_anisotropy", 0.0),
            absorption=col("absorption", (0.0, 0.0, 0.0)),
            **_mix_arrays(rows), **_programs(rows), **_programs(rows, "aov_program"),
            textures=list(textures or []), names=[r.get("name", f"material{i}") for i, r in enumerate(rows)])


def _mix_arrays(rows: list[dict]) -> dict:
    """The mix_* fields of :class:`MaterialTable` from rows' "mix" lists of (component, weight, texture, sign)."""
    first = np.full(len(rows), -1, np.int32)
    count = np.zeros(len(rows), np.int32)
    comps = []
    for i, r in enumerate(rows):
        if r.get("mix"):
            first[i], count[i] = len(comps), len(r["mix"])
            comps += list(r["mix"])
    cols = list(zip(*comps)) if comps else [(), (), (), ()]
    return {"mix_first": first, "mix_count": count, "mix_comp": np.array(cols[0], np.int32),
            "mix_weight": np.array(cols[1], np.float32), "mix_tex": np.array(cols[2], np.int32),
            "mix_sign": np.array(cols[3], np.float32)}


def _programs(rows: list[dict], key: str = "program") -> dict:
    """The program fields of :class:`MaterialTable` from rows' ``key`` entries (a Program or absent):
    {key: index (m,), key + "s": the programs}."""
    programs = [r[key] for r in rows if r.get(key) is not None]
    index, k = np.full(len(rows), -1, np.int32), 0
    for i, r in enumerate(rows):
        if r.get(key) is not None:
            index[i], k = k, k + 1
    return {key: index, key + "s": programs}


DEFAULT_MATERIAL = {"name": "(default grey)", "base_color": (0.8, 0.8, 0.8), "roughness": 0.5, "f0": 0.04}


@dataclass
class Lamps:
    """Blender Light objects that are not scene geometry: they emit but never occlude (as in Cycles).

    tris: emitting triangles (area shapes, spheres for point/spot). Per triangle:
    spot_center (n, 3) (the centre of a point/spot light), spot_axis (n, 3) unit, spot_cos (n,) cos of the
    half cone angle (-2 = no cone), spot_smooth (n,) blend width in cosine, camera_visible (n,) bool,
    sphere_radius (n,) the radius of the sphere a point/spot light's proxy triangles enclose (0 = the triangle
    itself emits), sphere_first (n,) int32 the first proxy triangle of that lamp (-1 = not a sphere).
    Suns (distant lights): sun_dir (s, 3) unit direction *towards* the sun,
    sun_cos (s,) cos of the half angle (1 = delta), sun_irradiance (s, 3) W·m⁻² on a surface facing it.
    textured: the lamps whose colour comes from a node graph that varies over them (lights/lamp_textures.py), a
    colour factor on their triangles' constant radiance that depends on the receiver.
    """

    tris: TriangleSet
    spot_center: np.ndarray
    spot_axis: np.ndarray
    spot_cos: np.ndarray
    spot_smooth: np.ndarray
    camera_visible: np.ndarray
    sun_dir: np.ndarray
    sun_cos: np.ndarray
    sun_irradiance: np.ndarray
    sphere_radius: np.ndarray = None
    sphere_first: np.ndarray = None
    group: np.ndarray = None      # (n,) int16 the lamp's light group (lights/groups.py; -1: none), None: no groups
    sun_group: np.ndarray = None  # (s,) int16 each sun's
    falloff: np.ndarray = None
    falloff_smooth: np.ndarray = None
    textured: object = None  # lights.lamp_textures.LampTextures: lamps coloured by node programs; None: none

    def __post_init__(self):
        n = len(self.spot_cos)
        if self.sphere_radius is None:
            self.sphere_radius = np.zeros(n, np.float32)
        if self.sphere_first is None:
            self.sphere_first = np.full(n, -1, np.int32)

    def falloff_terms(self) -> tuple:
        """(k (n,), smooth (n,)) float32 per lamp triangle: zeros where none were given (the physical falloff)."""
        n = len(self.spot_cos)
        if self.falloff is None or len(self.falloff) != n:
            return np.zeros(n, np.float32), np.zeros(n, np.float32)
        return self.falloff, self.falloff_smooth

    def receiver_dependent(self) -> np.ndarray:
        """(n,) bool: lamp triangles whose radiance depends on where the receiver is (a spot cone, a falloff)."""
        k, s = self.falloff_terms()
        out = (self.spot_cos > -1.5) | (k != 0) | (s > 0)
        if self.textured is not None:
            out = out | (self.textured.program >= 0)
        return out

    @staticmethod
    def empty() -> Lamps:
        z3 = np.zeros((0, 3), np.float32)
        z = np.zeros(0, np.float32)
        return Lamps(TriangleSet.empty(), z3, z3, z, z, np.zeros(0, bool), z3, z, z3)


@dataclass
class Camera:
    """Pinhole or orthographic camera.

    cam_to_world (4, 4) camera matrix (Blender: looks down -Z, +Y up)
    ndc_to_cam   (4, 4) inverse of Blender's projection matrix (``calc_matrix_camera``)
    width, height: full render resolution in pixels (after the percentage)
    window: (x0, y0, w, h) pixel rectangle to render, y0 counted from the bottom row (border/crop)
    clip_start, clip_end: camera clipping distances in scene units
    blind: the camera object is scaled to zero and has no orientation; it sees nothing (a black frame)
    pixel_filter: the film's filter (geometry.pixel_filter.PixelFilter) the camera samples land by; None = a box of
    one pixel
    lens: the thin lens of depth of field (geometry.lens.Lens), or None for a pinhole
    panorama: the panoramic projection (geometry.panorama.Panorama), or None
    """

    cam_to_world: np.ndarray
    ndc_to_cam: np.ndarray
    width: int
    height: int
    window: tuple
    ortho: bool = False
    clip_start: float = 0.1
    clip_end: float = 1000.0
    blind: bool = False
    pixel_filter: object = None
    lens: object = None  # geometry.lens.Lens for depth of field; None = pinhole
    panorama: object = None  # geometry.panorama.Panorama for a panoramic camera; None = perspective / orthographic


@dataclass
class Motion:
    """Object and camera transforms of the neighbouring frames, for motion vectors.

    current (k, 4, 4): each instance's world matrix now; prev / next (k, 4, 4): the same instances one
    frame before / after (equal to current where an instance does not exist then: it has no motion);
    camera_prev / camera_next: the camera then (None = unknown)."""

    current: np.ndarray
    prev: np.ndarray
    next: np.ndarray
    camera_prev: object = None
    camera_next: object = None

    def moved_points(self, points: np.ndarray, instance: np.ndarray, which: str) -> np.ndarray:
        """World positions (3, n) that surface points (3, n) on ``instance`` have in the 'prev' or 'next'
        frame."""
        other = self.prev if which == "prev" else self.next
        if len(other) == 0:  # no instances: nothing moves
            return points.astype(np.float32)
        instance = np.clip(instance, 0, len(other) - 1)
        xform = np.einsum("nij,njk->nik", other, affine_inverse(self.current))[instance]  # other · current⁻¹
        p = points.astype(np.float64)
        out = np.einsum("nij,jn->in", xform[:, :3, :3], p) + xform[:, :3, 3].T
        return out.astype(np.float32)


def affine_inverse(m: np.ndarray) -> np.ndarray:
    """Inverses of affine matrices (k, 4, 4) that tolerate singular ones: an object scaled to zero on some axis
    (how animators hide objects) gets the pseudo-inverse of its linear part, which takes its points back to the
    object's surviving axes (to its origin when scaled to zero on all), so they move with the object."""
    m = np.asarray(m, np.float64)
    lin = m[:, :3, :3]
    det = np.linalg.det(lin)
    scale = np.maximum(np.abs(lin).max(axis=(1, 2)), 1e-300)
    regular = np.abs(det) > 1e-12 * scale ** 3
    inv_lin = np.empty_like(lin)
    if regular.any():
        inv_lin[regular] = np.linalg.inv(lin[regular])
    if not regular.all():
        inv_lin[~regular] = np.linalg.pinv(lin[~regular])
    out = np.zeros_like(m)
    out[:, :3, :3] = inv_lin
    out[:, :3, 3] = -np.einsum("nij,nj->ni", inv_lin, m[:, :3, 3])
    out[:, 3, 3] = 1.0
    return out


@dataclass
class Scene:
    geometry: TriangleSet
    materials: MaterialTable
    lamps: Lamps
    camera: Camera
    world_radiance: np.ndarray = field(default_factory=lambda: np.zeros(3, np.float32))
    warnings: list = field(default_factory=list)
    world_image: np.ndarray | None = None     # (h, w, 3) equirectangular radiance (then world_radiance is unused)
    world_rotation: np.ndarray | None = None  # (3, 3) world -> environment texture frame (core/lights/world.py)
    world_camera_view: tuple | None = None    # (radiance (3,), image or None, graph or None) camera rays see instead
    world_graph: object = None                # lights.world.WorldGraph: world_image's exact source, or None
    motion: Motion | None = None
    blur: object = None  # geometry.motion_blur.ShutterMotion: where things are during the shutter (None: no motion blur)
    light_groups: object = None  # lights.groups.LightGroups: the view layer's light groups (None: none)
