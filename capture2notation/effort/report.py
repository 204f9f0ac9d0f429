"""Writing ``effort.json`` and the Effort plots (atomically).

Plots (matplotlib ``Figure`` objects, no pyplot and no display needed):

* ``effort_progress.png`` — each movement's observed progress s(τ) with the
  posterior median curve and its 90 % band;
* ``effort_pooled.png`` — corner-style plot of the pooled (b, x0) posterior
  of the phrase and of each body part, with the emotion presets marked.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from ..atomic import atomic_path, write_text
from ..notation.effort import PRESETS, progress
from .estimate import EffortResult

__all__ = ["EFFORT_JSON", "POOLED_PNG", "PROGRESS_PNG", "plot_pooled", "plot_progress", "write_effort"]

EFFORT_JSON = "effort.json"
PROGRESS_PNG = "effort_progress.png"
POOLED_PNG = "effort_pooled.png"
#: Most movements drawn in the progress figure (the JSON has them all).
MAX_PANELS = 30


def _figure(**kw):
    """A matplotlib Figure with the Agg canvas — no pyplot, so no global figure state to leak."""
    from matplotlib.figure import Figure

    return Figure(**kw)


def write_effort(result: EffortResult, outdir, plots: bool = True, rng=0) -> dict:
    """Write ``effort.json`` (and the plots) into `outdir`.

    Parameters
    ----------
    result : EffortResult
    outdir : str or Path
        Created if missing.
    plots : bool
        Also draw the two PNG figures.
    rng : numpy.random.Generator or int
        Picks the posterior draws shown in the bands.

    Returns
    -------
    dict
        Paths written, by kind (``json``, ``progress``, ``pooled``).
    """
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    paths = {"json": write_text(outdir / EFFORT_JSON, json.dumps(result.to_dict(), indent=2) + "\n")}
    if plots:
        paths["progress"] = plot_progress(result, outdir / PROGRESS_PNG, rng=rng)
        paths["pooled"] = plot_pooled(result, outdir / POOLED_PNG)
    return paths


def _band(samples: np.ndarray, grid: np.ndarray, rng, n: int = 200) -> np.ndarray:
    """5 %, 50 %, 95 % of progress curves over `n` posterior draws, (3, G)."""
    rng = np.random.default_rng(rng)
    idx = rng.choice(samples.shape[0], size=min(n, samples.shape[0]), replace=False)
    curves = progress(grid[None, :], samples[idx, 0, None], samples[idx, 1, None])
    return np.percentile(curves, [5, 50, 95], axis=0)


def plot_progress(result: EffortResult, path, rng=0) -> Path:
    """Observed progress of each movement with its posterior band; returns `path`."""
    from matplotlib.ticker import FixedLocator

    rng = np.random.default_rng(rng)
    moves = result.movements[:MAX_PANELS]
    n = max(len(moves), 1)
    cols = min(n, 5)
    rows = math.ceil(n / cols)
    fig = _figure(figsize=(2.6 * cols, 2.3 * rows))
    axes = fig.subplots(rows, cols, squeeze=False, sharex=True, sharey=True)
    grid = np.linspace(0.0, 1.0, 101)
    # fixed ticks: the automatic locators re-run on every panel, which
    # dominated the drawing time of a phrase's many small panels
    axes.flat[0].xaxis.set_major_locator(FixedLocator([0.0, 0.5, 1.0]))
    axes.flat[0].yaxis.set_major_locator(FixedLocator([0.0, 0.5, 1.0]))
    for ax, m in zip(axes.flat, moves):
        lo, med, hi = _band(m.posterior.samples, grid, rng)
        ax.fill_between(grid, lo, hi, color="tab:blue", alpha=0.3, lw=0, label="90 % band")
        ax.plot(grid, med, color="tab:blue", lw=1.2, label="posterior median")
        ax.plot(m.curve.tau, m.curve.s, ".", color="k", ms=3, label="observed")
        b = m.posterior.summary(0)["median"]
        x0 = m.posterior.summary(1)["median"]
        flag = "" if m.posterior.converged else " (not converged)"
        ax.set_title(f"{m.part} @ {m.start:g}\nb={b:.2f} x0={x0:.2f}{flag}", fontsize=7)
        ax.tick_params(labelsize=6)
    for ax in list(axes.flat)[len(moves) :]:
        ax.axis("off")
    if not moves:
        axes.flat[0].text(0.5, 0.5, "no movement measured", ha="center", va="center")
    else:
        axes.flat[0].legend(fontsize=5, loc="upper left")
    extra = f" (first {MAX_PANELS} of {len(result.movements)})" if len(result.movements) > MAX_PANELS else ""
    fig.suptitle(f"Progress s(τ) per movement{extra}", fontsize=9)
    fig.supxlabel("normalised time τ", fontsize=8)
    fig.supylabel("progress s", fontsize=8)
    # fixed margins instead of tight_layout (which measures every tick label)
    fig.subplots_adjust(
        left=0.35 / (2.6 * cols) + 0.04,
        right=0.98,
        bottom=0.45 / (2.3 * rows) + 0.03,
        top=1.0 - 0.75 / (2.3 * rows),
        wspace=0.12,
        hspace=0.55,
    )
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    return Path(path)


def plot_pooled(result: EffortResult, path) -> Path:
    """Corner-style plot of the pooled (b, x0) posteriors; returns `path`."""
    from matplotlib import rcParams

    fig = _figure(figsize=(6.0, 5.5))
    axes = fig.subplots(2, 2)
    groups = ([("phrase", result.pooled)] if result.pooled is not None else []) + sorted(result.parts.items())
    colours = rcParams["axes.prop_cycle"].by_key()["color"]
    for k, (label, pooled) in enumerate(groups):
        smp = pooled.posterior.samples
        c = colours[k % len(colours)]
        kw = {"color": c, "histtype": "step", "density": True, "bins": 40}
        axes[0, 0].hist(smp[:, 0], label=f"{label} (n={pooled.n_movements})", **kw)
        axes[1, 1].hist(smp[:, 1], **kw)
        axes[1, 0].plot(
            smp[:: max(1, smp.shape[0] // 1500), 0],
            smp[:: max(1, smp.shape[0] // 1500), 1],
            ".",
            ms=1,
            alpha=0.3,
            color=c,
        )
    for name, preset in PRESETS.items():
        axes[1, 0].plot(preset.effort.time, preset.effort.weight, "k+", ms=8)
        axes[1, 0].annotate(
            name, (preset.effort.time, preset.effort.weight), fontsize=7, xytext=(3, 3), textcoords="offset points"
        )
    axes[0, 0].set_xlabel("time b")
    axes[1, 1].set_xlabel("weight x0")
    axes[1, 0].set_xlabel("time b")
    axes[1, 0].set_ylabel("weight x0")
    axes[0, 1].axis("off")
    lines = [f"tempo {result.tempo:g} bpm"]
    if result.emotion:
        lines += [f"{k}: {v:.2f}" for k, v in result.emotion.items()]
    axes[0, 1].text(0.05, 0.95, "\n".join(lines), va="top", fontsize=9, transform=axes[0, 1].transAxes)
    if groups:
        axes[0, 0].legend(fontsize=6)
    fig.suptitle("Pooled Effort posterior", fontsize=10)
    fig.subplots_adjust(left=0.11, right=0.97, bottom=0.09, top=0.92, wspace=0.3, hspace=0.35)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    return Path(path)
