"""The cost of an STO rollout, a pure function of the states read every sample period.

``rollout_cost`` charges (``StoCost``): the goal distance at the end, objects off the table, robot-table
contact, high contact forces on objects, disturbance of the obstacles and of the target, ending next to
an obstacle, and the control effort. The paper's success test is part of it (``RolloutOutcome``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from hlp_drake.scene.model import Scene
from hlp_drake.systems.low_level.outcome import RolloutOutcome
from hlp_drake.systems.low_level.sto.config import StoConfig
from hlp_drake.systems.world.scene_models import off_table_mask
from hlp_drake.systems.world.success import ReachEnd, SuccessConfig, half_extent

BLOWN_UP_COST = 1.0e9


@dataclass(frozen=True)
class RolloutSamples:
    """A rollout's state read every sample period (T samples, m objects; object 0 is the target).

    Attributes:
        times: (T,) sample times, s.
        positions: (T, m, 3) object centres.
        tcp: (T, 3) tcp positions.
        max_force: (T,) largest contact force magnitude on any object, N.
        table_contact: (T,) whether the robot touched the table.
        blew_up: why the simulation is not to be trusted (None if it is sane).
        asleep: the objects asleep at the end (``rollout_sampler``).
        switches: how often the set of sleeping objects changed.
    """

    times: np.ndarray
    positions: np.ndarray
    tcp: np.ndarray
    max_force: np.ndarray
    table_contact: np.ndarray
    blew_up: str | None = None
    asleep: tuple[str, ...] = ()
    switches: int = 0


def rollout_cost(
    samples: RolloutSamples,
    scene: Scene,
    sto: StoConfig,
    *,
    success: SuccessConfig,
    tcp_height: float,
    effort: float,
    step_duration: float,
) -> RolloutOutcome:
    """The cost of a rollout from its samples (see ``StoCost`` for the terms), its success by the
    ``success`` test."""
    weights = sto.cost
    names = [obj.name for obj in scene.objects]
    simulated = float(samples.times[-1]) if len(samples.times) else 0.0
    if samples.blew_up is not None:
        return RolloutOutcome(
            BLOWN_UP_COST,
            {"blew_up": BLOWN_UP_COST},
            False,
            f"the simulation blew up: {samples.blew_up}",
            math.inf,
            simulated_s=simulated,
        )
    positions, tcp = samples.positions, samples.tcp
    per_step = (samples.times[1] - samples.times[0]) / step_duration if len(samples.times) > 1 else 1.0
    off = np.array([off_table_mask(p, scene.table) for p in positions])  # (T, m)
    final = positions[-1]
    start = positions[0]
    fallen = tuple(name for name, f in zip(names, off[-1]) if f)
    end = ReachEnd(tcp[-1], start, final, fallen, tcp_height)
    distance, shrink = end.distance(), sto.acceptance_margin
    inside = end.region_problem(scene, success, shrink=shrink) is None
    lifted = int(np.sum(final[:, 2] - start[:, 2] > success.max_lift))
    moved = np.sum((final[:, :2] - start[:, :2]) ** 2, axis=1)
    near = [
        name
        for name, obj, p, gone in zip(names[1:], scene.obstacles, final[1:], off[-1, 1:])
        if not gone and np.hypot(*(tcp[-1, :2] - p[:2])) <= half_extent(obj.size) + weights.near_distance
    ]
    excess = np.clip(samples.max_force - weights.force_limit, 0.0, None)
    terms = {
        "goal": distance if inside else weights.goal_weight * distance,
        "off_table": weights.off_table * (float(np.sum(off)) * per_step + lifted),
        "table_contact": weights.table_contact * float(np.sum(samples.table_contact)) * per_step,
        "force": weights.force_weight * float(np.sum(excess)) * per_step,
        "disturbance": weights.disturbance_weight * float(np.sum(moved[1:])),
        "target_disturbance": weights.target_disturbance_weight * float(moved[0]),
        "near_obstacle": weights.near_obstacle * len(near),
        "effort": weights.effort_weight * effort,
    }
    reason = end.problem(scene, success, shrink=shrink, accepting=True)
    if reason is not None and end.problem(scene, success) is None:
        reason = f"passes the success test, not as the planner accepts it (margin {shrink:g} m): {reason}"
    return RolloutOutcome(
        float(sum(terms.values())), terms, reason is None, reason, distance, fallen, simulated
    )
