"""A study's summary: success rate and mean planning times per condition and series, beside the
paper's where the series is one of its planners.

``summarise`` turns the rows of ``results.csv`` into a JSON-ready dict; ``summary_markdown`` prints
it in the paper's format. A condition is one generator at one object count (Gen I: one group); a
series is one cell of the grid: its planner pair, and whatever else the grid varies (robot,
execution, perception, model error). Where two series differ only in the initialiser, the ratio of
their mean total times says what the human prior saves.
"""

from __future__ import annotations

import json
import math
from collections import defaultdict
from collections.abc import Iterable
from dataclasses import asdict
from pathlib import Path
from statistics import fmean
from typing import Any

from hlp_drake.config.what_ran import WhatRan
from hlp_drake.experiments.paper import PaperFigures, notes, paper_figures
from hlp_drake.experiments.runner import Row
from hlp_drake.experiments.study import Study
from hlp_drake.files.atomic import write_text_atomic
from hlp_drake.runtime.terminal import counted

PLANNER_LABELS = {"hlp": "HLP", "sto": "STO (straight line)"}
"""The paper's planners as the tables name them."""
TIMES = ("init_s", "optimise_s", "total_s")
TIME_LABELS = {"init_s": "init", "optimise_s": "optimisation", "total_s": "total"}
CELL = ("robot", "initial", "low_level", "execution", "perception", "model_error", "world")
"""The columns of a row's cell (a series)."""


def condition_label(generator: str, objects: int, generators: tuple[str, ...]) -> str:
    """A condition's name: the generator (one study of several) and the object count."""
    if len(generators) > 1:
        return f"{generator}, {counted(objects, 'object')}"
    return f"Gen I ({counted(objects, 'object')})" if generator == "gen1" else counted(objects, "object")


def wilson_interval(successes: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """The 95 % Wilson score interval of a success rate, in percent."""
    p = successes / n
    denominator = 1.0 + z * z / n
    centre = (p + z * z / (2 * n)) / denominator
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denominator
    return round(100 * max(0.0, centre - half), 2), round(100 * min(1.0, centre + half), 2)


def _mean(values: Iterable[float]) -> float | None:
    finite = [v for v in values if math.isfinite(v)]
    return round(fmean(finite), 4) if finite else None


def _ratio(numerator: float | None, denominator: float | None) -> float | None:
    if numerator is None or not denominator:
        return None
    return round(numerator / denominator, 4)


def _less(total: float | None, part: float | None) -> float | None:
    return None if total is None or part is None else total - part


def planner_stats(rows: list[Row], paper: PaperFigures) -> dict[str, Any]:
    """n, successes, success % (and interval), crashes and mean times of one series in one condition."""
    n = len(rows)
    successes = sum(row["success"] for row in rows)
    stats: dict[str, Any] = {
        "n": n,
        "successes": successes,
        "success_pct": round(100 * successes / n, 2),
        "success_ci95": wilson_interval(successes, n),
        "crashed": sum((row["failure_reason"] or "").startswith("crashed:") for row in rows),
    }
    stats.update({column: _mean(row[column] for row in rows) for column in (*TIMES, "verify_s", "execute_s")})
    stats["rollouts_mean"] = _mean(row.get("rollouts", 0) for row in rows)
    stats["model_accepts"] = sum(bool(row.get("model_success")) for row in rows)
    stats["false_accepts"] = sum(bool(row.get("false_accept")) for row in rows)
    stats["paper"] = asdict(paper)
    return stats


def series_label(cell: dict[str, Any], varying: tuple[str, ...]) -> str:
    """A series' name: its planner pair (the paper's names for its two), then the other axes the
    grid varies."""
    parts = [PLANNER_LABELS.get(cell["planner"], cell["planner"])]
    for axis in varying:
        value = cell[axis]
        if axis in ("initial", "low_level"):
            continue
        parts.append(f"model error {value}" if axis == "model_error" and value is not None else str(value))
    return ", ".join(parts)


def _ratios(series: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per pair of series that differ only in the initialiser (hlp and line): the ratio of their mean
    total times, with and without verification."""
    ratios = []
    others = [axis for axis in CELL if axis != "initial"]
    for human in (s for s in series if s["cell"]["initial"] == "hlp"):
        for line in series:
            same = all(line["cell"][a] == human["cell"][a] for a in others)
            if not same or line["cell"]["initial"] != "line":
                continue
            hlp, sto = human["stats"], line["stats"]
            ratios.append(
                {
                    "of": f"{human['label']} / {line['label']}",
                    "total": _ratio(hlp["total_s"], sto["total_s"]),
                    "total_without_verification": _ratio(
                        _less(hlp["total_s"], hlp["verify_s"]), _less(sto["total_s"], sto["verify_s"])
                    ),
                    "paper": _ratio(hlp["paper"]["total_s"], sto["paper"]["total_s"]),
                }
            )
    return ratios


def summarise(
    study: Study, rows: Iterable[Row], measured_on: str | None = None, ran: WhatRan | None = None
) -> dict[str, Any]:
    """Per condition and series: the figures of the study's table (Table II or III for the bundled
    ``gen1`` and ``gen2``); what the run ran (``ran``)."""
    rows = list(rows)
    varying = tuple(axis for axis in CELL if len({row[axis] for row in rows}) > 1)
    groups: dict[tuple, dict[tuple, list[Row]]] = defaultdict(lambda: defaultdict(list))
    for row in rows:
        cell = (row["planner"], *(row[axis] for axis in CELL))
        groups[(row["generator"], row["objects"])][cell].append(row)
    order = {g: i for i, g in enumerate(study.generators)}
    conditions = []
    for (generator, objects), cells in sorted(
        groups.items(), key=lambda item: (order.get(item[0][0], 99), item[0])
    ):
        series = []
        for key in sorted(cells, key=lambda k: tuple("" if v is None else str(v) for v in k)):
            cell = dict(zip(("planner", *CELL), key))
            stats = planner_stats(cells[key], paper_figures(generator, objects, cell))
            series.append({"label": series_label(cell, varying), "cell": cell, "stats": stats})
        conditions.append(
            {
                "condition": condition_label(generator, objects, study.generators),
                "generator": generator,
                "objects": objects,
                "series": series,
                "ratios": _ratios(series),
            }
        )
    return {
        "study": study.name,
        "table": study.heading,
        **({} if ran is None else ran.to_dict()),
        "measured_on": measured_on,
        "conditions": conditions,
        "notes": notes(study.generators),
    }


def _number(value: float | None, digits: int = 2) -> str:
    return "n/a" if value is None else f"{value:.{digits}f}"


def _paper_number(value: float | None) -> str:
    return "n/a" if value is None else f"{value:g}"


def _table_rows(condition: dict[str, Any]) -> list[str]:
    lines = []
    for series in condition["series"]:
        stats = series["stats"]
        paper = stats["paper"]
        low, high = stats["success_ci95"]
        cells = [
            condition["condition"],
            series["label"],
            str(stats["n"]),
            f"{stats['success_pct']:.1f} [{low:.0f}-{high:.0f}] ({_paper_number(paper['success_pct'])})",
        ]
        cells += [f"{_number(stats[column])} ({_paper_number(paper[column])})" for column in TIMES]
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def summary_markdown(summary: dict[str, Any]) -> str:
    """The summary as Markdown: the paper's table with the paper's values in parentheses, ratios, notes."""
    lines = [f"# {summary['table']}", ""]
    ran = WhatRan.from_dict(summary)
    if ran is not None:
        lines += [f"Ran: {ran.line()}.", ""]
    if summary["measured_on"]:
        lines += [f"Measured on {summary['measured_on']}.", ""]
    lines += [
        "Ours, with the paper's value in parentheses.",
        "",
        "| condition | planner | n | success % [95 % CI] (paper) | "
        + " | ".join(f"{TIME_LABELS[c]} s (paper)" for c in TIMES)
        + " |",
        "|---|---|---:|---:|" + "---:|" * len(TIMES),
    ]
    for condition in summary["conditions"]:
        lines += _table_rows(condition)
    ratios = [(c["condition"], ratio) for c in summary["conditions"] for ratio in c["ratios"]]
    if ratios:  # a study without both initialisers has none
        lines += [
            "",
            "| condition | mean total times | ratio | the ratio without verification | the paper's ratio |",
            "|---|---|---:|---:|---:|",
        ]
        lines += [
            f"| {condition} | {ratio['of']} | {_number(ratio['total'], 3)} | "
            f"{_number(ratio['total_without_verification'], 3)} | {_number(ratio['paper'], 3)} |"
            for condition, ratio in ratios
        ]
    lines += [
        "",
        "| condition | planner | world | rollouts (mean) | verification s (mean) | model accepted "
        + "| false accepts (model accepted, world failed) |",
        "|---|---|---|---:|---:|---:|---:|",
    ]
    for condition in summary["conditions"]:
        for series in condition["series"]:
            stats = series["stats"]
            lines.append(
                f"| {condition['condition']} | {series['label']} | {series['cell']['world']} | "
                f"{_number(stats['rollouts_mean'], 1)} | {_number(stats['verify_s'])} | "
                f"{stats['model_accepts']} of {stats['n']} | {stats['false_accepts']} of {stats['model_accepts']} |"
            )
    lines += ["", "Notes:", ""] + [f"- {note}" for note in summary["notes"]]
    return "\n".join(lines) + "\n"


def write_summary(directory: Path, summary: dict[str, Any]) -> list[Path]:
    """Write ``summary.json`` and ``summary.md`` into ``directory``; return their paths."""
    paths = [directory / "summary.json", directory / "summary.md"]
    write_text_atomic(paths[0], json.dumps(summary, indent=2) + "\n")
    write_text_atomic(paths[1], summary_markdown(summary))
    return paths


__all__ = ["PLANNER_LABELS", "TIMES", "TIME_LABELS", "summarise", "summary_markdown", "write_summary"]
