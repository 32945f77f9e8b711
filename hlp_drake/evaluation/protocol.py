"""Cross-subject evaluation (reference 1.8, 7): train on some subjects, plan for the others' scenes."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from tqdm import tqdm

from hlp_drake.evaluation.metrics import TrialOutcome, score_trial
from hlp_drake.features.training import TrainingData
from hlp_drake.learners.models import DecisionModels, LearnerSettings
from hlp_drake.planner import PlannerConfig, plan
from hlp_drake.segmentation.demonstration import Demonstration
from hlp_drake.segmentation.modes import is_faithful

PAPER_TABLE_I = {"gap_accuracy": 0.95, "object_accuracy": 0.85, "shlp": 0.70, "shlp_decision": 0.79,
                 "shlp_element": 0.67}
METRICS = ("gap_accuracy", "object_accuracy", "shlp", "shlp_decision", "shlp_element", "shlp_element_plan")


def subject_splits(subjects: Sequence[str], *, n_train: int, splits: int, seed: int) -> list[tuple[list[str], list[str]]]:
    """``splits`` seeded random (train, test) subject splits with ``n_train`` training subjects."""
    rng = np.random.default_rng(seed)
    subjects = sorted(subjects)
    result = []
    for _ in range(splits):
        train = sorted(rng.choice(subjects, n_train, replace=False).tolist())
        result.append((train, [s for s in subjects if s not in train]))
    return result


@dataclass
class SplitResult:
    train: list[str]
    test: list[str]
    outcomes: list[TrialOutcome]

    def metrics(self) -> dict[str, float]:
        rows = [r for o in self.outcomes for r in o.rows]
        return {
            "gap_accuracy": sum(o.gap_correct for o in self.outcomes) / max(sum(o.gap_total for o in self.outcomes), 1),
            "object_accuracy": sum(o.object_correct for o in self.outcomes)
            / max(sum(o.object_total for o in self.outcomes), 1),
            "shlp": float(np.mean([o.shlp for o in self.outcomes])),
            "shlp_decision": float(np.mean([r.decision_ok for r in rows])),
            "shlp_element": float(np.mean([r.element_ok for r in rows])),
            "shlp_element_plan": float(np.mean([r.element_plan_ok for r in rows])),
        }


def evaluate_split(data: TrainingData, demonstrations: Sequence[Demonstration], train: list[str], test: list[str],
                   *, settings: LearnerSettings, progress: bool = False) -> SplitResult:
    """Fit on the ``train`` subjects' data, plan every ``test`` subject's scene, score against them."""
    models = DecisionModels(settings).fit(data.subset(train))
    config = PlannerConfig(mode=data.mode)
    faithful = is_faithful(data.mode)
    tests = [d for d in demonstrations if d.subject in test]
    outcomes = []
    for demo in tqdm(tests, desc="planning test scenes", unit="scene", leave=False, disable=not progress):
        lengths = (demo.link_lengths.upper_arm, demo.link_lengths.forearm)
        result = plan(demo.scene, models, config, start_arm=demo.keypoints[0].arm, link_lengths=lengths)
        outcomes.append(score_trial(demo, result, faithful=faithful))
    return SplitResult(train, test, outcomes)


def summarise(results: Sequence[SplitResult]) -> dict[str, dict[str, float]]:
    """Mean and standard deviation over splits of every metric, plus planning time figures."""
    per_split = [r.metrics() for r in results]
    summary = {m: {"mean": float(np.mean([s[m] for s in per_split])), "std": float(np.std([s[m] for s in per_split]))}
               for m in METRICS}
    times = np.array([o.planning_time_s for r in results for o in r.outcomes])
    summary["planning_time_s"] = {"median": float(np.median(times)), "p95": float(np.percentile(times, 95))}
    return summary
