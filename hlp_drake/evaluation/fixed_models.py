"""Score trained models as they are (no training) on the trials of one category, beside the baselines."""

from __future__ import annotations

from collections.abc import Sequence

from hlp_drake.dataset.records import category_of
from hlp_drake.evaluation.baselines import majority_decision
from hlp_drake.evaluation.protocol import SplitResult, calibration, score_plans
from hlp_drake.features.training import row_choice_set
from hlp_drake.learners.models import DecisionModels
from hlp_drake.segmentation.demonstration import Demonstration


def evaluate_models(
    models: DecisionModels, demonstrations: Sequence[Demonstration], *, category: str, progress: bool = False
) -> SplitResult:
    """Plan and score every demonstration of ``category`` with ``models``.

    The majority baseline takes the majority decision of the other subjects' demonstrations (of
    every category), or of all of them where every subject is tested. No ceiling: the models'
    training people are not known here.
    """
    tests = [d for d in demonstrations if category_of(d.trial) == category]
    tested = {d.subject for d in tests}
    others = [d for d in demonstrations if d.subject not in tested] or list(demonstrations)
    outcomes, baselines, _, _ = score_plans(models, tests, majority_decision(others), progress=progress)
    rows = row_choice_set(tests) if models.planner == "rows" else None
    return SplitResult(
        sorted(models.subjects_),
        sorted(tested),
        outcomes,
        baselines,
        category,
        calibration(models, rows) if rows is not None else {},
    )
