"""The facts docs/ARCHITECTURE.md states about the code: the import ranks of core's folders, the packed target's
width and the stage names of a sample pass."""
import ast
import os
import re

from restir_engine.core.restir import target

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CORE = os.path.join(ROOT, "restir_engine", "core")
ARCHITECTURE = open(os.path.join(ROOT, "docs", "ARCHITECTURE.md")).read()
# ARCHITECTURE.md, "Folders and import ranks"
RANKS = {"scene": 0, "sampling": 0, "profile": 0, "parallel": 0, "modes": 0, "geometry": 1, "materials": 2, "lights": 2,
         "restir": 3, "integrators": 3, "pipeline": 4, "renderer": 4}


def _core_imports():
    """(importing unit, imported unit) for every import between core's top-level units."""
    for folder, _dirs, files in os.walk(CORE):
        for name in files:
            if not name.endswith(".py"):
                continue
            path = os.path.join(folder, name)
            rel = os.path.relpath(path, CORE).split(os.sep)
            unit = rel[0][:-3] if rel[0].endswith(".py") else rel[0]
            if unit == "__init__":
                continue
            pkg = ["restir_engine", "core"] + rel[:-1]
            for node in ast.walk(ast.parse(open(path).read())):
                if isinstance(node, ast.ImportFrom):
                    if node.level:
                        base = pkg[:len(pkg) - node.level + 1] + (node.module.split(".") if node.module else [])
                    else:
                        base = node.module.split(".")
                    assert base[0] != "bpy", path
                    if base[:2] != ["restir_engine", "core"]:
                        assert base[0] != "restir_engine", f"{path} imports {'.'.join(base)} outside core"
                        continue
                    targets = [base[2]] if len(base) > 2 else [a.name for a in node.names]
                    for t in targets:
                        yield path, unit, t
                elif isinstance(node, ast.Import):
                    for a in node.names:
                        assert not a.name.startswith(("bpy", "restir_engine")) or a.name.startswith(
                            "restir_engine.core"), path


def test_core_imports_follow_the_ranks():
    for path, unit, imported in _core_imports():
        assert unit in RANKS and imported in RANKS, (path, imported)
        assert RANKS[imported] <= RANKS[unit], f"{os.path.relpath(path, ROOT)} (rank {RANKS[unit]}) imports " \
                                               f"{imported} (rank {RANKS[imported]})"


def test_every_core_folder_has_a_rank_in_the_docs():
    units = {n[:-3] if n.endswith(".py") else n for n in os.listdir(CORE)
             if not n.startswith("__") and (n.endswith(".py") or os.path.isdir(os.path.join(CORE, n)))}
    units.discard("__pycache__")
    assert units == set(RANKS)
    for unit in RANKS:
        assert re.search(rf"core/{unit}(\.py|/)", ARCHITECTURE), unit


def test_target_width_is_what_the_docs_say():
    assert target.WIDTH == 32
    assert f"(WIDTH, n) = ({target.WIDTH}, n)" in ARCHITECTURE
    assert "27 rows" not in ARCHITECTURE and "(27, n)" not in ARCHITECTURE


def _stage_names_in_code():
    names = set()
    folder = os.path.join(CORE, "pipeline")
    for name in os.listdir(folder):
        if name.endswith(".py"):
            text = open(os.path.join(folder, name)).read()
            names |= set(re.findall(r'stage\("(\w+)"\)', text))
            names |= set(re.findall(r'"(gi_temporal|gi_spatial|temporal|spatial)"\)', text))
    return names


def test_stage_names_are_listed_in_the_plan_and_the_docs():
    from restir_engine.core.pipeline import plan
    code = _stage_names_in_code()
    assert {"probe", "primary", "initial", "paths", "gbuffer", "temporal", "boiling", "spatial", "gi_temporal",
            "gi_spatial", "shade", "passes"} == code
    listed = set(re.findall(r"^  (\w+)\s", plan.__doc__, re.M))
    assert code == listed
    table = set(re.findall(r"^\| (\w+) \|", ARCHITECTURE.split("## One frame through the code")[1], re.M))
    assert code <= table


def test_a_timed_frame_reports_only_the_listed_stages():
    from restir_engine.core.profile import StageClock
    from restir_engine.core.renderer import RenderSettings, render_frame
    from scenes_core import regression_room
    clock = StageClock()
    render_frame(regression_room(24, 18), RenderSettings(integrator="RESTIR", direct_method="RESTIR",
                                                         indirect_method="RESTIR_GI", max_bounces=1, samples=1,
                                                         bias_correction="UNBIASED", data_passes=False), clock=clock)
    assert {"primary", "initial", "paths", "gbuffer", "spatial", "gi_spatial", "shade", "passes"} <= set(clock.stages)
    assert set(clock.stages) <= _stage_names_in_code()
