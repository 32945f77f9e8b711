"""``StoConfig``: every setting of the stochastic trajectory optimiser, the low-level planner ``sto``
(a ``Scenario``'s ``planner.low_level`` with ``kind: sto``).

In a scenario file it sits under ``planner: {low_level: ...}``::

    planner:
      low_level:
        kind: sto
        samples: 8
        update: mppi
        noise: {vx: 0.04, vy: 0.04, yaw_rate: 0.02}
        cost: {goal_weight: 2000.0}
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Annotated, Literal

from hlp_drake.config.ranges import (
    MAX_DURATION,
    MAX_SEED,
    MAX_TIME_STEP,
    PERIOD,
    Count,
    NonNegativeFloat,
    Positive,
    PositiveFloat,
    Rule,
)
from hlp_drake.systems.low_level.protocol import LowLevelConfig

MAX_WORKERS = 64
"""Most rollout processes."""
FRACTION = Rule(lambda v: 0.0 <= v <= 1.0, "{where} must be in [0, 1], got {value}")
PERCEIVED_CHECKS = 2
"""``StoConfig.displaced_checks`` when it is None and the scene is perceived (``perception.source:
camera``): the 100-scene Table III at 9 objects, docs/perception.md."""


@dataclass(frozen=True)
class BaseNoise:
    """Standard deviations of the Gaussian noise added to the base's planar velocity per control step.

    The STO family perturbs the planar (x, y, yaw) velocity of the holonomic base; the arm keeps the
    joint motion of the sequence being improved, so the whole gripper shifts in the table plane.
    """

    vx: NonNegativeFloat = 0.04  # m/s
    vy: NonNegativeFloat = 0.04  # m/s
    yaw_rate: NonNegativeFloat = 0.02  # rad/s
    end_fraction: Annotated[float, FRACTION] = 0.25
    """Share of the noise's accumulated drift kept at the end of the sequence: the rest is taken out
    evenly over the steps, so a detour returns towards the end point the sequence aims at."""


@dataclass(frozen=True)
class StoCost:
    """Weights of the rollout cost (charged from the states at the ends of the control steps).

    Attributes:
        goal_weight: final cost per metre of tcp-to-pre-grasp-region distance outside the region.
        off_table: per object off the table (centre outside the top or below it), at every step.
        table_contact: per control step in which the robot touches the table (its edge or top).
        force_limit, force_weight: per newton of a contact force on an object above the limit.
        disturbance_weight: final, per square metre of the obstacles' summed squared displacement.
        target_disturbance_weight: final, per square metre of the target's squared displacement.
        near_obstacle: final, when the tcp ends within ``near_distance`` of an obstacle's centre
            line plus its half-size (the fingers would close on it).
        effort_weight: per (rad/s)^2 or (m/s)^2, times seconds, of the commanded joint velocities.
    """

    goal_weight: NonNegativeFloat = 2000.0
    off_table: NonNegativeFloat = 300.0
    table_contact: NonNegativeFloat = 300.0
    force_limit: NonNegativeFloat = 60.0
    force_weight: NonNegativeFloat = 50.0
    disturbance_weight: NonNegativeFloat = 100.0
    target_disturbance_weight: NonNegativeFloat = 1000.0
    near_obstacle: NonNegativeFloat = 500.0
    near_distance: NonNegativeFloat = 0.01
    effort_weight: NonNegativeFloat = 0.05


@dataclass(frozen=True)
class StoConfig(LowLevelConfig):
    """The stochastic trajectory optimiser (``hlp_drake.systems.low_level.sto.optimiser``).

    Attributes:
        kind: "sto".
        samples: noisy rollouts per iteration (K).
        max_iterations: iteration budget (an iteration = K rollouts + an update).
        max_rollouts: rollout budget of one optimisation, the initial and the alternatives'
            rollouts included: no iteration starts that would pass it. With ``max_iterations`` it
            decides when the optimiser gives up, so the same seed gives the same result on any
            machine, busy or idle, on 1 or N workers.
        time_budget_s: an optional wall-clock safety cap of one optimisation, s (0: none); no
            iteration starts that is expected to end past it. A result then depends on the machine.
        step_duration: duration of one control step, s (the sequence's knots are this far apart).
        noise: base-velocity noise per step.
        update: "greedy" (keep the best noisy rollout) or "mppi" (cost-weighted mean of the noise).
        mppi_temperature: h in w_k = exp(-h (c_k - c_min) / (c_max - c_min)).
        workers: rollout processes (1: roll out in this process).
        seed: seed of the noise.
        reduced_model: an approximation of the execution model for rollouts: let the objects sleep
            (their joints locked) while nothing comes near them, and again once they have come to
            rest with nothing near (fewer degrees of freedom and contacts; every cost term still
            covers every object; a passing rollout is then verified, see ``verify``); off (the
            default): the rollouts run on the execution model itself, every object awake.
        weld_clearance: an object is woken ``weld_lookahead`` before the robot's collision geometry,
            following the commanded motion, first comes within this of it, and goes back to sleep
            only with neither the robot nor a moving object this close, m.
        weld_lookahead: see ``weld_clearance``, s.
        weld_margin: when at a sample the robot or an awake object that has moved comes within this
            (plus the largest motion of a body since the previous sample) of a sleeping object, the
            rollout goes back to the previous sample and on with it awake, m.
        sleep_speed: an awake object slower than this at two samples in a row has come to rest, m/s.
        sample_period: how often a rollout's state is read for the cost, s (it ends ``success.settle_s``
            after the sequence) (the cost terms are per
            second; the reduced model's sleep checks' margins grow with the motion between samples).
        max_object_speed: an object faster than this (m/s) means the simulation blew up.
        max_sink: an object's centre more than this below the table top while over it means it
            tunnelled into the table, m.
        cost: the cost weights (``off_table`` is charged once more per object lifted off the table
            at the end).
        acceptance_margin: a rollout is accepted only if it passes the success test with the
            pre-grasp region shrunk by this, horizontally and vertically, m, and lifts no object
            (the world, finer than the rollouts' model, judges by the test itself; 5 mm: on Gen I,
            4 of the 10 plans accepted without it that failed in the world ended within 3 mm
            outside the region).
        verify: with ``reduced_model``, before declaring success, simulate a passing rollout's
            sequence again on the execution model (every object awake); only if it passes there too
            does the optimisation succeed, else that outcome (and cost) replaces the rollout's and
            the optimisation goes on. Without it, a rollout is the execution model's own: nothing
            to verify.
        max_verifications: verifications per optimisation at most (on the execution model, or in
            the ``displaced_checks`` worlds; they do not count in ``max_rollouts``). Once they are
            spent the optimisation ends, whatever rollouts are left (8: with 4, searches whose
            fifth candidate held ended at half their rollouts, see docs/perception.md).
        displaced_checks: a sequence that passes its verification counts only if it also passes
            on the execution model in this many worlds with every object displaced (seeded
            Gaussian offsets of ``displaced_sigma`` per axis and ``displaced_yaw_sigma``): a push
            whose outcome hinges on where an object stands to a fraction of a millimetre, as a
            perceived scene cannot promise, is rejected (0: off; None, the default:
            ``PERCEIVED_CHECKS`` on a perceived scene, ``perception.source: camera``, else 0; the
            initial optimisation only, not the closed loop's re-optimisations).
        check_step: a sequence that passes its rollout counts only if it also passes on the
            rollouts' model at this finer plant step, s (the contact geometry unchanged; 0: off;
            the initial optimisation only, like ``displaced_checks``; counted in ``verifications``).
            5 ms: of the plans accepted on 60 fresh scenes that failed in the reference world, it
            caught all but one (docs/results.md, "The world that judges").
        displaced_sigma: see ``displaced_checks``, m.
        displaced_yaw_sigma: see ``displaced_checks``, rad.
    """

    kind: Literal["sto"] = "sto"
    samples: Annotated[int, Count(1, 1000)] = 8
    max_iterations: Annotated[int, Count(1, 10_000)] = 20
    max_rollouts: Annotated[int, Count(1, 1_000_000)] = 100
    time_budget_s: NonNegativeFloat = 0.0
    step_duration: Annotated[float, PERIOD] = 0.5
    noise: BaseNoise = field(default_factory=BaseNoise)
    update: Literal["greedy", "mppi"] = "greedy"
    mppi_temperature: PositiveFloat = 10.0
    workers: Annotated[int, Count(1, MAX_WORKERS)] = 2
    seed: Annotated[int, Count(0, MAX_SEED)] = 0
    reduced_model: bool = False
    weld_clearance: PositiveFloat = 0.15
    weld_lookahead: Annotated[float, Positive(upper=MAX_DURATION, zero_ok=True)] = 0.5
    weld_margin: NonNegativeFloat = 0.01
    sleep_speed: NonNegativeFloat = 0.005
    sample_period: Annotated[float, PERIOD] = 0.2
    max_object_speed: PositiveFloat = 5.0
    max_sink: PositiveFloat = 0.03
    cost: StoCost = field(default_factory=StoCost)
    acceptance_margin: Annotated[float, Positive(upper=0.1, zero_ok=True)] = 0.005
    verify: bool = True
    max_verifications: Annotated[int, Count(0, 1000)] = 8
    displaced_checks: Annotated[int | None, Count(0, 100)] = None
    check_step: Annotated[float, Positive(upper=MAX_TIME_STEP, zero_ok=True)] = 0.005
    displaced_sigma: Annotated[float, Positive(upper=0.1, zero_ok=True)] = 0.001
    displaced_yaw_sigma: Annotated[float, Positive(upper=math.pi, zero_ok=True)] = math.radians(0.5)

    def problems(self, where: str) -> list[str]:
        """The rules across the fields (``where``: the section's path)."""
        margin, clearance = self.weld_margin, self.weld_clearance
        if not margin > clearance:
            return []
        return [f"{where}.weld_margin ({margin}) must not exceed {where}.weld_clearance ({clearance})"]
