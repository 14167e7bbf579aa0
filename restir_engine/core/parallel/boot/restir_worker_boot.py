"""Entry point of a render worker process (parallel/processes.py starts it with multiprocessing's spawn).

This file is imported on its own, from its folder on ``sys.path``, never as part of the add-on: the add-on's
package imports bpy, which a worker cannot. It limits the worker's math libraries to one thread, ignores Ctrl+C
(the rendering process stops its workers), exits when the rendering process is gone, loads the core package from
``core_dir`` under the name ``restir_core`` and serves the rendering process (restir_core.pipeline.worker).
"""
import os
import sys

THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS",
                    "VECLIB_MAXIMUM_THREADS")


def _watch_parent() -> None:
    import multiprocessing
    import threading
    from multiprocessing import connection

    parent = multiprocessing.parent_process()
    if parent is None:
        return

    def watch():
        connection.wait([parent.sentinel])
        os._exit(3)

    threading.Thread(target=watch, name="restir-parent-watch", daemon=True).start()


def main(core_dir: str, *args) -> None:
    for name in THREAD_VARIABLES:
        os.environ[name] = "1"
    import signal
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _watch_parent()
    import importlib.util
    spec = importlib.util.spec_from_file_location("restir_core", os.path.join(core_dir, "__init__.py"),
                                                  submodule_search_locations=[core_dir])
    module = importlib.util.module_from_spec(spec)
    sys.modules["restir_core"] = module
    spec.loader.exec_module(module)
    from restir_core.pipeline import worker
    worker.serve(*args)
