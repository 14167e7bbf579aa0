"""The automatic direct-light method (core/direct_choice.py) and that the renderer applies and reports it."""
from scenes_core import floor_with_emitter
from test_light_tiles import _many_coloured_lights
from test_sphere_lights import floor_under_sphere

from restir_engine.core import pathtracer
from restir_engine.core.direct_choice import FEW_LIGHTS, choose_direct_method
from restir_engine.core.renderer import RenderSettings, render_frame


def lights_of(scene):
    return pathtracer.build_context(scene, 0).lights


def test_rules():
    sphere, square, many = lights_of(floor_under_sphere()), lights_of(floor_with_emitter()), lights_of(_many_coloured_lights())
    assert many.n_tri > FEW_LIGHTS >= square.n_tri
    assert choose_direct_method(sphere, False, 0)[0] == "LIGHT_SAMPLING"  # cone-sampled lamps
    assert choose_direct_method(square, False, 0)[0] == "RESTIR"          # area light, direct only
    assert choose_direct_method(square, False, 4)[0] == "LIGHT_SAMPLING"  # indirect noise dominates
    assert choose_direct_method(many, False, 4)[0] == "RESTIR"
    assert choose_direct_method(sphere, True, 4)[0] == "RESTIR"          # a reservoir pass needs reservoirs
    method, reason = choose_direct_method(many, False, 0)
    assert str(many.n_tri) in reason


def test_renderer_applies_and_reports_the_choice():
    r = render_frame(floor_under_sphere(width=16), RenderSettings(samples=1, integrator="RESTIR", direct_method="AUTO",
                                                                  max_bounces=1))
    assert r.stats["direct_method"] == "LIGHT_SAMPLING" and "Reservoir M" not in r.passes
    r = render_frame(_many_coloured_lights(16), RenderSettings(samples=1, integrator="RESTIR", direct_method="AUTO",
                                                               max_bounces=0))
    assert r.stats["direct_method"] == "RESTIR" and "Reservoir M" in r.passes
    assert r.stats["spatial_radius"] >= 4.0
