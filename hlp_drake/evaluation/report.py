"""The evaluation's report: a table per protocol, the figures as JSON, every scored row as CSV, a plot."""

from __future__ import annotations

import csv
import io
import json
from argparse import Namespace
from collections.abc import Sequence

import numpy as np

from hlp_drake.evaluation.protocol import (
    CEILING,
    PAPER_TABLE_I,
    SETTINGS,
    SplitResult,
    planners_of,
    summarise,
)
from hlp_drake.files.atomic import write_text_atomic
from hlp_drake.files.plotting import new_figure, save_png
from hlp_drake.segmentation.demonstration import Demonstration

COLUMNS = (
    ("shlp", "sHLP"),
    ("shlp_plan", "sHLP plan"),
    ("shlp_decision", "I(D)"),
    ("shlp_element", "I(E)"),
    ("shlp_element_plan", "I(E) plan"),
    ("gap_accuracy", "Cg"),
    ("object_accuracy", "Co"),
)
NAMES = {"hlp": "planner", "nearest_gap": "nearest gap", "majority": "majority", CEILING: "ceiling"}


def table(label: str, summaries: dict[str, dict], paper: bool) -> str:
    """The planners' figures (mean +- std over splits) under ``label``, the paper's beside if asked."""
    lines = [label, f"  {'':<12}" + "".join(f"{name:>15}" for _, name in COLUMNS)]
    for planner, summary in summaries.items():
        lines.append(
            f"  {NAMES[planner]:<12}"
            + "".join(f"{summary[key]['mean']:>8.3f} +-{summary[key]['std']:.3f}" for key, _ in COLUMNS)
        )
    if paper:
        lines.append(
            f"  {'paper':<12}"
            + "".join(
                f"{PAPER_TABLE_I[key]:>15.2f}" if key in PAPER_TABLE_I else f"{'-':>15}" for key, _ in COLUMNS
            )
        )
    if CEILING in summaries:
        c = summaries[CEILING]["coverage"]
        found = f"{c['layout']} on a shared layout"
        if "threshold" in c:
            found += f", {c['matched']} matched within {c['threshold']:.3f}"
        same = summaries[CEILING]["same_rows"]
        lines.append(
            f"  ceiling: the training people's choices on {c['rows']} of the {c['rows_total']} rows "
            f"({found}); on those rows sHLP "
            + ", ".join(f"{NAMES[p]} {same[p]['shlp']['mean']:.3f}" for p in same)
            + f", ceiling {summaries[CEILING]['shlp']['mean']:.3f}"
        )
    if "row_ece" in summaries["hlp"]:
        h = summaries["hlp"]
        lines.append(
            f"  Cr on the held-out rows: calibration error {h['row_ece']['mean']:.3f}, Brier "
            f"{h['row_brier']['mean']:.3f}, within the demonstrations' range "
            f"{h['row_in_distribution']['mean']:.1%}"
        )
    t = summaries["hlp"]["planning_time_s"]
    lines.append(
        f"  planning time per scene: median {t['median'] * 1e3:.2f} ms, p95 {t['p95'] * 1e3:.2f} ms, "
        f"p99 {t['p99'] * 1e3:.2f} ms"
    )
    return "\n".join(lines)


def rows_csv(results: dict[str, list[SplitResult]]) -> str:
    """One row per split, planner, test trial and scored row."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(
        [
            "label",
            "split",
            "planner",
            "subject",
            "trial",
            "row",
            "human_decision",
            "human_element",
            "decision",
            "element",
        ]
    )
    for label, splits in results.items():
        for k, split in enumerate(splits, start=1):
            for planner in planners_of([split]):
                for outcome in split.planner_outcomes(planner):
                    subject, trial = outcome.key.split("/T")
                    for r in outcome.rows:
                        writer.writerow(
                            [
                                label,
                                k,
                                planner,
                                subject,
                                int(trial),
                                r.row,
                                r.human_decision,
                                r.human_element,
                                r.hlp_decision,
                                r.hlp_element,
                            ]
                        )
    return out.getvalue()


def _plot(path: str, summaries: dict[str, dict[str, dict]], title: str) -> None:
    """Grouped bars: per result, each planner's sHLP (plan) and I(D), with the std over splits (the
    ceiling's on its rows, zero where it has none, with the planner's on those rows marked)."""
    figure, axes = new_figure(max(8.0, 2.6 * len(summaries)), 4.6)
    labels = list(summaries)
    planners = [p for p in NAMES if any(p in summaries[label] for label in labels)]
    width = 0.8 / (2 * len(planners))
    nothing = {"mean": 0.0, "std": 0.0}
    for p, planner in enumerate(planners):
        for m, (metric, name) in enumerate((("shlp_plan", "sHLP"), ("shlp_decision", "I(D)"))):
            x = np.arange(len(labels)) + (2 * p + m - len(planners) + 0.5) * width
            means = [summaries[label].get(planner, {}).get(metric, nothing)["mean"] for label in labels]
            stds = [summaries[label].get(planner, {}).get(metric, nothing)["std"] for label in labels]
            axes.bar(
                x,
                means,
                width,
                yerr=stds,
                capsize=2,
                label=f"{NAMES[planner]}{' (its rows)' * (planner == CEILING)}: {name}",
                color=f"C{p}",
                alpha=1.0 if m == 0 else 0.55,
            )
            same = [summaries[label].get(CEILING, {}).get("same_rows", {}).get("hlp") for label in labels]
            if planner == CEILING:
                axes.scatter(
                    x,
                    [s[metric]["mean"] if s else np.nan for s in same],
                    marker="_",
                    s=500,
                    linewidths=3,
                    color="black",
                    zorder=3,
                    label="planner on the ceiling's rows" if m == 0 else None,
                )
    axes.set_xticks(np.arange(len(labels)), labels)
    axes.set_ylim(0.0, 1.3)
    axes.set_yticks(np.linspace(0.0, 1.0, 6))
    axes.set_ylabel("agreement with the held-out people")
    axes.grid(axis="y", alpha=0.3)
    axes.legend(fontsize=7, ncol=len(planners), loc="upper center", columnspacing=1.0)
    axes.set_title(title)
    save_png(figure, path)


def _plot_curve(path: str, summaries: dict[str, dict[str, dict]], title: str) -> None:
    figure, axes = new_figure(6.5, 4.5)
    sizes = [int(n) for n in summaries]
    for metric, name in (
        ("shlp", "sHLP"),
        ("shlp_decision", "I(D)"),
        ("gap_accuracy", "Cg"),
        ("object_accuracy", "Co"),
    ):
        axes.errorbar(
            sizes,
            [summaries[str(n)]["hlp"][metric]["mean"] for n in sizes],
            yerr=[summaries[str(n)]["hlp"][metric]["std"] for n in sizes],
            marker="o",
            capsize=3,
            label=name,
        )
    axes.set_xlabel("training subjects")
    axes.set_ylabel("score on the held-out subjects")
    axes.set_ylim(0.0, 1.0)
    axes.grid(alpha=0.3)
    axes.legend(fontsize=8)
    axes.set_title(title)
    save_png(figure, path)


def write_report(
    args: Namespace,
    results: dict[str, list[SplitResult]],
    demonstrations: Sequence[Demonstration],
    seconds: float,
) -> int:
    """Print the tables and write the JSON (and CSV, PNG) ``args`` asks for; return 0."""
    summaries = {
        label: {planner: summarise(splits, planner) for planner in planners_of(splits)}
        for label, splits in results.items()
    }
    protocol = "models" if args.models else args.protocol
    what = f"models {args.models}" if args.models else f"{args.preset} learners"
    print(
        f"{protocol} protocol, {args.mode} mode, {what}, {len(demonstrations)} demonstrations, {seconds:.0f} s"
    )
    for label, summary in summaries.items():
        heading = {"a": f"setting a: {SETTINGS['a']}", "b": f"setting b: {SETTINGS['b']}"}.get(label, label)
        count = len(results[label])
        if protocol == "num_subjects":
            heading = f"{label} training subjects"
        print(
            table(f"{heading} ({count} split{'s' * (count > 1)}, mean +- std)", summary, protocol == "80_20")
        )
    report = {
        "protocol": protocol,
        "mode": args.mode,
        "preset": None if args.models else args.preset,
        "models": args.models,
        "splits": args.splits,
        "folds": args.folds,
        "seed": args.seed,
        "demonstrations": len(demonstrations),
        "seconds": seconds,
        "paper": PAPER_TABLE_I,
        "settings": SETTINGS,
        "results": summaries,
        "splits_subjects": {
            label: [{"train": r.train, "test": r.test} for r in splits] for label, splits in results.items()
        },
    }
    write_text_atomic(args.json, json.dumps(report, indent=2) + "\n")
    if args.csv:
        write_text_atomic(args.csv, rows_csv(results))
    if args.png:
        title = f"{protocol} protocol ({args.mode} mode, {what})"
        (_plot_curve if protocol == "num_subjects" else _plot)(args.png, summaries, title)
    print(f"wrote {args.json}")
    return 0
