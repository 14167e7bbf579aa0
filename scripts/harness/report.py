"""Charts (PNG) and the Markdown table of an evaluation run."""
from __future__ import annotations

import math

import numpy as np

from . import metrics


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def display(img: np.ndarray, scale: float) -> np.ndarray:
    """Scene-linear RGB -> sRGB-encoded [0, 1] for the strips (exposure 1/scale)."""
    x = np.clip(np.asarray(img, np.float64)[..., :3] / max(scale, 1e-8), 0, 1)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


def chart_scene(result: dict, methods, path: str):
    plt = _plt()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for m in methods:
        pts = [p for p in result["points"] if p["method"] == m.key]
        if not pts:
            continue
        axes[0].loglog([p["wall"] for p in pts], [p["relmse"] for p in pts], "o-", color=m.color, label=m.label)
        for p in pts:
            axes[0].annotate(str(p["spp"]), (p["wall"], p["relmse"]), fontsize=7, textcoords="offset points",
                             xytext=(3, 3))
        lit = [p for p in pts if "relmse_lit" in p]
        core = [p for p in pts if p.get("core")]
        if lit:  # direct-light scene: the right panel scores surfaces only (Combined - Emission)
            axes[1].loglog([p["wall"] for p in lit], [p["relmse_lit"] for p in lit], "o-", color=m.color,
                           label=m.label)
        elif core:
            axes[1].loglog([p["core"] for p in core], [p["relmse"] for p in core], "o-", color=m.color, label=m.label)
    has_lit = any("relmse_lit" in p for p in result["points"])
    axes[0].set_xlabel("wall-clock seconds per frame (Blender render incl. export)")
    axes[1].set_xlabel("wall-clock seconds per frame" if has_lit else "core seconds per frame (renderer only, our methods)")
    for ax in axes:
        ax.set_ylabel("relMSE")
    if has_lit:
        axes[0].set_title("Combined", fontsize=8)
        axes[1].set_title("surfaces only: Combined - Emission (emitters seen directly removed)", fontsize=8)
        axes[1].set_ylabel("relMSE (Combined - Emission)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(f"{result['title']}  ({result['size'][0]}x{result['size'][1]}, {result['bounces']} bounces, "
                 f"reference: Cycles {result['reference_spp']} spp; numbers = samples per pixel)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def equal_time_points(result: dict, methods, budget: float) -> dict:
    """For each method the point whose wall time is closest to ``budget`` (log distance)."""
    out = {}
    for m in methods:
        pts = [p for p in result["points"] if p["method"] == m.key]
        if pts:
            out[m.key] = min(pts, key=lambda p: abs(math.log(p["wall"] / budget)))
    return out


def strip_scene(result: dict, images: dict, reference: np.ndarray, methods, budget: float, path: str):
    plt = _plt()
    chosen = equal_time_points(result, methods, budget)
    n = 1 + len(chosen)
    fig, axes = plt.subplots(2, n, figsize=(2.6 * n, 4.4))
    axes = np.atleast_2d(axes)
    scale = float(np.percentile(reference.mean(axis=2), 99)) or 1.0
    axes[0, 0].imshow(display(reference, scale), origin="lower")
    axes[0, 0].set_title("reference", fontsize=8)
    axes[1, 0].axis("off")
    for k, (key, p) in enumerate(chosen.items(), start=1):
        img = images[(key, p["spp"])]
        label = next(m.label for m in methods if m.key == key)
        axes[0, k].imshow(display(img, scale), origin="lower")
        axes[0, k].set_title(f"{label}\n{p['spp']} spp, {p['wall']:.2f}s, relMSE {p['relmse']:.3g}", fontsize=7)
        err = np.abs(img - reference).mean(axis=2) / (reference.mean(axis=2) + 0.1)
        axes[1, k].imshow(err, origin="lower", cmap="magma", vmin=0, vmax=1)
        axes[1, k].set_title("|error| / (ref + 0.1)", fontsize=7)
    for ax in axes.ravel():
        ax.set_xticks([])
        ax.set_yticks([])
    fig.suptitle(f"{result['title']}: equal time ≈ {budget:.2f} s", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def table_rows(result: dict, methods, budget: float, target: float) -> list[str]:
    rows = []
    for m in methods:
        pts = [p for p in result["points"] if p["method"] == m.key]
        if not pts:
            continue
        walls = [p["wall"] for p in pts]
        errs = [p["relmse"] for p in pts]
        inside = min(walls) <= budget <= max(walls)  # no extrapolation: outside the measured range is "—"
        at_budget = metrics.interpolate_loglog(walls, errs, budget) if inside else float("nan")
        lit = float("nan")
        if inside and all("relmse_lit" in p for p in pts):
            lit = metrics.interpolate_loglog(walls, [p["relmse_lit"] for p in pts], budget)
        reach = metrics.time_to_reach(walls, errs, target)
        best = max(pts, key=lambda p: p["spp"])
        rows.append(f"| {result['title']} | {m.label} | {'—' if math.isnan(at_budget) else f'{at_budget:.4g}'} | "
                    f"{'—' if math.isnan(lit) else f'{lit:.4g}'} | "
                    f"{'—' if math.isinf(reach) else f'{reach:.2f} s'} | {best['bias'] * 100:+.2f} % ({best['spp']} spp) "
                    f"| {best['flip']:.4f} |")
    return rows


def chart_growth(growth: dict, path: str):
    plt = _plt()
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    for ax, key, xlabel in zip(axes, ("lights", "resolution", "triangles"),
                               ("emissive triangles", "pixels", "scene triangles")):
        pts = growth.get(key, [])
        if not pts:
            continue
        xs = [p["x"] for p in pts]
        ax.loglog(xs, [p["core"] for p in pts], "o-", label="core (renderer)")
        ax.loglog(xs, [p["wall"] for p in pts], "s--", label="wall (Blender, incl. export)")
        ax.set_xlabel(xlabel)
        ax.set_ylabel("seconds per frame")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        ax.set_title(f"path tracer, {pts[0]['spp']} spp, {pts[0]['bounces']} bounces", fontsize=8)
    fig.suptitle("Cost growth", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def chart_animation(anim: dict, methods, path: str):
    plt = _plt()
    fig, ax = plt.subplots(1, 1, figsize=(6, 3.6))
    for m in methods:
        series = anim["per_method"].get(m.key)
        if series:
            ax.semilogy(anim["frames"], series["relmse"], "o-", color=m.color, label=f"{m.label} ({series['spp']} spp)")
    ax.axvline(anim["light_off_frame"], color="k", ls=":", lw=1)
    ax.set_xlabel("frame (dotted: the red lamp switches off)")
    ax.set_ylabel("relMSE")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def efficiency_bars(ax, labels, gains: dict, title: str, rotation: int = 40) -> None:
    """Grouped bars of efficiency ratios (``gains``: series name -> one value per label) on a log axis with the
    1x line: the chart of the method/integrator benchmarks."""
    x = np.arange(len(labels))
    width = 0.8 / max(1, len(gains))
    for i, (name, values) in enumerate(gains.items()):
        ax.bar(x + (i - (len(gains) - 1) / 2) * width, values, width, label=name)
    ax.set_yscale("log")
    ax.axhline(1.0, color="k", lw=0.6)
    ax.set_xticks(x, labels, rotation=rotation, ha="right", fontsize=8)
    ax.set_title(title)


def save_bar_figure(fig, axes, ylabel: str, title: str, path: str) -> None:
    """Label, title and save a row of :func:`efficiency_bars` axes."""
    axes[0].set_ylabel(ylabel)
    axes[0].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
