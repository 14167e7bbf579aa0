"""What every benchmark case shares: the repository's paths (``scripts/bench.py`` puts the repository, scripts/ and
tests/ on sys.path before a case is imported) and the JSON writer of their results."""
from __future__ import annotations

import json
import os

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
RESULTS = os.path.join(ROOT, "docs", "results")


def write_json(path: str, data, indent: int = 1) -> None:
    """Write ``data`` as JSON to ``path`` (its folder made if missing), ending with a newline."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w") as f:
        json.dump(data, f, indent=indent)
        f.write("\n")


def render_rgb(scene, path: str) -> tuple:
    """(RGB (h, w, 3) float32 with row 0 at the top as Blender's image pixels are read, seconds): an F12 of ``scene``
    through ``bpy.ops.render.render``, written to ``path`` as a 32-bit EXR and read back; the seconds are the
    render's wall time (export, render, denoising)."""
    import time

    import bpy
    import numpy as np

    from restir_engine.compat import set_output_format
    set_output_format(scene.render.image_settings, "OPEN_EXR")
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = path
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    seconds = time.perf_counter() - t0
    img = bpy.data.images.load(path, check_existing=False)
    px = np.array(img.pixels[:], np.float32).reshape(img.size[1], img.size[0], -1)[..., :3]
    bpy.data.images.remove(img)
    return px, seconds


def bar_chart(path: str, labels, values, ylabel: str, title: str, reference: tuple | None = None) -> None:
    """A bar per label (``values`` in the labels' order) saved as a PNG at ``path``; ``reference`` (label, value)
    draws a dashed horizontal line for comparison."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 3.6))
    ax.bar(range(len(values)), values, color="#4c72b0")
    ax.set_xticks(range(len(values)), labels)
    for i, v in enumerate(values):
        ax.text(i, v, f"{v:.2f}", ha="center", va="bottom")
    if reference is not None:
        ax.axhline(reference[1], ls="--", color="#c44e52", label=reference[0])
        ax.legend()
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(True, axis="y", alpha=0.3)
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
