"""The physics-based stochastic trajectory optimiser (STO).

``optimise(scenario, initial, pool)`` improves a ``ControlSequence`` as the STO family does
(the project's notes, section A): every iteration rolls out ``samples`` noisy copies of the current
sequence in the contact simulation (``RolloutWorld``), the noise being Gaussian per-step velocities
of the holonomic base; the update keeps the cheapest copy ("greedy") or the cost-weighted mean of
the noise, w_k = exp(-h (c_k - c_min) / (c_max - c_min)) ("mppi", rolled out once more); a candidate
replaces the current sequence only if its cost is lower (monotone acceptance). It stops at the first
successful rollout (target in the pre-grasp region, nothing fell), at ``max_iterations``, or when
the next iteration would end past ``time_budget_s``. Beyond the paper: when the initial sequence's
rollout fails and the planner has alternatives (the HLP's next candidate plans), they are rolled
out once each before the first iteration; a successful one ends the optimisation (the best-ranked
first), else the cheapest of them all becomes the current sequence.

Its Drake block is ``StochasticTrajectoryOptimiser`` (``hlp_drake.systems.optimiser_system``).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from hlp_drake.systems.control_sequence import ControlSequence
from hlp_drake.systems.optimiser_config import BaseNoise, StoConfig
from hlp_drake.systems.rollout_cost import RolloutOutcome
from hlp_drake.systems.rollout_pool import RolloutPool

if TYPE_CHECKING:
    from hlp_drake.systems.scenario import Scenario


@dataclass
class StoResult:
    """The outcome of one optimisation.

    Attributes:
        sequence: the best sequence found (the initial one if nothing was better).
        outcome: its rollout.
        success: whether its rollout passed the success test.
        failure_reason: why not (None on success), one line.
        iterations: iterations run (0: the initial sequence already succeeded, or none was run).
        rollouts: rollouts simulated, the initial one included.
        optimise_s: wall-clock time of the optimisation, s.
        costs: the current cost after the initial rollout, after the alternatives' rollouts (if
            any) and after every iteration.
        initial_cost: the initial sequence's cost.
        start: which sequence the result grew from: 0 the initial one, i >= 1 the i-th alternative.
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

    def to_dict(self) -> dict:
        return {
            "success": self.success,
            "failure_reason": self.failure_reason,
            "iterations": self.iterations,
            "rollouts": self.rollouts,
            "optimise_s": self.optimise_s,
            "initial_cost": self.initial_cost,
            "start": self.start,
            "final_cost": self.outcome.cost if self.outcome is not None else None,
            "cost_terms": dict(self.outcome.terms) if self.outcome is not None else {},
            "costs": list(self.costs),
        }


def sample_base_noise(
    rng: np.random.Generator, sequence: ControlSequence, noise: BaseNoise, samples: int
) -> np.ndarray:
    """(samples, n, 3) Gaussian base velocities (vx, vy, yaw rate) per step of ``sequence``.

    All but ``noise.end_fraction`` of each sample's accumulated drift is taken out evenly over the
    duration, so a noisy copy detours and comes back towards the sequence's end point.
    """
    sigma = np.array([noise.vx, noise.vy, noise.yaw_rate])
    velocity = rng.normal(size=(samples, sequence.num_steps, 3)) * sigma
    drift = np.einsum("knj,n->kj", velocity, sequence.steps)  # (samples, 3) displacement at the end
    return velocity - (1.0 - noise.end_fraction) * drift[:, None, :] / sequence.duration


def mppi_weights(costs: np.ndarray, temperature: float) -> np.ndarray:
    """Normalised weights exp(-h (c - c_min) / (c_max - c_min)) of the rollouts' costs."""
    costs = np.asarray(costs, dtype=float)
    spread = float(np.max(costs) - np.min(costs))
    if not np.isfinite(spread) or spread <= 0:
        return np.full(len(costs), 1.0 / len(costs))
    weights = np.exp(-temperature * (costs - np.min(costs)) / spread)
    return weights / np.sum(weights)


def optimise(
    scenario: Scenario,
    initial: ControlSequence,
    pool: RolloutPool,
    *,
    alternatives: Callable[[], Sequence[ControlSequence]] | None = None,
    progress: Callable[[int, float], None] | None = None,
) -> StoResult:
    """Improve ``initial`` on ``scenario``'s scene (see the module's docstring); never raises for a bad scene.

    Args:
        pool: the rollout workers (the caller's, who closes them).
        alternatives: returns the planner's other initial sequences, best first; called only if
            the initial rollout fails and ``optimiser.alternatives`` > 0 (the first that many are used).
        progress: called as ``progress(iteration, cost)`` after every iteration.
    """
    sto: StoConfig = scenario.optimiser
    started = time.perf_counter()
    collisions = pool.world(scenario).start_collisions
    if collisions:
        return StoResult(
            initial,
            None,
            False,
            f"the robot starts in collision with {', '.join(collisions)}",
            optimise_s=time.perf_counter() - started,
        )
    rng = np.random.default_rng(sto.seed)
    best = initial
    (outcome,) = pool.rollouts(scenario, [best])
    result = StoResult(
        best,
        outcome,
        outcome.success,
        outcome.failure_reason,
        rollouts=1,
        costs=[outcome.cost],
        initial_cost=outcome.cost,
    )
    if not result.success and alternatives is not None and sto.alternatives > 0:
        others = list(alternatives())[: sto.alternatives]
        if others:
            outcomes = pool.rollouts(scenario, others)
            result.rollouts += len(others)
            passed = [i for i, o in enumerate(outcomes) if o.success]
            i = passed[0] if passed else int(np.argmin([o.cost for o in outcomes]))
            if passed or outcomes[i].cost < outcome.cost:
                best, outcome, result.start = others[i], outcomes[i], i + 1
                result.sequence, result.outcome = best, outcome
                result.success, result.failure_reason = outcome.success, outcome.failure_reason
            result.costs.append(outcome.cost)
    last_iteration_s = 0.0
    while not result.success and result.iterations < sto.max_iterations:
        elapsed = time.perf_counter() - started
        if elapsed + last_iteration_s > sto.time_budget_s:
            result.failure_reason = f"{outcome.failure_reason} (time budget of {sto.time_budget_s:g} s spent)"
            break
        iteration_started = time.perf_counter()
        noise = sample_base_noise(rng, best, sto.noise, sto.samples)
        candidates = [best.with_base_velocity(v) for v in noise]
        outcomes = pool.rollouts(scenario, candidates)
        result.rollouts += len(candidates)
        if sto.update == "mppi":
            weights = mppi_weights(np.array([o.cost for o in outcomes]), sto.mppi_temperature)
            mean = best.with_base_velocity(np.einsum("k,knj->nj", weights, noise))
            candidates.append(mean)
            outcomes.extend(pool.rollouts(scenario, [mean]))
            result.rollouts += 1
        i = int(np.argmin([o.cost for o in outcomes]))
        if outcomes[i].cost < outcome.cost:  # monotone acceptance
            best, outcome = candidates[i], outcomes[i]
        result.iterations += 1
        result.sequence, result.outcome = best, outcome
        result.success, result.failure_reason = outcome.success, outcome.failure_reason
        result.costs.append(outcome.cost)
        last_iteration_s = time.perf_counter() - iteration_started
        if progress is not None:
            progress(result.iterations, outcome.cost)
    if not result.success and result.iterations >= sto.max_iterations and result.failure_reason:
        result.failure_reason = f"{result.failure_reason} (after {result.iterations} iterations)"
    result.optimise_s = time.perf_counter() - started
    return result


__all__ = ["StoResult", "mppi_weights", "optimise", "sample_base_noise"]
