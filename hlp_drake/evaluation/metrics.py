"""Per-trial similarity of a plan to the person's decisions (reference section 7, the paper's Table I)."""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass

import numpy as np

from hlp_drake.features.training import gap_labels, object_labels
from hlp_drake.planner.plan import HighLevelPlan
from hlp_drake.segmentation.demonstration import GAP, NONE, OBJECT, Demonstration
from hlp_drake.taskspace import TaskSpace


@dataclass(frozen=True)
class RowOutcome:
    row: int
    human_decision: str
    human_element: str
    hlp_decision: str
    hlp_element: str
    decision_ok: bool  # I(D)
    element_ok: bool  # I(E) as the released code: raw classifier labels of the row match the person's
    element_plan_ok: bool  # the plan used the person's element


@dataclass(frozen=True)
class TrialOutcome:
    key: str
    rows: tuple[RowOutcome, ...]
    gap_correct: int
    gap_total: int
    object_correct: int
    object_total: int
    planning_time_s: float

    @property
    def shlp(self) -> float:
        """0.25 * sum over rows of I(D) * (I(D) + I(E)) for two rows; scaled by rows otherwise
        (I(E) as the released code: the row's raw classifier labels)."""
        return self._shlp([r.element_ok for r in self.rows])

    @property
    def shlp_plan(self) -> float:
        """As ``shlp`` with I(E) = the plan used the person's element."""
        return self._shlp([r.element_plan_ok for r in self.rows])

    def _shlp(self, element_ok: list[bool]) -> float:
        scores = [int(r.decision_ok) * (int(r.decision_ok) + int(e)) for r, e in zip(self.rows, element_ok)]
        return float(np.sum(scores)) / (2.0 * len(self.rows)) if self.rows else 0.0


def planned_rows(plan: HighLevelPlan) -> dict[int, tuple[str, str]]:
    """Per row: ("gap", index) or ("object", name) of the plan."""
    rows: dict[int, tuple[str, str]] = {}
    for k in plan.keypoints:
        if k.row is not None and k.row not in rows and k.action in ("gap", "move"):
            rows[k.row] = (GAP if k.action == "gap" else OBJECT, str(k.element))
    return rows


def score_trial(
    demo: Demonstration, plan: HighLevelPlan, *, faithful: bool, rows: Collection[int] | None = None
) -> TrialOutcome:
    """Compare ``plan`` (made for ``demo.scene``) with what the person did.

    Args:
        rows: score only these rows (and count only their gaps and obstacles in the gap and object
            accuracies); every row by default.
    """
    space = TaskSpace(demo.scene)
    gap_truth = np.array(gap_labels(demo, space, faithful=faithful)) > 0
    object_truth = np.array(object_labels(demo, space)) > 0
    gaps = [g for row in space.gaps for g in row]
    if rows is not None:
        gap_kept = np.array([g.row in rows for g in gaps], dtype=bool)
        members = {n for r in space.rows if r.index in rows for n in r.members}
        object_kept = np.array([n in members for n in space.obstacle_names], dtype=bool)
    else:
        gap_kept, object_kept = np.ones(len(gaps), dtype=bool), np.ones(len(object_truth), dtype=bool)
    gap_raw = np.array([plan.details.get("gap_scores", {}).get(f"{g.row}:{g.index}", -1.0) > 0 for g in gaps])
    object_raw = np.array(
        [plan.details.get("object_scores", {}).get(n, -1.0) > 0 for n in space.obstacle_names]
    )
    planned = planned_rows(plan)
    outcomes = []
    for decision in demo.decisions:
        if decision.decision == NONE:  # a row the person never crossed: no element, not scored
            continue
        if rows is not None and decision.row not in rows:
            continue
        hlp_decision, hlp_element = planned.get(decision.row, ("none", ""))
        if hlp_decision == GAP:
            mask = np.array([g.row == decision.row for g in gaps])
            element_ok = bool(np.array_equal(gap_raw[mask], gap_truth[mask]))
        elif hlp_decision == OBJECT:
            members = set(space.rows[decision.row - 1].members)
            mask = np.array([n in members for n in space.obstacle_names])
            element_ok = bool(np.array_equal(object_raw[mask], object_truth[mask]))
        else:
            element_ok = False
        decision_ok = hlp_decision == decision.decision
        outcomes.append(
            RowOutcome(
                decision.row,
                decision.decision,
                decision.element,
                hlp_decision,
                hlp_element,
                decision_ok,
                element_ok,
                decision_ok and hlp_element == decision.element,
            )
        )
    return TrialOutcome(
        demo.key,
        tuple(outcomes),
        int((gap_raw == gap_truth)[gap_kept].sum()),
        int(gap_kept.sum()),
        int((object_raw == object_truth)[object_kept].sum()),
        int(object_kept.sum()),
        plan.planning_time_s,
    )
