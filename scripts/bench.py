"""One runner for every benchmark case (scripts/benchmarks/<case>.py):

    .venv313/bin/python scripts/bench.py --list              # the cases and what each measures
    .venv313/bin/python scripts/bench.py CASE [ARGS...]      # run one; ARGS are the case's own (CASE --help)

The runner puts the repository, scripts/ and tests/ on sys.path, so a case imports the add-on, the harness
(scripts/harness/) and the test scenes directly; each writes its JSON (benchmarks.common.write_json) and charts
under docs/results/. Most cases need the bpy venvs (scripts/setup_venv.sh); stages, foundation and gi_materials
can time exported or core scenes.
"""
from __future__ import annotations

import importlib
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# the cases, in one place: name -> module under scripts/benchmarks/
CASES = ("ablation_restir_di", "adaptive", "coverage", "default_cube", "defaults", "denoise", "direct_methods",
         "first_sample", "foundation", "frame_cost", "gi_materials", "glass", "integrators", "material_cost",
         "memory", "memory_1080p", "memory_bands", "motion_blur", "node_cost", "pan", "restir_di", "restir_gi",
         "scaling", "scene_update", "sky", "stages", "subsurface", "team_timeline", "third_party", "viewport",
         "world_light", "world_reservoirs", "evaluate")


def bootstrap() -> None:
    for p in (os.path.join(ROOT, "tests"), os.path.join(ROOT, "scripts"), ROOT):
        if p not in sys.path:
            sys.path.insert(0, p)


def module_name(case: str) -> str:
    return "evaluate" if case == "evaluate" else f"benchmarks.{case}"


def summary(case: str) -> str:
    """The first line of the case's docstring, read without importing it (most cases import bpy)."""
    import ast
    path = os.path.join(ROOT, "scripts", *module_name(case).split(".")) + ".py"
    doc = ast.get_docstring(ast.parse(open(path).read())) or ""
    return doc.strip().splitlines()[0] if doc.strip() else ""


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if not argv or argv[0] in ("-h", "--help", "--list"):
        print(__doc__)
        for case in CASES:
            print(f"  {case:20s} {summary(case)}")
        return 0
    case, args = argv[0], argv[1:]
    if case not in CASES:
        print(f"bench.py: unknown case {case!r}; --list shows them", file=sys.stderr)
        return 2
    bootstrap()
    module = importlib.import_module(module_name(case))
    sys.argv = [f"bench.py {case}"] + args
    result = module.main()
    return result if isinstance(result, int) else 0


if __name__ == "__main__":
    sys.exit(main())
