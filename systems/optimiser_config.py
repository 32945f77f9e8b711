"""``StoConfig``: every setting of the stochastic trajectory optimiser (a ``Scenario``'s ``optimiser``).

In a scenario file it sits under ``optimiser:``::

    optimiser:
      samples: 8
      update: mppi
      noise: {vx: 0.04, vy: 0.04, yaw_rate: 0.02}
      cost: {goal_weight: 2000.0}
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

UPDATES = ("greedy", "mppi")


@dataclass(frozen=True)
class BaseNoise:
    """Standard deviations of the Gaussian noise added to the base's planar velocity per control step.

    The STO family perturbs the planar (x, y, yaw) velocity of the holonomic base; the arm keeps the
    joint motion of the sequence being improved, so the whole gripper shifts in the table plane.
    """

    vx: float = 0.04  # m/s
    vy: float = 0.04  # m/s
    yaw_rate: float = 0.02  # rad/s
    end_fraction: float = 0.25
    """Share of the noise's accumulated drift kept at the end of the sequence: the rest is taken out
    evenly over the steps, so a detour returns towards the end point the sequence aims at."""


@dataclass(frozen=True)
class StoCost:
    """Weights of the rollout cost (charged from the states at the ends of the control steps).

    Attributes:
        pregrasp_margin: the target is inside the gripper's pre-grasp region when the tcp is within
            its radius plus this (horizontally) and within this of the keypoint height, m.
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

    pregrasp_margin: float = 0.03
    goal_weight: float = 2000.0
    off_table: float = 300.0
    table_contact: float = 300.0
    force_limit: float = 60.0
    force_weight: float = 50.0
    disturbance_weight: float = 100.0
    target_disturbance_weight: float = 1000.0
    near_obstacle: float = 500.0
    near_distance: float = 0.01
    effort_weight: float = 0.05


@dataclass(frozen=True)
class StoConfig:
    """The stochastic trajectory optimiser (``hlp_drake.systems.optimiser``).

    Attributes:
        samples: noisy rollouts per iteration (K).
        max_iterations: iteration budget (an iteration = K rollouts + an update).
        time_budget_s: wall-clock budget of one optimisation; no iteration starts that is expected
            to end past it.
        step_duration: duration of one control step, s (the sequence's knots are this far apart).
        noise: base-velocity noise per step.
        update: "greedy" (keep the best noisy rollout) or "mppi" (cost-weighted mean of the noise).
        mppi_temperature: h in w_k = exp(-h (c_k - c_min) / (c_max - c_min)).
        workers: rollout processes (1: roll out in this process).
        seed: seed of the noise.
        rollout_time_step: plant time step of the rollouts, s (coarser than the execution's; the
            executed result is checked on the full model).
        reduced_model: roll out on reduced models in which objects nothing has come near yet are
            welded at their scene poses (fewer bodies and contacts; every cost term still covers every
            object, a welded one simply stays put); off: every rollout simulates every object.
        weld_clearance: in the reduced model, an object is freed ``weld_lookahead`` before the robot's
            collision geometry, following the commanded motion, first comes within this of it, m.
        weld_lookahead: see ``weld_clearance``, s.
        weld_margin: in the reduced model, when at a sample the robot or an object that has moved
            comes within this (plus the largest motion of a body since the previous sample) of a
            welded object, the rollout goes back to the previous sample and on with it freed, m.
        settle_s: simulated time after the last control step before the final state is read, s.
        sample_period: how often a rollout's state is read for the cost, s.
        max_object_speed: an object faster than this (m/s) means the simulation blew up.
        max_sink: an object's centre more than this below the table top while over it means it
            tunnelled into the table, m.
        cost: the cost weights.
        alternatives: when the initial sequence's rollout fails, roll out the planner's next this
            many distinct candidate plans once (the HLP's, by expected arm collision; the straight
            line has none) and go on from the best of them all (0: never).
    """

    samples: int = 8
    max_iterations: int = 20
    time_budget_s: float = 120.0
    step_duration: float = 0.5
    noise: BaseNoise = field(default_factory=BaseNoise)
    update: Literal["greedy", "mppi"] = "greedy"
    mppi_temperature: float = 10.0
    workers: int = 2
    seed: int = 0
    rollout_time_step: float = 0.005
    reduced_model: bool = True
    weld_clearance: float = 0.15
    weld_lookahead: float = 0.5
    weld_margin: float = 0.01
    settle_s: float = 0.5
    sample_period: float = 0.1
    max_object_speed: float = 5.0
    max_sink: float = 0.03
    cost: StoCost = field(default_factory=StoCost)
    alternatives: int = 3
