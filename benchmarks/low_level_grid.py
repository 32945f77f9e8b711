"""The low-level planner grid: {sto, trajopt, rrt} x {hlp, line}, from experiment runs' results.

    python -m hlp_drake.experiments gen1 --low-level sto trajopt rrt --out runs/gen1
    python benchmarks/low_level_grid.py runs/gen1 [runs/gen2-9 ...] [--out DIR]

Reads each run folder's ``results.csv`` and gives per condition (generator, object count, robot),
low-level planner and initialiser: success with its 95 % Wilson interval, the planning time (init +
low-level planning, s) mean and median (and the medians of each part), the low-level planner's iterations and rollouts (mean,
median), the false accepts (the planner accepted, the world failed), the fallbacks (a kinematic
planner that allowed contact with every object) and the grasps held after a reach success.
Writes ``DIR/low_level_grid.json``, ``DIR/low_level_grid.csv`` and ``DIR/low_level_grid.png``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pandas as pd

from hlp_drake.commands.parsing import run_cli
from hlp_drake.experiments.results import read_results
from hlp_drake.experiments.summary import wilson_interval
from hlp_drake.files.atomic import check_folder, write_text_atomic
from hlp_drake.files.plotting import new_figure, save_png

OUTPUTS = ("low_level_grid.json", "low_level_grid.csv", "low_level_grid.png")
PLANNERS = ("sto", "trajopt", "rrt")


def grid(rows: pd.DataFrame) -> pd.DataFrame:
    """One line per (condition, low-level planner, initialiser) of ``rows``."""
    rows = rows.assign(condition=rows.generator + "-" + rows.objects.astype(str) + " " + rows.robot)
    lines = []
    for (condition, low_level, initial), got in rows.groupby(["condition", "low_level", "initial"]):
        n, wins = len(got), int(got.success.sum())
        low, high = wilson_interval(wins, n)
        held = got.grasp_held[got.success]
        lines.append(
            {
                "condition": condition,
                "low_level": low_level,
                "initial": initial,
                "scenes": n,
                "success_pct": 100.0 * wins / n,
                "success_low_pct": low,
                "success_high_pct": high,
                "time_mean_s": got.total_s.mean(),
                "time_median_s": got.total_s.median(),
                "init_median_s": got.init_s.median(),
                "low_level_median_s": got.optimise_s.median(),
                "iterations_mean": got.iterations.mean(),
                "iterations_median": got.iterations.median(),
                "rollouts_mean": got.rollouts.mean(),
                "model_accepted": int(got.model_success.sum()),
                "false_accepts": int(got.false_accept.sum()),
                "fallbacks": int(got.fallback.sum()),
                "grasp_held": None if held.isna().any() else int(held.astype(bool).sum()),
                "reach_successes": wins,
            }
        )
    order = {name: i for i, name in enumerate(PLANNERS)}
    table = pd.DataFrame(lines)
    return table.sort_values(
        ["condition", "low_level", "initial"], key=lambda c: c.map(order) if c.name == "low_level" else c
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path, help="experiment run folders")
    parser.add_argument("--out", type=Path, default=Path("benchmark-results"))
    args = parser.parse_args(argv)
    check_folder(args.out, *OUTPUTS).mkdir(exist_ok=True)
    rows = pd.DataFrame([row for run in args.runs for row in read_results(run / "results.csv")])
    table = grid(rows)
    records = [{k: None if pd.isna(v) else v for k, v in r.items()} for r in table.to_dict(orient="records")]
    write_text_atomic(args.out / OUTPUTS[0], json.dumps(records, indent=1))
    write_text_atomic(args.out / OUTPUTS[1], table.to_csv(index=False, float_format="%.4f"))
    conditions = list(dict.fromkeys(table.condition))
    figure, _ = new_figure(4.0 * len(conditions), 3.6)
    figure.clf()
    for k, condition in enumerate(conditions):
        ax = figure.add_subplot(1, len(conditions), k + 1)
        part = table[table.condition == condition]
        for j, initial in enumerate(("hlp", "line")):
            got = part[part.initial == initial].set_index("low_level").reindex(PLANNERS)
            x = np.arange(len(PLANNERS)) + (j - 0.5) * 0.38
            error = [got.success_pct - got.success_low_pct, got.success_high_pct - got.success_pct]
            ax.bar(x, got.success_pct, 0.36, yerr=error, capsize=3, label=initial)
        ax.set_xticks(np.arange(len(PLANNERS)), PLANNERS)
        ax.set_ylim(0, 118)
        ax.set_title(condition)
        if k == 0:
            ax.set_ylabel("success in the reference world, %")
        ax.legend(loc="upper right", fontsize=8, ncols=2)
    save_png(figure, args.out / OUTPUTS[2])
    print(table.to_string(index=False, float_format=lambda v: f"{v:.3g}"))
    print(f"wrote {', '.join(str(args.out / name) for name in OUTPUTS)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(run_cli(main))  # bad paths: one line, exit 2
