"""What the Light Path node reads at the vertices of a path tracer's paths, carried along each path: the type of the
ray that reached a vertex (diffuse, glossy or singular lobe; reflection or transmission) and the bounces before it,
as Cycles counts them (diffuse and glossy reflections and transmissions apart; glossy counts singular rays too).

A state is a dict of (n,) float32 arrays named as materials/nodes/attributes.PATH_ATTRIBUTES, aligned with the
surfaces of the current vertices; a camera hit's is :func:`at_camera` (all 0)."""
from __future__ import annotations

import numpy as np

from ..materials.glass import ROUGH_ALPHA_MIN
from ..materials.microfacet_tables import ALPHA_MIN
from ..materials.nodes.attributes import PATH_ATTRIBUTES, SURFACE_DEFAULT
from ..sampling import cols, dot

#: the alpha up to which a microfacet lobe counts as singular (a mirror; Cycles: α² <= 2e-10, below the smallest
#: alpha the lobes here keep, ALPHA_MIN, which roughness up to 0.03 reaches)
SINGULAR_ALPHA = ALPHA_MIN * 1.001


def at_camera(n: int) -> dict:
    """The state of n camera hits: no bounce yet, no ray type."""
    return {k: np.zeros(n, np.float32) for k in PATH_ATTRIBUTES}


def unknown(n: int) -> dict:
    """The state of n rays of unknown type (a subsurface walk's exits): a diffuse reflection after one bounce."""
    return {k: np.full(n, np.float32(SURFACE_DEFAULT.get(k, 0.0)), np.float32) for k in PATH_ATTRIBUTES}


def ray_kinds(s, u_lobe: np.ndarray, wi: np.ndarray) -> tuple:
    """(diffuse, singular, transmit) (n,) bool of the BSDF samples ``wi`` (3, n, world) drawn at surfaces ``s``
    (a Surface) with lobe-choice uniforms ``u_lobe``: glass samples are glossy (singular when smooth) and transmit
    where they cross the surface; a Translucent BSDF's transmit diffusely; other samples are glossy where the
    specular lobe was chosen, else diffuse reflections."""
    p = s.params
    spec = u_lobe < p.p_spec
    singular = spec & (p.alpha <= SINGULAR_ALPHA)
    diffuse = ~spec
    transmit = np.zeros(len(u_lobe), bool)
    if s.translucent is not None:
        transmit |= s.translucent
    if s.glass is not None:
        g = np.flatnonzero(s.glass)
        front = s.facing_normals()[0]
        diffuse[g] = False
        singular[g] = s.glass_alpha[g] <= ROUGH_ALPHA_MIN  # smooth glass: a delta closure
        transmit[g] = dot(cols(wi, g), cols(front, g)) < 0
    return diffuse, singular, transmit


def after_bounce(state: dict, rows: np.ndarray, diffuse, singular, transmit) -> dict:
    """The state of the rays leaving the vertices ``rows`` of ``state`` with the kinds given per ray."""
    reflect = ~transmit
    f = np.float32
    out = {"ray_depth": state["ray_depth"][rows] + f(1),
           "diffuse_depth": state["diffuse_depth"][rows] + (diffuse & reflect),
           "glossy_depth": state["glossy_depth"][rows] + (~diffuse & reflect),
           "transmission_depth": state["transmission_depth"][rows] + transmit,
           "transparent_depth": state["transparent_depth"][rows],
           "is_diffuse_ray": diffuse, "is_glossy_ray": ~diffuse, "is_singular_ray": singular,
           "is_reflection_ray": reflect, "is_transmission_ray": transmit}
    return {k: np.asarray(v, np.float32) for k, v in out.items()}


def take(state: dict | None, rows: np.ndarray) -> dict | None:
    """The state of the paths ``rows``."""
    return None if state is None else {k: v[rows] for k, v in state.items()}
