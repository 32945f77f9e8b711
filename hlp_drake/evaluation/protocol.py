"""Cross-subject evaluation (reference 1.8, 7): train on some subjects, plan for the others' scenes.

Two protocols, each scoring the planner and the two baselines (``evaluation.baselines``) on the
same rows:
- Table I (``subject_splits``): random splits of the subjects; train and test on structured trials.
- Transfer to unstructured layouts (``transfer_folds``): folds of the participants who have
  unstructured trials; test on their unstructured trials, train on the other participants' trials,
  in setting "a" their structured trials only (zero-shot transfer), in "b" their structured and
  unstructured trials.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from tqdm import tqdm

from hlp_drake.dataset.records import STRUCTURED, category_of
from hlp_drake.evaluation.baselines import BASELINES, majority_plan, nearest_gap_plan
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
PLANNERS = ("hlp", *BASELINES)
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
    """One split's (or fold's) trial outcomes per planner ("hlp" and the baselines)."""

    train: list[str]
    test: list[str]
    outcomes: list[TrialOutcome]
    baselines: dict[str, list[TrialOutcome]] = field(default_factory=dict)
    setting: str = ""
    calibration: dict[str, float] = field(default_factory=dict)

    def metrics(self, planner: str = "hlp") -> dict[str, float]:
        return metrics_of(self.outcomes if planner == "hlp" else self.baselines[planner])


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
    """
    training = data.where(keep) if keep is not None else data.subset(train)
    models = DecisionModels(settings).fit(training)
    tests = [d for d in demonstrations if d.subject in test]
    outcomes, baselines = score_plans(models, tests, _majority(training), config=config, progress=progress)
    tested = {d.key for d in tests}
    held_out = data.where(lambda key: key in tested).row
    return SplitResult(train, test, outcomes, baselines, setting, calibration(models, held_out))


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
    progress: bool = False,
) -> tuple[list[TrialOutcome], dict[str, list[TrialOutcome]]]:
    """Plan every demonstration's scene with ``models`` (the person's own arm at the start) and
    with the baselines (``majority``: the majority decision), and score each against the person."""
    config = config or PlannerConfig(mode=models.mode_)
    faithful = is_faithful(models.mode_)
    outcomes, baselines = [], {name: [] for name in BASELINES}
    for demo in tqdm(
        demonstrations,
        desc="planning test scenes",
        unit="scene",
        leave=False,
        disable=bars_disabled(progress),
    ):
        lengths = (demo.link_lengths.upper_arm, demo.link_lengths.forearm)
        result = plan(demo.scene, models, config, start_arm=demo.keypoints[0].arm, link_lengths=lengths)
        outcomes.append(score_trial(demo, result, faithful=faithful))
        baselines["nearest_gap"].append(score_trial(demo, nearest_gap_plan(demo.scene), faithful=faithful))
        baselines["majority"].append(
            score_trial(demo, majority_plan(demo.scene, majority), faithful=faithful)
        )
    return outcomes, baselines


def summarise(results: Sequence[SplitResult], planner: str = "hlp") -> dict[str, dict[str, float]]:
    """Mean and standard deviation over splits of every metric of ``planner``, plus the planner's
    planning time figures."""
    per_split = [r.metrics(planner) for r in results]
    summary = {
        m: {
            "mean": float(np.mean([s[m] for s in per_split])),
            "std": float(np.std([s[m] for s in per_split])),
        }
        for m in METRICS
    }
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
