"""python -m hlp_drake.evaluate: how human-like the planner is on people it never saw, beside two baselines.

    python -m hlp_drake.evaluate [--dataset PATH] [--protocol 80_20|num_subjects|unstructured]
        [--preset boosted|svm|paper] [--mode fixed|faithful] --json OUT [--csv ROWS.csv] [--png OUT.png]
    python -m hlp_drake.evaluate --models DIR|bundled [--category unstructured|structured] --json OUT

Protocols: 80_20 (the paper's Table I: random 19/5 subject splits of the structured trials);
num_subjects (the learning curve over 3-23 training subjects); unstructured (folds of the
participants who have unstructured trials, tested on those; trained in setting a on the other
participants' structured trials only, in setting b on their structured and unstructured trials).
With --models, no training: the given models (a directory, or the bundled ones) plan every
successful trial of --category. Every result scores the planner and the two baselines (the gap
nearest the start-target line; the majority decision) on the same rows, and beside them (not with
--models) the human ceiling: the training people's choices in the same situation (a shared layout;
in the unstructured protocol also the nearest matched row), on the rows it covers.
"""

from __future__ import annotations

import os
import time
from collections.abc import Sequence
from contextlib import nullcontext
from functools import partial

from tqdm import tqdm

from hlp_drake.commands.parsing import DATASET_DEFAULT, MAX_WORKERS, Parser, add_quiet, integer, make_parser
from hlp_drake.config.ranges import MAX_SEED
from hlp_drake.dataset.dataset import Dataset
from hlp_drake.dataset.records import STRUCTURED, UNSTRUCTURED, category_of
from hlp_drake.errors import HlpError
from hlp_drake.evaluation import SETTINGS, evaluate_split, subject_splits, transfer_filter, transfer_folds
from hlp_drake.evaluation.fixed_models import evaluate_models
from hlp_drake.evaluation.report import write_report
from hlp_drake.features import training_data
from hlp_drake.files.atomic import check_writable
from hlp_drake.learners import DEFAULT_PRESET, PRESETS, DecisionModels
from hlp_drake.learners.bundled import default_models
from hlp_drake.runtime.processes import interrupts_held, worker_pool
from hlp_drake.runtime.terminal import bars_disabled
from hlp_drake.segmentation import DEFAULT_MODE, MODES, segment_dataset

TRAIN_SIZES = (3, 7, 11, 15, 19, 23)
PROTOCOLS = ("80_20", "num_subjects", "unstructured")
MIN_SUBJECTS = {"80_20": 3, "num_subjects": TRAIN_SIZES[0] + 1}
"""Participants with structured trials a protocol needs: every split then tests someone."""


def _jobs(
    args, subjects: list[str], everyone: list[str], unstructured_subjects: list[str]
) -> list[tuple[str, list[str], list[str], str]]:
    """(label, train subjects, test subjects, transfer setting) of every split or fold: Table I's
    and the learning curve's of the participants with structured trials (``subjects``), the
    unstructured protocol's of ``unstructured_subjects`` (trained on ``everyone`` else)."""
    if args.protocol != "unstructured" and len(subjects) < MIN_SUBJECTS[args.protocol]:
        raise HlpError(
            f"the {args.protocol} protocol needs usable structured trials of at least "
            f"{MIN_SUBJECTS[args.protocol]} participants; the dataset has {len(subjects)}"
        )
    if args.protocol == "80_20":
        n = round(0.8 * len(subjects))
        return [
            (f"{n}/{len(subjects) - n}", tr, te, "")
            for tr, te in subject_splits(subjects, n_train=n, splits=args.splits, seed=args.seed)
        ]
    if args.protocol == "num_subjects":
        return [
            (str(n), tr, te, "")
            for n in TRAIN_SIZES
            if n < len(subjects)
            for tr, te in subject_splits(subjects, n_train=n, splits=args.splits, seed=args.seed)
        ]
    if len(unstructured_subjects) < args.folds:
        raise HlpError(
            f"the unstructured protocol needs at least {args.folds} participants with unstructured "
            f"trials; the dataset has {len(unstructured_subjects)} (lay the unstructured archive over it)"
        )
    folds = transfer_folds(unstructured_subjects, folds=args.folds, seed=args.seed)
    return [
        (setting, [s for s in everyone if s not in test], test, setting)
        for setting in args.settings
        for test in folds
    ]


def _parser() -> Parser:
    """The command line of ``python -m hlp_drake.evaluate``."""
    parser = make_parser("python -m hlp_drake.evaluate", __doc__)
    parser.add_argument("--dataset", help="the dataset: archives or folders " + DATASET_DEFAULT)
    parser.add_argument("--protocol", choices=PROTOCOLS, default="80_20")
    parser.add_argument(
        "--splits", type=integer(1, 1000), default=5, help="random subject splits per size (default 5)"
    )
    parser.add_argument(
        "--folds", type=integer(2, 100), default=4, help="participant folds of the unstructured protocol"
    )
    parser.add_argument(
        "--settings",
        nargs="+",
        choices=sorted(SETTINGS),
        default=sorted(SETTINGS),
        help="the unstructured protocol's training settings (default: a b)",
    )
    parser.add_argument("--seed", type=integer(0, MAX_SEED), default=0)
    parser.add_argument("--mode", choices=MODES, default=DEFAULT_MODE)
    parser.add_argument("--preset", choices=sorted(PRESETS), default=DEFAULT_PRESET)
    parser.add_argument(
        "--models", help="score these trained models (a directory, or 'bundled') instead of training"
    )
    parser.add_argument(
        "--category",
        choices=(UNSTRUCTURED, STRUCTURED),
        default=UNSTRUCTURED,
        help="with --models: the trials to plan (default unstructured)",
    )
    parser.add_argument("--json", required=True, help="write the figures here")
    parser.add_argument(
        "--csv", "--predictions", dest="csv", help="every scored row's decisions, per planner"
    )
    parser.add_argument("--png", help="a bar chart of the planners' scores")
    parser.add_argument(
        "--workers", type=integer(1, MAX_WORKERS), help="parallel splits (default: one per core)"
    )
    add_quiet(parser)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = _parser()
    args = parser.parse_args(argv)
    if args.splits < 1 or args.folds < 2:
        parser.error("--splits must be at least 1 and --folds at least 2")
    if args.models and args.category == UNSTRUCTURED and args.mode != "fixed":
        parser.error("unstructured trials (--category) are segmented in fixed mode only")
    if args.protocol == "unstructured" and args.mode != "fixed":
        parser.error(
            "the unstructured protocol segments in fixed mode (faithful mode cannot read unstructured rows)"
        )
    check_writable(args.json, args.csv, args.png)
    started = time.perf_counter()
    models = None
    if args.models:  # before any work: a missing or damaged model file is a usage error
        models = default_models() if args.models == "bundled" else DecisionModels.load(args.models)
    dataset = Dataset(args.dataset, progress=not args.quiet)
    categories = (STRUCTURED, UNSTRUCTURED) if args.mode == "fixed" else (STRUCTURED,)
    segmentation = segment_dataset(dataset, mode=args.mode, categories=categories, progress=not args.quiet)
    demonstrations = segmentation.demonstrations
    if models is not None:
        if not any(category_of(d.trial) == args.category for d in demonstrations):
            raise HlpError(f"the dataset has no usable {args.category} trials to plan (--category)")
        results = {args.category: [evaluate_models(models, demonstrations, category=args.category)]}
        return write_report(args, results, demonstrations, time.perf_counter() - started)
    data = training_data(demonstrations, mode=args.mode)
    structured = [d for d in demonstrations if category_of(d.trial) == STRUCTURED]
    unstructured = [d for d in demonstrations if category_of(d.trial) == UNSTRUCTURED]
    unstructured_subjects = sorted({d.subject for d in unstructured})
    everyone = sorted({d.subject for d in demonstrations})
    jobs = _jobs(args, sorted({d.subject for d in structured}), everyone, unstructured_subjects)
    workers = max(1, min(args.workers or os.cpu_count() or 1, len(jobs)))
    results: dict[str, list] = {}
    with worker_pool(workers, method=None) if workers > 1 else nullcontext() as pool:
        run = partial(_run, data, structured, unstructured, PRESETS[args.preset])
        with interrupts_held():  # the workers start here
            futures = [(job[0], pool.submit(run, *job[1:]) if pool else None, job) for job in jobs]
        for label, future, job in tqdm(
            futures,
            desc=f"{args.protocol} ({workers} workers)",
            unit="split",
            disable=bars_disabled(not args.quiet),
        ):
            results.setdefault(label, []).append(future.result() if future else run(*job[1:]))
    return write_report(args, results, demonstrations, time.perf_counter() - started)


def _run(data, structured, unstructured, settings, train, test, setting):
    """One split (Table I, learning curve) or fold (unstructured, ``setting``); the ceiling's votes
    from the trials the models learn from."""
    people = [*structured, *unstructured]
    if setting:
        return evaluate_split(
            data,
            unstructured,
            train,
            test,
            settings=settings,
            keep=transfer_filter(setting, test),
            setting=setting,
            people=people,
            match_rows=True,
        )
    return evaluate_split(data, structured, train, test, settings=settings, people=people)
