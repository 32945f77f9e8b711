"""``LowLevelResult``: what every low-level planner returns, read alike by every consumer (the run,
the closed loop, the experiments' rows, the JSON) whatever planner made it."""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING

import numpy as np

from hlp_drake.systems.low_level.control_sequence import ControlSequence

if TYPE_CHECKING:
    from hlp_drake.systems.low_level.outcome import RolloutOutcome


@dataclass
class LowLevelResult:
    """The outcome of one low-level planning.

    Attributes:
        sequence: the commanded motion (the initial one if nothing better was found).
        outcome: the planner's own simulation of it, for planners that simulate (the STO's rollout:
            its cost, success, prediction of the objects, and its verification on the execution
            model); None otherwise.
        success: whether the planner accepts it (its own test: the STO's rollout passed).
        failure_reason: why not (None on success), one line.
        iterations: iterations run (0: the initial motion already succeeded, or none was run).
        rollouts: simulations of candidate motions, the initial one included (0: none).
        optimise_s: wall-clock time of the planning, s.
        costs: the current cost after each step (the initial rollout, the alternatives', every
            iteration), for planners with a cost.
        initial_cost: the initial motion's cost.
        start: which initial motion the result grew from: 0 the plan's, i >= 1 its i-th alternative.
        verifications: accepted candidates checked again (on the execution model, or in worlds
            with the objects displaced; not in ``rollouts``).
        rejected: of those, how many failed there.
        verify_s: wall-clock time of the verifications, s (part of ``optimise_s``).
        displaced_checks: simulations in worlds with the objects displaced.
        low_level: the planner's name (its registry name; empty when no planner ran).
        fallback: how the planner relaxed its problem to find this motion, and why ("": it did not;
            a kinematic planner: "contact allowed with every object (...)").
        notes: what else it did that a reader should know (e.g. a sub-goal it left out).
    """

    sequence: ControlSequence
    outcome: RolloutOutcome | None
    success: bool
    failure_reason: str | None
    iterations: int = 0
    rollouts: int = 0
    optimise_s: float = 0.0
    costs: list[float] = field(default_factory=list)
    initial_cost: float | None = None
    start: int = 0
    verifications: int = 0
    rejected: int = 0
    verify_s: float = 0.0
    displaced_checks: int = 0
    low_level: str = ""
    fallback: str = ""
    notes: tuple[str, ...] = ()

    def to_dict(self) -> dict:
        """The result as JSON-ready data: its counts, times and costs (not its motion)."""
        record = {
            f.name: getattr(self, f.name) for f in fields(self) if f.name not in ("sequence", "outcome")
        }
        outcome = self.outcome
        record.update(
            final_cost=None if outcome is None else outcome.cost,
            cost_terms={} if outcome is None else dict(outcome.terms),
            costs=list(self.costs),
            notes=list(self.notes),
        )
        return record


StoResult = LowLevelResult
"""The STO's name of ``LowLevelResult`` (kept for code written against it)."""

EMPTY_RESULT = LowLevelResult(
    ControlSequence(np.array([0.0, 1.0]), np.zeros((2, 0))), None, False, "not planned"
)
"""A placeholder result (an abstract port's model value; it commands no position)."""


def unplanned(sequence: ControlSequence, reason: str, low_level: str) -> LowLevelResult:
    """The result of a planning that did not run (``reason``): ``sequence`` commanded as it is."""
    return LowLevelResult(sequence, None, False, reason, low_level=low_level)


def held(start: np.ndarray | None) -> ControlSequence:
    """The robot held at its ``start`` positions for a second (no positions at all for None): what
    is commanded when there is no motion to plan."""
    if start is None or len(start) == 0:
        return EMPTY_RESULT.sequence
    start = np.asarray(start, dtype=float)
    return ControlSequence(np.array([0.0, 1.0]), np.vstack([start, start]))


__all__ = ["EMPTY_RESULT", "LowLevelResult", "StoResult", "held", "unplanned"]
