"""Figures of posefilter runs (matplotlib, Agg backend, PNG files).

Every function writes one PNG and returns its path. Data come from the bindings: results of
:meth:`posefilter.Estimator.estimate`, priors, synthetic scenes, and the JSON written by
``posefilter eval --json``.

* :func:`overlay_grid`       estimated (green) vs ground-truth (blue) poses drawn over shaded depth;
* :func:`weight_history`     best-particle weight per iteration;
* :func:`iteration_times`    time per iteration (thesis Fig. 7.35);
* :func:`prior_heatmap`      a prior's class heatmap, its CDF over cells and the cells the
                             initialisation draws (thesis Fig. 7.10);
* :func:`recall_curve`       recall vs acceptance threshold (fraction of the diameter).
"""

from __future__ import annotations

import json
import math
import os
from typing import Iterable, Mapping, Sequence

import matplotlib

matplotlib.use("Agg")  # files only; no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from . import _posefilter as _pf  # noqa: E402

EST_COLOR = (40, 220, 60)   # RGB of estimated poses (as `posefilter estimate --overlay`)
GT_COLOR = (60, 120, 255)   # RGB of ground-truth poses (as `posefilter demo`)


def _save(fig, path) -> str:
    path = os.fspath(path)
    parent = os.path.dirname(path)
    if parent:
        os.makedirs(parent, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def _results(results) -> list:
    """A Result, a BatchResult or an iterable of Results → list of Results."""
    if isinstance(results, _pf.Result):
        return [results]
    return list(results)


def overlay_grid(panels: Sequence[Mapping], path, cols: int = 3) -> str:
    """Grid of overlays, one panel per mapping with keys:

    ``depth`` (H x W metres), ``camera``, ``mesh``, ``estimate`` (4x4 T_cam_obj or None),
    ``gt`` (4x4 or None), optional ``title``. Each panel is the shaded depth with the mesh drawn
    at the ground truth (blue) and the estimate (green) by the library's overlay renderer.
    """
    if not panels:
        raise ValueError("overlay_grid: no panels")
    cols = max(1, min(cols, len(panels)))
    rows = math.ceil(len(panels) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4 * cols, 3.3 * rows), squeeze=False)
    for ax in axes.ravel():
        ax.axis("off")
    for ax, p in zip(axes.ravel(), panels):
        img = _pf.shade_depth(p["depth"])
        if p.get("gt") is not None:
            img = _pf.draw_pose_overlay(img, p["mesh"], p["gt"], p["camera"], GT_COLOR)
        if p.get("estimate") is not None:
            img = _pf.draw_pose_overlay(img, p["mesh"], p["estimate"], p["camera"], EST_COLOR)
        ax.imshow(img)
        ax.set_title(p.get("title", ""), fontsize=9)
    fig.suptitle("green: estimate, blue: ground truth", fontsize=10)
    fig.tight_layout()
    return _save(fig, path)


def weight_history(results, path, labels: Sequence[str] | None = None) -> str:
    """Best-particle weight (eq. 7.4) after each iteration, one line per result.

    Iterations of all restarts are concatenated (a restart shows as a drop to a fresh run)."""
    res = _results(results)
    fig, ax = plt.subplots(figsize=(6, 4))
    for i, r in enumerate(res):
        h = r.best_weight_history
        label = labels[i] if labels else f"{r.obj} (final {r.weight:.3f})"
        ax.plot(np.arange(1, len(h) + 1), h, marker=".", label=label)
    ax.set_xlabel("iteration (all restarts)")
    ax.set_ylabel("best weight")
    ax.set_ylim(0, 1)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("best-particle weight per iteration")
    fig.tight_layout()
    return _save(fig, path)


def iteration_times(results, path, labels: Sequence[str] | None = None) -> str:
    """Wall time of each iteration in milliseconds (cf. thesis Fig. 7.35), one line per result."""
    res = _results(results)
    fig, ax = plt.subplots(figsize=(6, 4))
    for i, r in enumerate(res):
        t = r.iteration_ms
        label = labels[i] if labels else f"{r.obj} (mean {np.mean(t):.1f} ms)" if len(t) else r.obj
        ax.plot(np.arange(1, len(t) + 1), t, marker=".", label=label)
    ax.set_xlabel("iteration (all restarts)")
    ax.set_ylabel("time per iteration [ms]")
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("iteration time")
    fig.tight_layout()
    return _save(fig, path)


def prior_heatmap(prior, cls, path, n_samples: int = 510, seed: int = 1, depth=None, camera=None,
                  image=None) -> str:
    """Thesis Fig. 7.10 for one class: per pyramid level the probability heatmap with the
    cells drawn by the initialisation's importance sampling marked, and the CDF over all cells
    (eq. 7.3). The draws are the library's (``sample_cells``: the filter's CDF sampler and
    threshold tracker, ``n_samples`` draws with ``seed``); with ``depth`` and ``camera``, cells
    without a heuristic volume get no mass, as in the filter. ``image`` (H x W x 3 uint8, e.g.
    ``shade_depth(depth)``) is shown first when given."""
    c = prior.class_index(cls) if isinstance(cls, str) else int(cls)
    name = prior.classes[c] if 0 <= c < len(prior.classes) else str(cls)
    draw = _pf.sample_cells(prior, c, n_samples, seed=seed, depth=depth, camera=camera)
    layout = prior.layout
    levels = layout.levels
    counts = np.bincount(draw["cells"], minlength=layout.cell_count())
    ncols = len(levels) + 1 + (image is not None)
    fig, axes = plt.subplots(1, ncols, figsize=(4.2 * ncols, 3.6), squeeze=False)
    axes = axes[0]
    k = 0
    if image is not None:
        axes[0].imshow(image)
        axes[0].set_title("scene")
        axes[0].axis("off")
        k = 1
    extent = (-0.5, layout.image_width - 0.5, layout.image_height - 0.5, -0.5)
    for level, (rows, cols, _, _) in enumerate(levels):
        ax = axes[k + level]
        grid = prior.level_grid(c, level)
        im = ax.imshow(grid, cmap="viridis", extent=extent, interpolation="nearest")
        fig.colorbar(im, ax=ax, fraction=0.035)
        off = layout.level_offset(level)
        lvl_counts = counts[off:off + rows * cols].reshape(rows, cols)
        r, q = np.nonzero(lvl_counts)
        sx, sy = layout.image_width / cols, layout.image_height / rows
        ax.scatter((q + 0.5) * sx - 0.5, (r + 0.5) * sy - 0.5, s=4 + 4 * np.sqrt(lvl_counts[r, q]),
                   facecolors="none", edgecolors="red", linewidths=0.8)
        ax.set_title(f"level {level} ({rows}x{cols}): {int(lvl_counts.sum())} draws", fontsize=9)
        ax.axis("off")
    ax = axes[-1]
    cdf = draw["cdf"]
    ax.plot(np.arange(len(cdf)), cdf, lw=1)
    for level in range(1, len(levels)):
        ax.axvline(layout.level_offset(level), color="grey", lw=0.6, ls="--")
    ax.set_xlabel("cell")
    ax.set_ylabel("CDF (eq. 7.3)")
    ax.set_ylim(0, 1.02)
    ax.set_title(f"CDF; tracker reads {draw['reads']} vs {draw['reads_linear']} linear", fontsize=9)
    ax.grid(alpha=0.3)
    fig.suptitle(f"prior of '{name}' and the cells drawn for {n_samples} particles", fontsize=10)
    fig.tight_layout()
    return _save(fig, path)


def load_eval_json(path) -> dict:
    """Per-object errors of a ``posefilter eval --json`` file as arrays (metres; NaN = missing):
    {"obj", "add", "adds", "diameter"}. Reads both kinds of file: single-scene (``--gt``; one
    entry per object under "objects") and dataset (``--dataset``; one entry per ground-truth
    instance under "instances", its diameter from the "objects" table by obj_id)."""
    path = os.fspath(path)
    with open(path) as f:
        j = json.load(f)
    if "instances" in j:  # eval --dataset
        diam = {o["obj_id"]: o.get("diameter_mm") for o in j.get("objects", [])}
        objs = []
        for t in j["instances"]:
            if t.get("obj_id") not in diam:
                raise ValueError(f"{path}: instance of obj_id {t.get('obj_id')} has no entry in \"objects\"")
            objs.append({"obj": str(t["obj_id"]), "add_mm": t.get("add_mm"), "adds_mm": t.get("adds_mm"),
                         "diameter_mm": diam[t["obj_id"]]})
    elif "objects" in j:
        objs = j["objects"]
    else:
        raise ValueError(f"{path}: not a posefilter eval --json file (no \"objects\" or \"instances\")")

    def col(key):
        return np.array([np.nan if o.get(key) is None else o[key] * 1e-3 for o in objs], dtype=float)

    return {"obj": [o["obj"] for o in objs], "add": col("add_mm"), "adds": col("adds_mm"),
            "diameter": col("diameter_mm")}


def errors_table(errors: Iterable) -> dict:
    """PoseErrors (None = missing) → the arrays of :func:`load_eval_json` (obj names empty)."""
    errs = list(errors)
    nan = float("nan")
    return {"obj": [""] * len(errs),
            "add": np.array([e.add if e is not None else nan for e in errs]),
            "adds": np.array([e.adds if e is not None else nan for e in errs]),
            "diameter": np.array([e.diameter if e is not None else nan for e in errs])}


def recall_at(errors: np.ndarray, diameters: np.ndarray, thresholds: np.ndarray) -> np.ndarray:
    """Fraction of objects with error < threshold·diameter, per threshold (missing = failure)."""
    ok = np.isfinite(errors) & np.isfinite(diameters)
    rel = np.where(ok, errors / np.where(ok, diameters, 1.0), np.inf)
    return np.array([(rel < t).mean() if len(rel) else 0.0 for t in thresholds])


def _is_single_evaluation(ev) -> bool:
    if isinstance(ev, (str, os.PathLike, dict)):
        return True
    return isinstance(ev, (list, tuple)) and (not ev or ev[0] is None or isinstance(ev[0], _pf.PoseErrors))


def recall_curve(evaluations, path, labels: Sequence[str] | None = None,
                 thresholds: np.ndarray | None = None) -> str:
    """Recall vs acceptance threshold (fraction of the diameter; the reported recall uses 0.1,
    docs/DATASETS.md) for ADD and ADD-S. ``evaluations``: one or more of: a ``posefilter eval
    --json`` path, a dict from :func:`load_eval_json`, or a list of PoseErrors (None = missing)."""
    if _is_single_evaluation(evaluations):
        evaluations = [evaluations]
    if thresholds is None:
        thresholds = np.linspace(0, 0.5, 101)
    fig, ax = plt.subplots(figsize=(6, 4))
    for i, ev in enumerate(evaluations):
        if isinstance(ev, (str, os.PathLike)):
            table = load_eval_json(ev)
            name = os.path.basename(os.fspath(ev))
        elif isinstance(ev, dict):
            table, name = ev, f"run {i}"
        else:
            table, name = errors_table(ev), f"run {i}"
        if labels:
            name = labels[i]
        n = len(table["adds"])
        for key, style in (("adds", "-"), ("add", "--")):
            r = recall_at(table[key], table["diameter"], thresholds)
            ax.plot(thresholds, r, style, label=f"{name}: {key.upper().replace('ADDS', 'ADD-S')} (n={n})")
    ax.axvline(0.1, color="grey", lw=0.8, ls=":")
    ax.set_xlabel("threshold [fraction of the diameter]")
    ax.set_ylabel("recall")
    ax.set_ylim(0, 1.02)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("recall vs threshold")
    fig.tight_layout()
    return _save(fig, path)
