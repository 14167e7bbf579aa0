"""scripts/bench.py: every module under scripts/benchmarks/ is a registered case, imports, and has its main()."""
import importlib
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def test_every_benchmark_is_a_registered_case_that_imports(addon):
    sys.path.insert(0, os.path.join(ROOT, "scripts"))
    import bench
    bench.bootstrap()
    modules = {n[:-3] for n in os.listdir(os.path.join(ROOT, "scripts", "benchmarks"))
               if n.endswith(".py") and n not in ("__init__.py", "common.py")}
    assert set(bench.CASES) == modules | {"evaluate"}
    for case in bench.CASES:
        module = importlib.import_module(bench.module_name(case))
        assert callable(module.main), case
        assert bench.summary(case), f"{case} has no docstring"


def test_unknown_case_is_refused(capsys):
    sys.path.insert(0, os.path.join(ROOT, "scripts"))
    import bench
    assert bench.main(["no_such_case"]) == 2
    assert "unknown case" in capsys.readouterr().err
