"""Similarity of the planner to held-out people (the paper's Table I, and transfer to unstructured layouts)."""

from hlp_drake.evaluation.baselines import BASELINES, majority_plan, nearest_gap_plan
from hlp_drake.evaluation.metrics import RowOutcome, TrialOutcome, planned_rows, score_trial
from hlp_drake.evaluation.protocol import (
    METRICS,
    PAPER_TABLE_I,
    PLANNERS,
    SETTINGS,
    SplitResult,
    evaluate_split,
    metrics_of,
    subject_splits,
    summarise,
    transfer_filter,
    transfer_folds,
)

__all__ = [
    "BASELINES",
    "METRICS",
    "PAPER_TABLE_I",
    "PLANNERS",
    "SETTINGS",
    "RowOutcome",
    "SplitResult",
    "TrialOutcome",
    "evaluate_split",
    "majority_plan",
    "metrics_of",
    "nearest_gap_plan",
    "planned_rows",
    "score_trial",
    "subject_splits",
    "summarise",
    "transfer_filter",
    "transfer_folds",
]
