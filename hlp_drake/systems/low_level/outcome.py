"""What a low-level planner that simulates says of a motion: where it predicts the objects and the
tcp (``Prediction``), where its run in a world ended (``FinalState``), its outcome there
(``RolloutOutcome``: cost, the success test, the fallen objects), and a start other than the
scene's (``RolloutStart``: a measured state, for re-planning in the closed loop). The STO's rollouts
give them; any planner that simulates may."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Prediction:
    """Where a rollout had the objects and the tcp at its samples (for comparing with the world later).

    Attributes:
        times: (T,) sample times from the rollout's start, s.
        positions: (T, m, 3) object centres (the target first).
        tcp: (T, 3) tcp positions.
    """

    times: np.ndarray
    positions: np.ndarray
    tcp: np.ndarray

    def at(self, t: float) -> tuple[np.ndarray, np.ndarray] | None:
        """(object centres, tcp) at the last sample at or before ``t`` (None before the first)."""
        k = int(np.searchsorted(self.times, t + 1e-9, side="right")) - 1
        return None if k < 0 else (self.positions[k], self.tcp[k])


@dataclass(frozen=True)
class FinalState:
    """Where a rollout on the execution model ended: the plant's model instances' positions and
    velocities (by name, ``RolloutWorld.states()``' form) at simulated time ``time``, in the world
    with key ``world_key`` (``hlp_drake.systems.world.model.world_key``). Its execution model is deterministic, so an execution
    of the same sequence from the same start in that world ends there too and may start from here.
    """

    world_key: str
    time: float
    states: dict[str, np.ndarray]


@dataclass(frozen=True)
class RolloutOutcome:
    """A rollout's cost and final state.

    Attributes:
        cost: total cost (``BLOWN_UP_COST`` if the simulation blew up).
        terms: the cost's terms by name.
        success: the paper's test at the end: target inside the pre-grasp region, nothing fell, sane.
        failure_reason: why not, one line (None on success).
        target_distance: final horizontal tcp-to-target distance, m.
        fallen: names of the objects off the table at the end.
        simulated_s, wall_s: simulated and wall-clock time of the rollout.
        asleep: the objects asleep at the end (empty: the full model).
        switches: how often the set of sleeping objects changed.
        prediction: the samples' object centres and tcp positions.
        verification: the same sequence's outcome on the execution model, when it was verified there
            and passed (its prediction is then the execution's own).
        final: the end state, for a rollout from the scene's start with every object awake (None otherwise).
    """

    cost: float
    terms: dict[str, float]
    success: bool
    failure_reason: str | None
    target_distance: float
    fallen: tuple[str, ...] = ()
    simulated_s: float = 0.0
    wall_s: float = 0.0
    asleep: tuple[str, ...] = ()
    switches: int = 0
    prediction: Prediction | None = None
    verification: RolloutOutcome | None = None
    final: FinalState | None = None


@dataclass(frozen=True)
class RolloutStart:
    """A rollout's start other than the scene's: the given model instances' positions and velocities
    (by name: the robot's and objects'; any other starts as in the scene) at time 0, in
    ``RolloutWorld.states()``' form (positions then velocities)."""

    states: dict[str, np.ndarray]


__all__ = ["FinalState", "Prediction", "RolloutOutcome", "RolloutStart"]
