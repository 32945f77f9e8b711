"""Cross-subject evaluation (reference 1.8, 7): train on some subjects, plan for the others' scenes.

Two protocols, each scoring the planner and the two baselines (``evaluation.baselines``) on the
same rows, and the human ceiling (``evaluation.ceiling``: the training people's choices in the
same situation) on the rows it covers, with the other planners scored on those rows too:
- Table I (``subject_splits``): random splits of the subjects; train and test on structured trials.
- Transfer to unstructured layouts (``transfer_folds``): folds of the participants who have
  unstructured trials; test on their unstructured trials, train on the other participants' trials,
  in setting "a" their structured trials only (zero-shot transfer), in "b" their structured and
  unstructured trials. Its layouts are all different: the ceiling matches rows there.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from tqdm import tqdm

from hlp_drake.dataset.records import STRUCTURED, category_of
from hlp_drake.evaluation.baselines import BASELINES, majority_plan, nearest_gap_plan
from hlp_drake.evaluation.ceiling import LAYOUT, MATCHED, Ceiling
from hlp_drake.evaluation.metrics import TrialOutcome, score_trial
from hlp_drake.features.training import LabelledSet, TrainingData
from hlp_drake.learners.models import DecisionModels, LearnerSettings
from hlp_drake.planner import PlannerConfig, plan
from hlp_drake.runtime.terminal import bars_disabled
from hlp_drake.segmentation.demonstration import GAP, OBJECT, Demonstration
from hlp_drake.segmentation.modes import is_faithful

PAPER_TABLE_I = {
    "gap_accuracy": 0.95,
    "object_accuracy": 0.85,
    "shlp": 0.70,
    "shlp_decision": 0.79,
    "shlp_element": 0.67,
}
METRICS = (
    "gap_accuracy",
    "object_accuracy",
    "shlp",
    "shlp_decision",
    "shlp_element",
    "shlp_element_plan",
    "shlp_plan",
)
CEILING = "ceiling"
PLANNERS = ("hlp", *BASELINES, CEILING)
SETTINGS = {
    "a": "trained on structured trials only (zero-shot transfer)",
    "b": "trained on structured + unstructured trials of the training participants",
}


def subject_splits(
    subjects: Sequence[str], *, n_train: int, splits: int, seed: int
) -> list[tuple[list[str], list[str]]]:
    """``splits`` seeded random (train, test) subject splits with ``n_train`` training subjects."""
    rng = np.random.default_rng(seed)
    subjects = sorted(subjects)
    result = []
    for _ in range(splits):
        train = sorted(rng.choice(subjects, n_train, replace=False).tolist())
        result.append((train, [s for s in subjects if s not in train]))
    return result


def transfer_folds(subjects: Sequence[str], *, folds: int, seed: int) -> list[list[str]]:
    """The ``subjects`` in ``folds`` seeded random groups of (nearly) equal size, each one fold's test."""
    order = np.random.default_rng(seed).permutation(sorted(subjects)).tolist()
    return [sorted(order[k::folds]) for k in range(folds)]


def transfer_filter(setting: str, test: Sequence[str]) -> Callable[[str], bool]:
    """Which trials (keys) a transfer fold trains on: no test participant's; in setting "a" only
    structured trials."""
    if setting not in SETTINGS:
        raise ValueError(f"unknown setting {setting!r}; choose one of {', '.join(SETTINGS)}")
    held_out = set(test)

    def keep(key: str) -> bool:
        subject, trial = key.split("/T")
        return subject not in held_out and (setting == "b" or category_of(int(trial)) == STRUCTURED)

    return keep


def metrics_of(outcomes: Sequence[TrialOutcome]) -> dict[str, float]:
    """Every metric of ``METRICS`` over the trials ``outcomes``."""
    rows = [r for o in outcomes for r in o.rows]
    return {
        "gap_accuracy": sum(o.gap_correct for o in outcomes) / max(sum(o.gap_total for o in outcomes), 1),
        "object_accuracy": sum(o.object_correct for o in outcomes)
        / max(sum(o.object_total for o in outcomes), 1),
        "shlp": float(np.mean([o.shlp for o in outcomes])),
        "shlp_decision": float(np.mean([r.decision_ok for r in rows])),
        "shlp_element": float(np.mean([r.element_ok for r in rows])),
        "shlp_element_plan": float(np.mean([r.element_plan_ok for r in rows])),
        "shlp_plan": float(np.mean([o.shlp_plan for o in outcomes])),
    }


@dataclass
class SplitResult:
    """One split's (or fold's) trial outcomes per planner ("hlp", the baselines and, where there
    is one, the ceiling).

    Attributes:
        same_rows: per planner but the ceiling, its outcomes on the ceiling's rows alone.
        coverage: the ceiling's rows: "rows" scored, of "rows_total"; "layout" and "matched" of
            them found on a shared layout and by matching; the matching "threshold" (if any).
    """

    train: list[str]
    test: list[str]
    outcomes: list[TrialOutcome]
    baselines: dict[str, list[TrialOutcome]] = field(default_factory=dict)
    setting: str = ""
    calibration: dict[str, float] = field(default_factory=dict)
    same_rows: dict[str, list[TrialOutcome]] = field(default_factory=dict)
    coverage: dict[str, float] = field(default_factory=dict)

    def planner_outcomes(self, planner: str = "hlp") -> list[TrialOutcome]:
        return self.outcomes if planner == "hlp" else self.baselines.get(planner, [])

    def metrics(self, planner: str = "hlp") -> dict[str, float]:
        return metrics_of(self.planner_outcomes(planner))


def planners_of(results: Sequence[SplitResult]) -> list[str]:
    """The planners of ``PLANNERS`` scored in ``results`` (the ceiling where it scored a row)."""
    return [p for p in PLANNERS if any(r.planner_outcomes(p) for r in results)]


def _majority(data: TrainingData) -> str:
    """The training rows' most common decision (from the row-choice set, whose positive candidates
    are the people's choices; from the object labels where there is none)."""
    if len(data.row):
        return OBJECT if data.row.X[data.row.y > 0, 0].mean() > 0.5 else GAP
    return OBJECT if data.object.y.mean() * 3 > 0.5 else GAP  # structured rows: three obstacles each


def evaluate_split(
    data: TrainingData,
    demonstrations: Sequence[Demonstration],
    train: list[str],
    test: list[str],
    *,
    settings: LearnerSettings,
    keep: Callable[[str], bool] | None = None,
    setting: str = "",
    config: PlannerConfig | None = None,
    people: Sequence[Demonstration] | None = None,
    match_rows: bool = False,
    progress: bool = False,
) -> SplitResult:
    """Fit on the training trials, plan every ``test`` subject's demonstration, score against them.

    Args:
        data: the training sets of every trial.
        demonstrations: the trials to test on (those of the ``test`` subjects are used).
        train, test: the subjects.
        keep: which trials (keys) to train on (default: those of the ``train`` subjects).
        setting: a label for the result (the transfer protocol's "a" or "b").
        config: the planner's settings (default: those of ``data.mode``).
        people: every demonstration, for the ceiling: those of the trials the models train on
            vote (none: no ceiling).
        match_rows: the ceiling matches rows without a shared layout (``Ceiling``).
    """
    training = data.where(keep) if keep is not None else data.subset(train)
    models = DecisionModels(settings).fit(training)
    tests = [d for d in demonstrations if d.subject in test]
    ceiling = None
    if people is not None:
        taught = keep if keep is not None else (lambda key: key.split("/")[0] in train)
        ceiling = Ceiling.of([d for d in people if taught(d.key)], match=match_rows)
    outcomes, baselines, same_rows, coverage = score_plans(
        models, tests, _majority(training), config=config, ceiling=ceiling, progress=progress
    )
    tested = {d.key for d in tests}
    held_out = data.where(lambda key: key in tested).row
    return SplitResult(
        train, test, outcomes, baselines, setting, calibration(models, held_out), same_rows, coverage
    )


def calibration(models: DecisionModels, rows: LabelledSet, bins: int = 10) -> dict[str, float]:
    """How well Cr's probabilities match how often people took the candidates of ``rows``: the
    expected calibration error (``bins`` equal-width bins) and the Brier score; the share of
    candidates within the demonstrations' range (novelty <= 1). Empty for the paper's planner."""
    if models.planner != "rows" or len(rows) == 0:
        return {}
    X = rows.X[:, : models.row_features]
    p = models.row.predict_proba(X)[:, 1]
    taken = rows.y > 0
    which = np.minimum((p * bins).astype(int), bins - 1)
    gap = sum(
        abs(p[which == b].mean() - taken[which == b].mean()) * np.mean(which == b)
        for b in range(bins)
        if np.any(which == b)
    )
    return {
        "ece": float(gap),
        "brier": float(np.mean((p - taken) ** 2)),
        "in_distribution": float(np.mean(models.row.novelty(X) <= 1.0)),
    }


def score_plans(
    models: DecisionModels,
    demonstrations: Sequence[Demonstration],
    majority: str,
    *,
    config: PlannerConfig | None = None,
    ceiling: Ceiling | None = None,
    progress: bool = False,
) -> tuple[list[TrialOutcome], dict[str, list[TrialOutcome]], dict[str, list[TrialOutcome]], dict]:
    """Plan every demonstration's scene with ``models`` (the person's own arm at the start), with
    the baselines (``majority``: the majority decision) and with the ``ceiling`` (if given), and
    score each against the person.

    Returns:
        The planner's outcomes; the baselines' (and the ceiling's, on its rows); every planner's
        but the ceiling's on the ceiling's rows; the ceiling's coverage (``SplitResult.coverage``).
    """
    config = config or PlannerConfig(mode=models.mode_)
    faithful = is_faithful(models.mode_)
    outcomes, baselines = [], {name: [] for name in BASELINES}
    same_rows: dict[str, list[TrialOutcome]] = {}
    found = {LAYOUT: 0, MATCHED: 0}
    for demo in tqdm(
        demonstrations,
        desc="planning test scenes",
        unit="scene",
        leave=False,
        disable=bars_disabled(progress),
    ):
        lengths = (demo.link_lengths.upper_arm, demo.link_lengths.forearm)
        result = plan(demo.scene, models, config, start_arm=demo.keypoints[0].arm, link_lengths=lengths)
        plans = {
            "hlp": result,
            "nearest_gap": nearest_gap_plan(demo.scene),
            "majority": majority_plan(demo.scene, majority),
        }
        outcomes.append(score_trial(demo, plans["hlp"], faithful=faithful))
        for name in BASELINES:
            baselines[name].append(score_trial(demo, plans[name], faithful=faithful))
        if ceiling is None:
            continue
        others, how = ceiling.plan(demo)
        if not how:
            continue
        rows = set(how)
        baselines.setdefault(CEILING, []).append(score_trial(demo, others, faithful=faithful, rows=rows))
        for name, other in plans.items():
            same_rows.setdefault(name, []).append(score_trial(demo, other, faithful=faithful, rows=rows))
        for way in how.values():
            found[way] += 1
    coverage = {}
    if ceiling is not None:
        coverage = {
            "rows": sum(len(o.rows) for o in baselines.get(CEILING, [])),
            "rows_total": sum(len(o.rows) for o in outcomes),
            **found,
        }
        if ceiling.threshold is not None:
            coverage["threshold"] = ceiling.threshold
    return outcomes, baselines, same_rows, coverage


def summarise(results: Sequence[SplitResult], planner: str = "hlp") -> dict[str, dict[str, float]]:
    """Mean and standard deviation over splits of every metric of ``planner``, plus the planner's
    planning time figures; for the ceiling (over the splits where it scored a row), its coverage
    summed over splits (the threshold: its mean) and every other planner's metrics on its rows."""
    if planner == CEILING:
        results = [r for r in results if r.planner_outcomes(CEILING)]
    per_split = [r.metrics(planner) for r in results]
    summary = {
        m: {
            "mean": float(np.mean([s[m] for s in per_split])),
            "std": float(np.std([s[m] for s in per_split])),
        }
        for m in METRICS
    }
    if planner == CEILING:
        coverage: dict[str, float] = {}
        for r in results:
            for key, value in r.coverage.items():
                coverage[key] = coverage.get(key, 0) + value
        if "threshold" in coverage:
            coverage["threshold"] /= len(results)
        summary["coverage"] = coverage
        summary["same_rows"] = {
            name: {
                m: {
                    "mean": float(np.mean([metrics_of(r.same_rows[name])[m] for r in results])),
                    "std": float(np.std([metrics_of(r.same_rows[name])[m] for r in results])),
                }
                for m in METRICS
            }
            for name in ("hlp", *BASELINES)
        }
        return summary
    for key in ("ece", "brier", "in_distribution"):
        values = [r.calibration[key] for r in results if key in r.calibration]
        if values and planner == "hlp":
            summary[f"row_{key}"] = {"mean": float(np.mean(values)), "std": float(np.std(values))}
    if planner == "hlp":  # the baselines' times are not measured
        times = np.array([o.planning_time_s for r in results for o in r.outcomes])
        summary["planning_time_s"] = {
            "median": float(np.median(times)),
            "p95": float(np.percentile(times, 95)),
            "p99": float(np.percentile(times, 99)),
        }
    return summary
