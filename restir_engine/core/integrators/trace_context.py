"""The trace context: everything a frame's chunks need, built once per scene content (acceleration structures,
the light table, per-material rows, per-triangle normals, the world), and the instances' screen boxes."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from ..geometry.accel import Accel
from ..lights.table import LightTable, triangle_geometry
from ..lights.world import World
from ..lights.world_points import WorldSphere
from ..materials import microfacet_tables
from ..materials.cutout import Cutout
from ..materials.params import SurfaceParams
from ..scene import Scene


@dataclass
class TraceContext:
    """Everything a chunk needs, built once per frame (reused while the scene content is unchanged).
    Per-triangle data the path tracer gathers is kept as rows (structure of arrays)."""

    scene: Scene
    geom_accel: Accel
    lamp_accel: Accel
    lights: LightTable
    geom_ng: np.ndarray  # (n, 3) unit geometric normals
    lamp_ng: np.ndarray
    material_params: SurfaceParams  # per material, untextured (gathered per hit)
    max_bounces: int
    rr_start: int = 3
    film_transparent: bool = False
    material_albedo: np.ndarray = None  # (m, 32) GGX albedo rows over μo at each material's α
    material_layer: np.ndarray = None   # (m, 32) dielectric layer factor S rows over μo (microfacet_tables)
    has_mix: bool = False  # some material is a Mix/Add shader (core/materials/mix.py)
    world: World = None    # the background as a light (core/lights/world.py)
    normal_maps: bool = False  # some material has a tangent-space normal map (image_normals.normal_map)
    bump_maps: bool = False    # some material has a Bump node (image_normals.bump_map)
    has_glass: bool = False    # some material has a smooth glass closure (core/materials/glass.py)
    has_programs: bool = False  # some material has a node program (core/materials/nodes)
    reads_path: bool = False  # some material's program reads the Light Path's ray type or depths (path_state.py)
    anisotropic: bool = False  # some material may have an anisotropic GGX lobe (core/materials/anisotropy.py)
    sheen: bool = False  # some material is a sheen lobe (core/materials/sheen.py)
    has_subsurface: bool = False  # some material has a subsurface share (integrators/subsurface.py)
    geom_flat: np.ndarray = None        # (n,) bool: the triangle's three corner normals are equal (no interpolation)
    geom_ng_rows: np.ndarray = None     # (3, n) geom_ng as rows
    geom_normal_rows: np.ndarray = None  # (9, n) corner shading normals as rows (corner 0 x, y, z, corner 1 ...)
    lamp_ng_rows: np.ndarray = None     # (3, n_lamp) lamp_ng as rows
    geom_derived: "GeometryDerived" = None  # the geometry-only arrays above, kept for a rebuild over the same triangles
    emit_accel: Accel = None  # the emissive scene triangles alone (light index = primitive index), or None
    groups: object = None  # lights.groups.GroupMap of this frame's light groups, or None (no groups)
    # what rendering this content measured (shared by the frames and views that reuse this context):
    # "auto_indirect" -> the last frame's AUTO indirect measurement and choice (renderer.FrameRenderer._remember)
    measured: dict = field(default_factory=dict)




@dataclass
class GeometryDerived:
    """Per-triangle arrays derived from the geometry alone (kept while the triangles are unchanged)."""

    bounds: tuple          # (min (3,), max (3,)) of the finite vertices, or None when there are none
    ng: np.ndarray         # (n, 3) unit geometric normals
    ng_rows: np.ndarray    # (3, n)
    flat: np.ndarray       # (n,) bool: the three corner normals are equal
    normal_rows: np.ndarray  # (9, n) corner shading normals as rows
    boxes: tuple = None    # (lo (k, 3), hi (k, 3)): each instance's box (one box without instances; camera.box_pixels)
    box_ids: np.ndarray | None = None  # (k,) the instance each box belongs to (None: one box for the whole scene)

    @staticmethod
    def of(geom) -> "GeometryDerived":
        verts = geom.verts.reshape(-1, 3)
        finite = verts[np.isfinite(verts).all(axis=1)]
        bounds = (finite.min(0), finite.max(0)) if len(finite) else None
        ids, lo, hi = instance_box_table(geom, bounds)
        ng, _ = triangle_geometry(geom.verts) if len(geom) else (np.zeros((0, 3), np.float32), None)
        nrm = geom.normals
        flat = (nrm[:, 0] == nrm[:, 1]).all(axis=1) & (nrm[:, 0] == nrm[:, 2]).all(axis=1)
        return GeometryDerived(bounds, ng, np.ascontiguousarray(ng.T), flat,
                               np.ascontiguousarray(nrm.reshape(len(nrm), 9).T, dtype=np.float32), (lo, hi), ids)


def instance_boxes(geom, bounds) -> tuple:
    """(lo (k, 3), hi (k, 3)) float32: the bounding box of each instance's finite vertices (geometry.instance),
    or the scene's ``bounds`` as one box when there are no instances; empty without geometry."""
    _ids, lo, hi = instance_box_table(geom, bounds)
    return lo, hi


def instance_box_table(geom, bounds) -> tuple:
    """(ids (k,) int32 or None, lo (k, 3), hi (k, 3)): :func:`instance_boxes` with the instance of each box, in
    increasing instance order (ids None: one box, the scene's ``bounds``, for a scene without instances)."""
    empty = (np.zeros((0, 3), np.float32), np.zeros((0, 3), np.float32))
    if bounds is None:
        return (None,) + empty
    inst = geom.instance
    if inst is None or len(inst) == 0 or inst.min() == inst.max():
        return None, np.asarray(bounds[0], np.float32)[None], np.asarray(bounds[1], np.float32)[None]
    return boxes_by_instance(geom.verts, inst)


def boxes_by_instance(verts: np.ndarray, inst: np.ndarray) -> tuple:
    """(ids (k,) int32, lo (k, 3), hi (k, 3)) float32: the box of the finite corners of each instance among the
    triangles ``verts`` (n, 3, 3) with instances ``inst`` (n,), in increasing instance order (instances without a
    finite corner left out)."""
    if not len(inst):
        return np.zeros(0, np.int32), np.zeros((0, 3), np.float32), np.zeros((0, 3), np.float32)
    ok = np.isfinite(verts).all(axis=2)[..., None]
    tlo = np.where(ok, verts, np.inf).min(axis=1)
    thi = np.where(ok, verts, -np.inf).max(axis=1)
    order = np.argsort(inst, kind="stable")
    starts = np.flatnonzero(np.r_[True, np.diff(inst[order]) != 0])
    lo = np.minimum.reduceat(tlo[order], starts)
    hi = np.maximum.reduceat(thi[order], starts)
    keep = np.isfinite(lo).all(axis=1) & np.isfinite(hi).all(axis=1)
    ids = inst[order][starts][keep].astype(np.int32)
    return ids, lo[keep].astype(np.float32), hi[keep].astype(np.float32)


def build_context(scene: Scene, max_bounces: int, film_transparent: bool = False, accels: dict | None = None
                  ) -> TraceContext:
    """Everything the chunks need for ``scene``. ``accels`` (optional) hands over what an earlier context built
    over exactly these triangles (an edit of materials, lamps or the world): "geom" / "lamp" Embree scenes
    (Accel), "derived" (GeometryDerived); they are reused instead of rebuilt."""
    accels = accels or {}
    geom = scene.geometry
    lamps = scene.lamps
    derived = accels.get("derived") or GeometryDerived.of(geom)
    geom_ng = derived.ng
    lamp_ng, _ = triangle_geometry(lamps.tris.verts) if len(lamps.tris) else (np.zeros((0, 3), np.float32), None)
    params = SurfaceParams.of_table(scene.materials)
    geom_ng_rows = derived.ng_rows
    cut = Cutout.of(geom, scene.materials)
    geom_accel = accels["geom"].with_cutout(cut, geom_ng_rows if cut else None) if "geom" in accels else \
        Accel(geom.verts, cut, geom_ng_rows if cut else None)
    world = World(scene.world_radiance, getattr(scene, "world_image", None), getattr(scene, "world_rotation", None),
                  getattr(scene, "world_camera_view", None), getattr(scene, "world_graph", None))
    lights = scene_lights(scene, derived.bounds, world)
    return TraceContext(scene=scene, geom_accel=geom_accel,
                        lamp_accel=accels["lamp"] if "lamp" in accels else Accel(lamps.tris.verts),
                        lights=lights, geom_ng=geom_ng, lamp_ng=lamp_ng,
                        emit_accel=Accel(lights.tri_verts[:lights.n_geom]) if lights.n_geom else None,
                        material_params=params, max_bounces=int(max(0, max_bounces)),
                        film_transparent=film_transparent, material_albedo=microfacet_tables.albedo_rows(params.alpha),
                        material_layer=microfacet_tables.layer_rows(params.alpha, params.f0r),
                        has_mix=scene.materials.mix_first is not None and bool((scene.materials.mix_first >= 0).any()),
                        normal_maps=scene.materials.normal_tex is not None
                        and bool((scene.materials.normal_tex >= 0).any()),
                        bump_maps=scene.materials.bump_tex is not None and bool((scene.materials.bump_tex >= 0).any()),
                        has_glass=scene.materials.transmission is not None
                        and bool((scene.materials.transmission > 0).any()),
                        has_programs=bool(getattr(scene.materials, "programs", None)),
                        reads_path=_reads_path(scene.materials),
                        anisotropic=may_be_anisotropic(scene.materials), world=world,
                        sheen=getattr(scene.materials, "sheen_roughness", None) is not None
                        and bool((scene.materials.sheen_roughness > 0).any()),
                        has_subsurface=may_have_subsurface(scene.materials),
                        geom_flat=derived.flat, geom_ng_rows=geom_ng_rows, geom_normal_rows=derived.normal_rows,
                        lamp_ng_rows=np.ascontiguousarray(lamp_ng.T), geom_derived=derived)


def may_have_subsurface(mats) -> bool:
    """Whether some material walks beneath its surface: a random-walk method with a Subsurface Weight above 0 (or
    one its node program computes)."""
    method = getattr(mats, "sss_method", None)
    if method is None or not (method > 0).any():
        return False
    w = mats.subsurface
    if bool(((w > 0) & (method > 0)).any()):
        return True
    prog = getattr(mats, "program", None)
    if prog is None:
        return False
    progs = getattr(mats, "programs", None) or ()
    return any(p >= 0 and progs[p].has("subsurface") for p in prog[method > 0])


def may_be_anisotropic(mats) -> bool:
    """Whether some material's aspect is not 1 or its node program computes one."""
    aspect = getattr(mats, "aniso_aspect", None)
    if aspect is not None and bool((aspect != 1).any()):
        return True
    return any(p.has("aniso_aspect") for p in getattr(mats, "programs", None) or ())


def scene_bounds(scene: Scene, geometry_bounds) -> tuple:
    """(lo (3,), hi (3,), radius): the box of the scene's finite triangle and lamp vertices (``geometry_bounds``:
    GeometryDerived.bounds) and half its diagonal (1 for an empty scene)."""
    lamp_verts = scene.lamps.tris.verts.reshape(-1, 3)
    lamp_verts = lamp_verts[np.isfinite(lamp_verts).all(axis=1)]
    boxes = [b for b in (geometry_bounds, (lamp_verts.min(0), lamp_verts.max(0)) if len(lamp_verts) else None)
             if b is not None]
    lo = np.min([b[0] for b in boxes], axis=0) if boxes else np.zeros(3)
    hi = np.max([b[1] for b in boxes], axis=0) if boxes else np.zeros(3)
    radius = float(np.linalg.norm(hi - lo) / 2) if boxes else 1.0
    return lo, hi, radius


def scene_lights(scene: Scene, geometry_bounds, world: World) -> LightTable:
    """The light table of ``scene`` (its scene radius from :func:`scene_bounds`), the world attached where it is
    sampled (its points may enter ReSTIR DI reservoirs: di.CandidateSettings.world_candidates)."""
    lo, hi, radius = scene_bounds(scene, geometry_bounds)
    lights = LightTable(scene, max(radius, 1e-3))
    if world.sampled:
        lights.attach_world(WorldSphere(world, (lo + hi) / 2, max(radius, 1e-3)))
    return lights


def moved_context(base: TraceContext, scene: Scene, rows: np.ndarray, still: tuple | None = None,
                  into: TraceContext | None = None) -> TraceContext:
    """``base``'s context for ``scene``, the same scene with the triangle rows ``rows`` moved (motion blur's
    poses, geometry/motion_blur.py): the moved rows' derived arrays and their Embree scene rebuilt (the others'
    Embree scene, built over the unmoved rows, is shared: ``still`` (Accel, rows) from an earlier call's
    :meth:`SplitAccel.still_part` with the same ``rows``), the light table rebuilt where an emitter moved; the
    materials, lamps and the world are base's. ``into``: an earlier result of this call with the same ``base``
    and ``rows``, whose per-triangle arrays are overwritten in those rows only (it is not to be used after)."""
    from ..geometry.accel import SplitAccel
    from .context_update import moved_lights, updated_derived
    geom = scene.geometry
    derived = updated_derived(base.geom_derived, geom, rows, None if into is None else into.geom_derived)
    if still is None:
        still = _still_part(base, rows)
    cut = base.geom_accel.cutout
    cut = None if cut is None else cut.with_geometry(geom)
    accel = SplitAccel(still[0], still[1], geom.verts[rows], rows, cut, derived.ng_rows if cut else None)
    lights, emit_accel = moved_lights(base, scene, rows, derived)
    return dataclasses.replace(base, scene=scene, geom_accel=accel, lights=lights, emit_accel=emit_accel,
                               geom_ng=derived.ng, geom_ng_rows=derived.ng_rows, geom_normal_rows=derived.normal_rows,
                               geom_flat=derived.flat, geom_derived=derived, measured=base.measured)


_STILL: tuple | None = None  # (Accel of a base context, moving rows, (Accel, rows) of the others): the last built


def _still_part(base: TraceContext, rows: np.ndarray) -> tuple:
    """(Accel, rows) of ``base``'s triangles outside ``rows``: the last one built for the same base context and
    rows (the bands of a banded frame share it), else built now."""
    global _STILL
    kept = _STILL
    if kept is not None and kept[0] is base.geom_accel and np.array_equal(kept[1], rows):
        return kept[2]
    keep = np.ones(len(base.scene.geometry), bool)
    keep[rows] = False
    still_rows = np.flatnonzero(keep)
    still = (Accel(base.scene.geometry.verts[still_rows]), still_rows)
    _STILL = (base.geom_accel, rows.copy(), still)
    return still


def _reads_path(materials) -> bool:
    """Whether some material's node program reads the Light Path outputs carried along paths."""
    from ..materials.nodes.attributes import PATH_ATTRIBUTES
    wanted = set(PATH_ATTRIBUTES)
    return any(wanted.intersection(getattr(p, "reads", ())) for p in getattr(materials, "programs", None) or ())
