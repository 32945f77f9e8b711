"""Similarity of the planner to held-out people (the paper's Table I)."""

from hlp_drake.evaluation.metrics import RowOutcome, TrialOutcome, planned_rows, score_trial
from hlp_drake.evaluation.protocol import (
    METRICS,
    PAPER_TABLE_I,
    SplitResult,
    evaluate_split,
    subject_splits,
    summarise,
)

__all__ = [
    "METRICS",
    "PAPER_TABLE_I",
    "RowOutcome",
    "SplitResult",
    "TrialOutcome",
    "evaluate_split",
    "planned_rows",
    "score_trial",
    "subject_splits",
    "summarise",
]
