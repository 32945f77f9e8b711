"""``ClosedLoopConfig``: the settings of closed-loop execution (a ``Scenario``'s ``closed_loop``), the
receding-horizon controller's (``hlp_drake.systems.execution.receding_horizon``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated

from hlp_drake.config.ranges import PERIOD, Count, NonNegativeFloat, PositiveFloat


@dataclass(frozen=True)
class ClosedLoopConfig:
    """The receding-horizon controller of closed-loop execution (``receding_horizon``).

    Attributes:
        enabled: execute closed loop (``--execution closed``); False plays the optimised sequence.
        replan_period: simulated time between two re-optimisations, s.
        iterations, rollouts: the budget of each re-optimisation (its iterations and rollouts).
        replan_distance: an object this far from where the current plan's rollout put it has
            "moved far": the controller asks for a new initial sequence (the planner's, on the
            observed scene) and optimises from it, the remainder of the current one its alternative, m.
        track_distance: while every observed object is within this of where the initial sequence's
            verification on the execution model had it, that verified sequence is on track and is
            kept without re-optimising (0: always re-optimise), m.
        max_rollouts: the re-optimisations' rollouts in all, so an execution the controller cannot
            rescue ends: once spent, the commanded sequence plays to its end without re-optimising.
    """

    enabled: bool = False
    replan_period: Annotated[float, PERIOD] = 0.5
    iterations: Annotated[int, Count(0, 10_000)] = 1
    rollouts: Annotated[int, Count(1, 1_000_000)] = 9
    replan_distance: PositiveFloat = 0.05
    track_distance: NonNegativeFloat = 0.005
    max_rollouts: Annotated[int, Count(1, 100_000_000)] = 300


__all__ = ["ClosedLoopConfig"]
