"""Levers for a stronger prior on people it never saw, side by side, one chosen per fold by inner CV.

    python benchmarks/prior_levers.py [--dataset PATH] [--out DIR] [--levers today mirror ...]
        [--folds 4] [--inner 3] [--seed 0] [--workers 2]

The protocol is ``python -m hlp_drake.evaluate --protocol unstructured``'s setting b, unchanged:
the participants with unstructured trials in ``--folds`` seeded folds; each fold trains on every
other participant's structured and unstructured trials and plans the fold's unstructured trials.
Only the row-choice classifier Cr differs between levers (Cd and Ra are the default preset's,
fitted once per fold).

Nothing is tuned on a test fold. Within each fold's training participants, ``--inner``
participant folds (GroupKFold over those with unstructured trials) score every lever on the
inner-held-out people's unstructured rows (sHLP's row score with the person's previous rows
given, as ``learners.adapt.row_score``); the lever with the best inner score is the fold's
"chosen" one. Every lever is also fitted on the whole training set and scored on the test fold
(planned scenes, sHLP as ``evaluate``), so all of them are shown side by side; the "chosen" row
is what keeping the inner CV's choice gives.

Levers (``LEVERS``): today's preset; structured trials weighted 0.5 (today 0.25); rows weighted by
how new they are (density ratio of unstructured to structured rows); a calibrated ensemble of
three boosted models (seeds); the previous rows' decisions as features (a sequence model: the way
the hand came conditions the next row); those and the hand's approach direction (wider context);
mirror augmentation; perturbation augmentation (obstacles moved by up to 1 cm and resized by up
to 10 %, the layout's rows and gaps kept, so every decision keeps its label).

Writes ``DIR/prior_levers.json`` (per fold and lever: inner and test scores; means; the chosen
lever per fold) and ``DIR/prior_levers.png``; each fold's results are kept in ``DIR/folds/`` as
they come, so a rerun goes on where it stopped.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np
from sklearn.ensemble import HistGradientBoostingClassifier
from sklearn.model_selection import GroupKFold

from hlp_drake.commands.parsing import run_cli
from hlp_drake.dataset.dataset import Dataset
from hlp_drake.dataset.records import STRUCTURED, UNSTRUCTURED, category_of
from hlp_drake.evaluation.protocol import _majority, metrics_of, score_plans, transfer_filter, transfer_folds
from hlp_drake.features.augment import mirrored_rows, perturbed_scene, same_layout
from hlp_drake.features.row_choice import ROW_CHOICE_FEATURES, ROW_CONTEXT_FEATURES
from hlp_drake.features.training import LabelledSet, row_choice_rows, row_choice_set, training_data
from hlp_drake.files.atomic import write_text_atomic
from hlp_drake.files.plotting import new_figure, save_png
from hlp_drake.learners import PRESETS, DecisionModels
from hlp_drake.learners.adapt import row_score
from hlp_drake.learners.choice import RowChoiceClassifier
from hlp_drake.learners.models import _category_weights
from hlp_drake.segmentation import segment_dataset
from hlp_drake.taskspace import TaskSpace

BASE = len(ROW_CHOICE_FEATURES)
SEQUENCE = BASE + 3  # came by a release, came through a gap, obstacles moved before
CONTEXT = len(ROW_CONTEXT_FEATURES)  # and the turn from the hand's heading


def joined(a: LabelledSet, b: LabelledSet) -> LabelledSet:
    """The rows of ``a`` followed by those of ``b``."""
    return LabelledSet(
        a.columns,
        *(np.concatenate([getattr(a, n), getattr(b, n)]) for n in ("X", "y", "subjects", "keys", "original")),
    )


class Ensemble:
    """Calibrated row-choice classifiers averaged (probabilities), novelty from the first."""

    def __init__(self, members: list[RowChoiceClassifier]) -> None:
        self.members = members
        self.n_features_in_ = members[0].n_features_in_

    def predict_proba(self, X: np.ndarray) -> np.ndarray:
        return np.mean([m.predict_proba(X) for m in self.members], axis=0)

    def novelty(self, X: np.ndarray) -> np.ndarray:
        return self.members[0].novelty(X)


def _weights(rows: LabelledSet, structured_weight: float = 0.25) -> np.ndarray:
    weight = _category_weights(rows.keys, structured_weight)
    return np.ones(len(rows.y)) if weight is None else weight


def _fit(rows: LabelledSet, columns: int = BASE, weight: np.ndarray | None = None, seed: int = 0):
    weight = _weights(rows) if weight is None else weight
    return RowChoiceClassifier(random_state=seed).fit(
        rows.X[:, :columns], rows.y, groups=rows.subjects, sample_weight=weight
    )


def _novelty_weights(rows: LabelledSet, seed: int) -> np.ndarray:
    """Unstructured rows 1; a structured row the density ratio p(unstructured | x) / p(structured | x)
    of its candidate's features (prior-corrected), clipped to [0.05, 1]: rows like the new
    layouts count fully, rows only the repeated structured layouts have count little."""
    unstructured = np.array([category_of(int(str(k).split("/T")[1])) == UNSTRUCTURED for k in rows.keys])
    if unstructured.all() or not unstructured.any():
        return np.ones(len(rows.y))
    domain = HistGradientBoostingClassifier(max_iter=100, random_state=seed).fit(
        rows.X[:, :BASE], unstructured
    )
    p = np.clip(domain.predict_proba(rows.X[:, :BASE])[:, 1], 1e-6, 1 - 1e-6)
    ratio = p / (1 - p) * (1 - unstructured.mean()) / unstructured.mean()
    return np.where(unstructured, 1.0, np.clip(ratio, 0.05, 1.0))


def _mirror(rows: LabelledSet) -> RowChoiceClassifier:
    X, y, groups, weight = mirrored_rows(rows.X[:, :BASE], rows.y, rows.subjects, _weights(rows))
    return RowChoiceClassifier().fit(X, y, groups=groups, sample_weight=weight)


LEVERS: dict[str, tuple[str, Callable[[LabelledSet, LabelledSet], object]]] = {
    "today": ("today's preset (structured rows weighted 0.25)", lambda r, p: _fit(r)),
    "structured_half": ("structured rows weighted 0.5", lambda r, p: _fit(r, weight=_weights(r, 0.5))),
    "novelty": ("rows weighted by how new they are", lambda r, p: _fit(r, weight=_novelty_weights(r, 0))),
    "ensemble": ("calibrated ensemble of 3 boosted models", lambda r, p: Ensemble([_fit(r, seed=s) for s in range(3)])),
    "sequence": ("the previous rows' decisions as features", lambda r, p: _fit(r, SEQUENCE)),
    "context": ("previous decisions + approach direction", lambda r, p: _fit(r, CONTEXT)),
    "mirror": ("mirror augmentation", lambda r, p: _mirror(r)),
    "perturb": ("perturbation augmentation (1 cm, 10 %)", lambda r, p: _fit(joined(r, p))),
}  # fmt: skip


def perturbed_rows(demonstrations, seed: int) -> LabelledSet:
    """The row-choice rows of one perturbed copy of every demonstration whose layout keeps its rows
    and gaps (so each decision keeps its label)."""
    copies = []
    for index, demo in enumerate(demonstrations):
        scene = perturbed_scene(demo.scene, np.random.default_rng([seed, index]))
        if same_layout(TaskSpace(demo.scene), TaskSpace(scene)):
            copies.append(replace(demo, scene=scene))
    return row_choice_set(copies)


def inner_score(lever, training: LabelledSet, perturbed: LabelledSet, held_rows, k: int) -> float:
    """Mean row score on inner-held-out people's unstructured rows (see the module's docstring);
    ``held_rows``: per person with unstructured trials, their rows (candidates' Xr, the taken one)."""
    people = np.array(sorted(held_rows))
    scores = []
    for _, held in GroupKFold(n_splits=k).split(people, groups=people):
        out = list(people[held])
        model = lever(
            training.rows(~np.isin(training.subjects, out)), perturbed.rows(~np.isin(perturbed.subjects, out))
        )
        for features, taken in (row for person in out for row in held_rows[person]):
            p = model.predict_proba(features[:, : model.n_features_in_])[:, 1]
            scores.append(row_score(p, taken, features[:, 0] > 0.5))
    return float(np.mean(scores))


def run_fold(job) -> dict:
    fold, test, levers, state, folder = job
    data, demonstrations, perturbed_all, inner = (
        state["data"],
        state["demos"],
        state["perturbed"],
        state["inner"],
    )
    path = folder / f"fold{fold}.json"
    record = json.loads(path.read_text()) if path.is_file() else {"test": test, "levers": {}}
    keep = transfer_filter("b", test)
    training = data.where(keep)
    rows = training.row
    perturbed = perturbed_all.rows(np.array([keep(k) for k in perturbed_all.keys], dtype=bool))
    models = DecisionModels(PRESETS["boosted"]).fit(training, only=("direction", "arm"))
    majority = _majority(training)
    tests = [d for d in demonstrations if d.subject in test and category_of(d.trial) == UNSTRUCTURED]
    training_people = {str(s) for s in rows.subjects}
    held_rows: dict[str, list] = {}
    for demo in demonstrations:
        if demo.subject in training_people and category_of(demo.trial) == UNSTRUCTURED:
            held_rows.setdefault(demo.subject, []).extend(
                (X, int(np.argmax(y))) for X, y in row_choice_rows(demo, TaskSpace(demo.scene))
            )
    for name in levers:
        if name in record["levers"]:
            continue
        started = time.perf_counter()
        lever = LEVERS[name][1]
        score = inner_score(lever, rows, perturbed, held_rows, inner)
        models.row = lever(rows, perturbed)
        outcomes, baselines, _, _ = score_plans(models, tests, majority)
        metrics = metrics_of(outcomes)
        record["levers"][name] = {
            "inner_row_score": score,
            "shlp": metrics["shlp"],
            "shlp_decision": metrics["shlp_decision"],
            "shlp_element": metrics["shlp_element"],
            "seconds": time.perf_counter() - started,
        }
        record["nearest_gap"] = metrics_of(baselines["nearest_gap"])["shlp"]
        write_text_atomic(path, json.dumps(record, indent=2) + "\n")
        print(
            f"fold {fold} {name}: inner {score:.3f}, test sHLP {metrics['shlp']:.3f} "
            f"({time.perf_counter() - started:.0f} s)",
            flush=True,
        )
    return record


def summary(records: list[dict], levers: list[str]) -> dict:
    """Per lever the mean over folds; the inner CV's choice per fold and its test score."""
    out = {
        name: {
            "about": LEVERS[name][0],
            "shlp": float(np.mean([r["levers"][name]["shlp"] for r in records])),
            "shlp_per_fold": [r["levers"][name]["shlp"] for r in records],
            "inner_row_score": float(np.mean([r["levers"][name]["inner_row_score"] for r in records])),
        }
        for name in levers
    }
    chosen = [max(levers, key=lambda n: r["levers"][n]["inner_row_score"]) for r in records]
    out["chosen"] = {
        "about": "the lever with the best inner score, per fold",
        "levers": chosen,
        "shlp": float(np.mean([r["levers"][c]["shlp"] for r, c in zip(records, chosen)])),
        "shlp_per_fold": [r["levers"][c]["shlp"] for r, c in zip(records, chosen)],
    }
    out["nearest_gap"] = {
        "about": "the gap nearest the start-target line",
        "shlp": float(np.mean([r["nearest_gap"] for r in records])),
        "shlp_per_fold": [r["nearest_gap"] for r in records],
    }
    return out


def plot(results: dict, path: Path) -> None:
    names = list(results)
    fig, ax = new_figure(9, 4)
    values = [results[n]["shlp"] for n in names]
    ax.bar(
        names, values, color=["tab:blue" if n not in ("chosen", "nearest_gap") else "tab:gray" for n in names]
    )
    ax.axhline(results["today"]["shlp"], color="k", lw=0.8, ls="--", label="today")
    ax.set_ylim(min(values) - 0.05, max(values) + 0.03)
    ax.set_ylabel("sHLP, unstructured (b), mean of folds")
    ax.set_title("Levers for the prior on unseen people (chosen: by inner CV per fold)")
    ax.tick_params(axis="x", rotation=30)
    ax.legend()
    save_png(fig, path)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--dataset", help="the dataset (default: as python -m hlp_drake.evaluate)")
    parser.add_argument("--out", type=Path, default=Path("benchmark-results"), help="output folder")
    parser.add_argument("--levers", nargs="+", choices=list(LEVERS), default=list(LEVERS))
    parser.add_argument("--folds", type=int, default=4)
    parser.add_argument("--inner", type=int, default=3)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    if "today" not in args.levers:
        parser.error("--levers: include today (the reference)")
    folder = args.out / "folds"
    folder.mkdir(parents=True, exist_ok=True)
    started = time.perf_counter()
    demonstrations = segment_dataset(
        Dataset(args.dataset, progress=False), mode="fixed", categories=(STRUCTURED, UNSTRUCTURED)
    ).demonstrations
    data = training_data(demonstrations, mode="fixed")
    perturbed = perturbed_rows(demonstrations, args.seed)
    print(
        f"{len(data.row)} rows, {len(perturbed.y)} perturbed ({time.perf_counter() - started:.0f} s)",
        flush=True,
    )
    people = sorted({d.subject for d in demonstrations if category_of(d.trial) == UNSTRUCTURED})
    folds = transfer_folds(people, folds=args.folds, seed=args.seed)
    state = {"data": data, "demos": demonstrations, "perturbed": perturbed, "inner": args.inner}
    jobs = [(k, test, args.levers, state, folder) for k, test in enumerate(folds)]
    if args.workers > 1:
        with multiprocessing.get_context("fork").Pool(args.workers) as pool:
            records = pool.map(run_fold, jobs, chunksize=1)
            pool.close()  # the workers finish: none is terminated mid-wait when the pool exits
            pool.join()
    else:
        records = [run_fold(job) for job in jobs]
    results = summary(records, args.levers)
    report = {
        "protocol": "unstructured, setting b; levers chosen by inner GroupKFold over training people",
        "folds": args.folds,
        "inner": args.inner,
        "seed": args.seed,
        "results": results,
        "per_fold": records,
        "seconds": time.perf_counter() - started,
    }
    write_text_atomic(args.out / "prior_levers.json", json.dumps(report, indent=2) + "\n")
    plot(results, args.out / "prior_levers.png")
    for name, r in results.items():
        print(f"{name:16s} sHLP {r['shlp']:.3f}  " + " ".join(f"{v:.3f}" for v in r["shlp_per_fold"]))
    return 0


if __name__ == "__main__":
    raise SystemExit(run_cli(main))
