"""``python -m hlp_drake.evaluate``: the paper's cross-subject evaluation (Table I), side by side.

    python -m hlp_drake.evaluate [--dataset PATH] [--splits 5] [--seed 0] [--protocol 80_20|num_subjects]
        [--mode fixed|faithful] --json OUT [--predictions CSV] [--png CURVE.png]
"""

from __future__ import annotations

import csv
import io
import json
import os
import time
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from contextlib import nullcontext
from functools import partial

from tqdm import tqdm

from hlp_drake.atomic import write_text_atomic
from hlp_drake.cli import add_quiet, make_parser, run_cli
from hlp_drake.dataset.dataset import Dataset
from hlp_drake.evaluation import METRICS, PAPER_TABLE_I, evaluate_split, subject_splits, summarise
from hlp_drake.features import training_data
from hlp_drake.learners import PRESETS
from hlp_drake.plotting import new_figure, save_png
from hlp_drake.segmentation import DEFAULT_MODE, MODES, segment_dataset

TRAIN_SIZES = (3, 7, 11, 15, 19, 23)
LABELS = {"gap_accuracy": "Cg accuracy", "object_accuracy": "Co accuracy", "shlp": "sHLP",
          "shlp_decision": "I(D)", "shlp_element": "I(E) (raw classifier labels)",
          "shlp_element_plan": "I(E) (plan's element)"}


def table(summary: dict) -> str:
    lines = [f"{'metric':<30}{'ours (mean +- std)':>22}{'paper':>8}"]
    for metric in METRICS:
        paper = PAPER_TABLE_I.get(metric)
        value = summary[metric]
        lines.append(f"{LABELS[metric]:<30}{value['mean']:>13.3f} +- {value['std']:.3f}"
                     f"{(f'{paper:.2f}' if paper is not None else '-'):>8}")
    t = summary["planning_time_s"]
    lines.append(f"planning time per scene: median {t['median'] * 1e3:.2f} ms, 95th percentile {t['p95'] * 1e3:.2f} ms")
    return "\n".join(lines)


def predictions_csv(results) -> str:
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(["split", "subject", "trial", "row", "human_decision", "human_element", "hlp_decision",
                     "hlp_element"])
    for split, result in enumerate(results, start=1):
        for outcome in result.outcomes:
            subject, trial = outcome.key.split("/T")
            for r in outcome.rows:
                writer.writerow([split, subject, int(trial), r.row, r.human_decision, r.human_element,
                                 r.hlp_decision, r.hlp_element])
    return out.getvalue()


def main(argv: Sequence[str] | None = None) -> int:
    parser = make_parser("python -m hlp_drake.evaluate", __doc__)
    parser.add_argument("--dataset", help="the archive or the unpacked dataset/ folder (default: $HLP_DATASET)")
    parser.add_argument("--splits", type=int, default=5, help="random subject splits (default 5)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--protocol", choices=("80_20", "num_subjects"), default="80_20")
    parser.add_argument("--mode", choices=MODES, default=DEFAULT_MODE)
    parser.add_argument("--preset", choices=sorted(PRESETS), default="strong")
    parser.add_argument("--json", required=True, help="write the figures here")
    parser.add_argument("--predictions", help="CSV of every test trial's per-row decisions (80_20)")
    parser.add_argument("--png", help="learning curve (num_subjects protocol)")
    parser.add_argument("--workers", type=int, help="parallel splits (default: one per core)")
    add_quiet(parser)
    args = parser.parse_args(argv)
    if args.splits < 1:
        parser.error("--splits must be at least 1")
    started = time.perf_counter()
    dataset = Dataset(args.dataset, progress=not args.quiet)
    segmentation = segment_dataset(dataset, mode=args.mode, progress=not args.quiet)
    data = training_data(segmentation.demonstrations, mode=args.mode)
    subjects = sorted({d.subject for d in segmentation.demonstrations})
    settings = PRESETS[args.preset]
    sizes = [round(0.8 * len(subjects))] if args.protocol == "80_20" else [n for n in TRAIN_SIZES if n < len(subjects)]
    curve = {}
    jobs = [(n, split) for n in sizes for split in subject_splits(subjects, n_train=n, splits=args.splits, seed=args.seed)]
    results_by_size: dict[int, list] = {n: [] for n in sizes}
    workers = max(1, min(args.workers or os.cpu_count() or 1, len(jobs)))
    with ProcessPoolExecutor(workers) if workers > 1 else nullcontext() as pool:
        run = partial(evaluate_split, data, segmentation.demonstrations, settings=settings)
        futures = [(n, pool.submit(run, train, test) if pool else None, train, test) for n, (train, test) in jobs]
        for n, future, train, test in tqdm(futures, desc=f"{args.protocol} splits ({workers} workers)", unit="split",
                                           disable=args.quiet):
            results_by_size[n].append(future.result() if future else run(train, test))
    for n, results in results_by_size.items():
        curve[n] = summarise(results)
    elapsed = time.perf_counter() - started
    report = {
        "protocol": args.protocol, "mode": args.mode, "preset": args.preset, "splits": args.splits, "seed": args.seed,
        "demonstrations": len(segmentation.demonstrations), "seconds": elapsed, "paper": PAPER_TABLE_I,
    }
    if args.protocol == "80_20":
        summary = curve[sizes[0]]
        report.update(summary)
        report["splits_subjects"] = [{"train": r.train, "test": r.test} for r in results_by_size[sizes[0]]]
        print(f"cross-subject evaluation, {args.splits} random {sizes[0]}/{len(subjects) - sizes[0]} splits "
              f"(seed {args.seed}), {args.mode} mode, {args.preset} learners, {elapsed:.0f} s")
        print(table(summary))
        if args.predictions:
            write_text_atomic(args.predictions, predictions_csv(results_by_size[sizes[0]]))
    else:
        report["curve"] = {str(n): s for n, s in curve.items()}
        for n, s in curve.items():
            print(f"{n:>2} training subjects: sHLP {s['shlp']['mean']:.3f} +- {s['shlp']['std']:.3f}, "
                  f"Cg {s['gap_accuracy']['mean']:.3f}, Co {s['object_accuracy']['mean']:.3f}")
        if args.png:
            figure, axes = new_figure(6.5, 4.5)
            for metric in ("shlp", "shlp_decision", "gap_accuracy", "object_accuracy"):
                means = [curve[n][metric]["mean"] for n in sizes]
                stds = [curve[n][metric]["std"] for n in sizes]
                axes.errorbar(sizes, means, yerr=stds, marker="o", capsize=3, label=LABELS[metric])
            axes.set_xlabel("training subjects")
            axes.set_ylabel("score on the held-out subjects")
            axes.set_ylim(0.0, 1.0)
            axes.grid(alpha=0.3)
            axes.legend(fontsize=8)
            axes.set_title(f"Learning curve ({args.mode} mode, {args.splits} draws per size)")
            save_png(figure, args.png)
    write_text_atomic(args.json, json.dumps(report, indent=2) + "\n")
    print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    raise SystemExit(run_cli(main))
