"""Similarity of the planner to held-out people (the paper's Table I, and transfer to unstructured layouts),
beside the baselines and the human ceiling."""

from hlp_drake.evaluation.baselines import BASELINES, majority_plan, nearest_gap_plan
from hlp_drake.evaluation.ceiling import Ceiling, consensus, layout_key
from hlp_drake.evaluation.metrics import RowOutcome, TrialOutcome, planned_rows, score_trial
from hlp_drake.evaluation.protocol import (
    CEILING,
    METRICS,
    PAPER_TABLE_I,
    PLANNERS,
    SETTINGS,
    SplitResult,
    evaluate_split,
    metrics_of,
    planners_of,
    subject_splits,
    summarise,
    transfer_filter,
    transfer_folds,
)

__all__ = [
    "BASELINES",
    "CEILING",
    "METRICS",
    "PAPER_TABLE_I",
    "PLANNERS",
    "SETTINGS",
    "Ceiling",
    "RowOutcome",
    "SplitResult",
    "TrialOutcome",
    "consensus",
    "evaluate_split",
    "layout_key",
    "majority_plan",
    "metrics_of",
    "nearest_gap_plan",
    "planned_rows",
    "planners_of",
    "score_trial",
    "subject_splits",
    "summarise",
    "transfer_filter",
    "transfer_folds",
]
