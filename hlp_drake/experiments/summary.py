"""Tables II and III: success rate and mean planning times per condition and planner, beside the paper's.

``summarise`` turns the rows of ``results.csv`` into a JSON-ready dict; ``summary_markdown`` prints it
in the paper's format. A condition is Generalization I (one group) or one object count of
Generalization II.
"""

from __future__ import annotations

import json
import math
from collections import defaultdict
from collections.abc import Iterable
from dataclasses import asdict, dataclass
from pathlib import Path
from statistics import fmean
from typing import Any

from hlp_drake.config.what_ran import WhatRan
from hlp_drake.experiments.runner import PLANNERS, Row
from hlp_drake.files.atomic import write_text_atomic

PLANNER_LABELS = {"hlp": "HLP", "sto": "STO (straight line)"}
TIMES = ("init_s", "optimise_s", "total_s")
TIME_LABELS = {"init_s": "init", "optimise_s": "optimisation", "total_s": "total"}
TABLES = {"gen1": "Table II: Generalization I", "gen2": "Table III: Generalization II"}


@dataclass(frozen=True)
class PaperFigures:
    """One planner's figures in the paper (None: not reported, or not in our notes)."""

    success_pct: float | None = None
    init_s: float | None = None
    optimise_s: float | None = None
    total_s: float | None = None


# Paper Table II (Gen I): success and total time; the init times are total - optimisation.
# Table III (Gen II): success only; its times are not in our notes.
PAPER: dict[tuple[str, int | None], dict[str, PaperFigures]] = {
    ("gen1", None): {
        "hlp": PaperFigures(94.0, round(1.56 - 0.97, 2), 0.97, 1.56),
        "sto": PaperFigures(84.0, round(17.88 - 17.84, 2), 17.84, 17.88),
    },
    ("gen2", 5): {"hlp": PaperFigures(93.0), "sto": PaperFigures(96.0)},
    ("gen2", 7): {"hlp": PaperFigures(93.0), "sto": PaperFigures(96.0)},
    ("gen2", 9): {"hlp": PaperFigures(95.0), "sto": PaperFigures(98.0)},
}
COMMON_NOTES = [
    (
        "Times are planning times per scene in seconds, means over all scenes of the condition (successes "
        "and failures): init = high-level plan + keypoint IK (plan_s + ik_s), optimisation = the stochastic "
        "trajectory optimiser, total = init + optimisation. The simulated execution (execute_s in "
        "results.csv) is excluded. Verification = the optimiser's checks of a passing rollout on the "
        "execution model (verify_s, part of optimisation); the ratio without it compares the search alone."
    ),
    (
        "Success % is followed by its 95 % Wilson interval; success = the target in the gripper's pre-grasp "
        "region at the end of the executed motion and no object fallen off the table."
    ),
    (
        "A run that crashed (an exception in plan_and_execute) counts as a failure; its times are left out "
        "of the means."
    ),
]
NOTES = {
    "gen1": [
        *COMMON_NOTES,
        (
            "The paper's init times are derived as total - optimisation "
            "(HLP 1.56 - 0.97 s, STO 17.88 - 17.84 s)."
        ),
    ],
    "gen2": [
        *COMMON_NOTES,
        (
            "Table III's times are not in our notes: the paper's time columns show n/a "
            "(null in summary.json) rather than invented numbers."
        ),
    ],
}


def paper_figures(kind: str, objects: int, planner: str) -> PaperFigures:
    table = PAPER.get((kind, None if kind == "gen1" else objects), {})
    return table.get(planner, PaperFigures())


def condition_label(kind: str, objects: int) -> str:
    return f"Gen I ({objects} objects)" if kind == "gen1" else f"{objects} objects"


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
    """n, successes, success % (and interval), crashes and mean times of one planner in one condition."""
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
    stats["passed_then_failed"] = sum(bool(row.get("passed_then_failed")) for row in rows)
    stats["paper"] = asdict(paper)
    return stats


def summarise(
    kind: str, rows: Iterable[Row], measured_on: str | None = None, ran: WhatRan | None = None
) -> dict[str, Any]:
    """Per condition (object count) and planner: the figures of Table II (gen1) or III (gen2); what
    the run ran (``ran``: robot, planners, execution, model error, perception, scenario file)."""
    groups: dict[int, dict[str, list[Row]]] = defaultdict(lambda: defaultdict(list))
    for row in rows:
        groups[row["objects"]][row["planner"]].append(row)
    conditions = []
    for objects in sorted(groups):
        by_planner = groups[objects]
        planners = {
            p: planner_stats(by_planner[p], paper_figures(kind, objects, p))
            for p in PLANNERS
            if by_planner[p]
        }
        hlp, sto = planners.get("hlp", {}), planners.get("sto", {})
        conditions.append(
            {
                "condition": condition_label(kind, objects),
                "objects": objects,
                "planners": planners,
                "hlp_to_sto_total": _ratio(hlp.get("total_s"), sto.get("total_s")),
                "hlp_to_sto_total_without_verification": _ratio(
                    _less(hlp.get("total_s"), hlp.get("verify_s")),
                    _less(sto.get("total_s"), sto.get("verify_s")),
                ),
                "paper_hlp_to_sto_total": _ratio(
                    paper_figures(kind, objects, "hlp").total_s, paper_figures(kind, objects, "sto").total_s
                ),
            }
        )
    return {
        "kind": kind,
        "table": TABLES[kind],
        **({} if ran is None else ran.to_dict()),
        "measured_on": measured_on,
        "conditions": conditions,
        "notes": NOTES[kind],
    }


def _number(value: float | None, digits: int = 2) -> str:
    return "n/a" if value is None else f"{value:.{digits}f}"


def _paper_number(value: float | None) -> str:
    return "n/a" if value is None else f"{value:g}"


def _table_rows(condition: dict[str, Any]) -> list[str]:
    lines = []
    for planner, stats in condition["planners"].items():
        paper = stats["paper"]
        low, high = stats["success_ci95"]
        cells = [
            condition["condition"],
            PLANNER_LABELS[planner],
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
    lines += [
        "",
        "| condition | ratio HLP / STO of the mean total times | the ratio without verification | the paper's ratio |",
        "|---|---:|---:|---:|",
    ]
    for condition in summary["conditions"]:
        lines.append(
            f"| {condition['condition']} | {_number(condition['hlp_to_sto_total'], 3)} | "
            f"{_number(condition['hlp_to_sto_total_without_verification'], 3)} | "
            f"{_number(condition['paper_hlp_to_sto_total'], 3)} |"
        )
    lines += [
        "",
        "| condition | planner | rollouts (mean) | verification s (mean) | rollout passed, execution failed |",
        "|---|---|---:|---:|---:|",
    ]
    for condition in summary["conditions"]:
        for planner, stats in condition["planners"].items():
            lines.append(
                f"| {condition['condition']} | {PLANNER_LABELS[planner]} | {_number(stats['rollouts_mean'], 1)} | "
                f"{_number(stats['verify_s'])} | {stats['passed_then_failed']} of {stats['n']} |"
            )
    lines += ["", "Notes:", ""] + [f"- {note}" for note in summary["notes"]]
    return "\n".join(lines) + "\n"


def write_summary(directory: Path, summary: dict[str, Any]) -> list[Path]:
    """Write ``summary.json`` and ``summary.md`` into ``directory``; return their paths."""
    paths = [directory / "summary.json", directory / "summary.md"]
    write_text_atomic(paths[0], json.dumps(summary, indent=2) + "\n")
    write_text_atomic(paths[1], summary_markdown(summary))
    return paths
