"""``success.png`` and ``times.png``: our success rates and mean planning times per condition and series
(a cell of the study's grid) as grouped bars, the paper's values as black markers where the paper (or
our notes of it) has them."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from hlp_drake.experiments.summary import TIME_LABELS, TIMES
from hlp_drake.files.plotting import plt, save_png

COLOURS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f")
"""The series' colours, in order (the first two: the HLP's and the straight line's)."""
GROUP_WIDTH = 0.72
"""The width of a condition's group of bars (the conditions are 1 apart)."""


def _label_bars(axes: plt.Axes, bars, values: list[float | None], label: Callable[[float], str]) -> None:
    """Write each value at its bar's half height (white), clear of the paper's diamond and the error
    bar near the top, or above a bar too short to hold it."""
    top = axes.get_ylim()[1]
    for bar, value in zip(bars, values):
        if value is None:
            continue
        inside = bar.get_height() > 0.12 * top
        axes.annotate(
            label(value),
            (bar.get_x() + bar.get_width() / 2, bar.get_height() / 2 if inside else bar.get_height()),
            xytext=(0, 0 if inside else 3),
            textcoords="offset points",
            ha="center",
            va="center" if inside else "bottom",
            fontsize=8,
            color="white" if inside else "black",
            fontweight="bold" if inside else "normal",
        )


def _grouped_bars(
    axes: plt.Axes,
    summary: dict[str, Any],
    field: str,
    label: Callable[[float], str],
    errors: Callable[[dict[str, Any]], tuple[float, float]] | None = None,
) -> None:
    """Bars of ``field`` per condition and series (with ``errors``' (low, high) if given); paper values
    as black diamonds."""
    conditions = summary["conditions"]
    centres = np.arange(len(conditions))
    labels = list(dict.fromkeys(s["label"] for c in conditions for s in c["series"]))
    width = GROUP_WIDTH / max(1, len(labels))
    labelled = []
    paper_shown = False
    for i, name in enumerate(labels):
        x = centres + (i - (len(labels) - 1) / 2) * width
        stats = [next((s["stats"] for s in c["series"] if s["label"] == name), None) for c in conditions]
        ours = [None if s is None else s[field] for s in stats]
        heights = np.array([np.nan if v is None else v for v in ours], float)
        yerr = None
        if errors is not None:
            bounds = np.array([errors(s) if s is not None else (np.nan, np.nan) for s in stats], float)
            yerr = np.clip(np.vstack([heights - bounds[:, 0], bounds[:, 1] - heights]), 0, None)
        bars = axes.bar(
            x,
            heights,
            width * 0.95,
            color=COLOURS[i % len(COLOURS)],
            label=name,
            yerr=yerr,
            error_kw={"ecolor": "0.25", "capsize": 3, "lw": 1},
        )
        labelled.append((bars, ours))
        paper = [None if s is None else s["paper"][field] for s in stats]
        shown = [(xi, v) for xi, v in zip(x, paper) if v is not None]
        if shown:
            axes.scatter(
                *zip(*shown),
                marker="D",
                s=40,
                color="black",
                edgecolor="white",
                linewidth=0.8,
                zorder=3,
                label=None if paper_shown else "paper",
            )
            paper_shown = True
    axes.set_xticks(centres, [c["condition"] for c in conditions])
    axes.set_xlim(-0.6, len(conditions) - 0.4)
    axes.set_ylim(0, axes.get_ylim()[1] * 1.08)
    axes.grid(axis="y", alpha=0.3)
    axes.set_axisbelow(True)
    for bars, values in labelled:
        _label_bars(axes, bars, values, label)


def plot_title(summary: dict[str, Any]) -> str:
    """The plots' title: the table, the robot (on another robot's tables), the scenes per condition."""
    scenes = max((s["stats"]["n"] for c in summary["conditions"] for s in c["series"]), default=0)
    robots = summary.get("robots") or [summary.get("robot")]
    ran = "" if robots == [None] else f", {' and '.join(robots)}"
    ran += f" on {summary['tables']}'s tables" if summary.get("tables") else ""
    return f"{summary['table']}{ran} ({scenes} scene{'s' if scenes != 1 else ''} per condition)"


def _legend_below(figure: plt.Figure, axes: plt.Axes) -> None:
    """One legend for the figure, centred below the panels (clear of bars and markers)."""
    handles, labels = axes.get_legend_handles_labels()
    figure.legend(
        handles,
        labels,
        loc="upper center",
        bbox_to_anchor=(0.5, 0.0),
        ncol=len(labels),
        fontsize=9,
        frameon=False,
    )


def plot_success(summary: dict[str, Any], path: Path) -> None:
    """Success % per condition and planner."""
    figure, axes = plt.subplots(figsize=(max(5.0, 2.2 * len(summary["conditions"]) + 2.0), 4.5))
    _grouped_bars(axes, summary, "success_pct", lambda v: f"{v:.0f}", errors=lambda s: s["success_ci95"])
    axes.set_ylim(0, 105)
    axes.set_ylabel("success rate (%), with 95 % interval")
    axes.set_title(plot_title(summary))
    figure.tight_layout()
    _legend_below(figure, axes)
    save_png(figure, path)


def plot_times(summary: dict[str, Any], path: Path) -> None:
    """Mean init, optimisation and total planning time per condition and planner, one panel each."""
    width = max(4.0, 1.6 * len(summary["conditions"]) + 1.5)
    figure, panels = plt.subplots(1, len(TIMES), figsize=(width * len(TIMES), 4.5))
    for axes, field in zip(panels, TIMES):
        _grouped_bars(axes, summary, field, lambda v: f"{v:.2f}")
        axes.set_title(f"mean {TIME_LABELS[field]} time")
        axes.set_ylabel("seconds per scene")
    figure.suptitle(f"{plot_title(summary)}: planning time (execution excluded)")
    figure.tight_layout()
    _legend_below(figure, panels[0])
    save_png(figure, path)


def write_plots(directory: Path, summary: dict[str, Any]) -> list[Path]:
    """Write ``success.png`` and ``times.png`` into ``directory``; return their paths."""
    paths = [directory / "success.png", directory / "times.png"]
    plot_success(summary, paths[0])
    plot_times(summary, paths[1])
    return paths
