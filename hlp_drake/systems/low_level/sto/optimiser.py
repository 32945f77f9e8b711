"""The physics-based stochastic trajectory optimiser (STO).

``optimise(spec, initial, pool)`` improves a ``ControlSequence`` as the STO family does
(the project's notes, section A): every iteration rolls out ``samples`` noisy copies of the current
sequence in the contact simulation (``RolloutWorld``), the noise being Gaussian per-step velocities
of the holonomic base; the update keeps the cheapest copy ("greedy") or the cost-weighted mean of
the noise, w_k = exp(-h (c_k - c_min) / (c_max - c_min)) ("mppi", rolled out once more); a candidate
replaces the current sequence only if its cost is lower (monotone acceptance). A rollout that passes
the success test (target in the pre-grasp region, nothing fell) succeeds: the rollouts run on the
execution model itself (with the reduced model, an approximation, it is simulated again there,
``verify``, and if it fails there that outcome replaces the rollout's and the optimisation goes on);
with ``displaced_checks`` it must also pass in copies of the scene
with every object displaced by about ``displaced_sigma`` (a push that only works to a fraction of
a millimetre is rejected). The budget counts rollouts and iterations (``max_rollouts``,
``max_iterations``), so a result does not depend on the machine's speed or load; seconds
(``time_budget_s``) are only an optional safety cap. Beyond the paper: when the initial sequence's
rollout fails and the planner has alternatives (the HLP's next candidate plans), they are rolled
out once each before the first iteration; a successful one ends the optimisation (the best-ranked
first), else the cheapest of them all becomes the current sequence.

Its Drake block is ``StochasticTrajectoryOptimiser`` (``hlp_drake.systems.low_level.system``).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np

from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.outcome import RolloutOutcome
from hlp_drake.systems.low_level.result import LowLevelResult
from hlp_drake.systems.low_level.sto.budget import Budget, BudgetedRun
from hlp_drake.systems.low_level.sto.config import BaseNoise, StoConfig
from hlp_drake.systems.low_level.sto.planar_noise import planar_shift
from hlp_drake.systems.low_level.sto.pool import RolloutPool, WorkersLost

if TYPE_CHECKING:
    from hlp_drake.systems.low_level.outcome import RolloutStart
    from hlp_drake.systems.low_level.sto.spec import RolloutSpec


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
    spec: RolloutSpec,
    initial: ControlSequence,
    pool: RolloutPool,
    *,
    alternatives: Callable[[], Sequence[ControlSequence]] | None = None,
    progress: Callable[[int, float], None] | None = None,
    budget: Budget | None = None,
    start: RolloutStart | None = None,
) -> LowLevelResult:
    """Improve ``initial`` on ``spec``'s scene (see the module's docstring); never raises for a bad
    scene, nor when the pool gives up on its dead workers (``WorkersLost``: the result fails with its reason).

    Args:
        pool: the rollout workers (the caller's, who closes them).
        alternatives: returns the planner's other initial sequences, best first; called only if
            the initial rollout fails and the budget has alternatives (the first that many are used).
        progress: called as ``progress(iteration, cost)`` after every iteration.
        budget: what the optimisation may spend (default: ``Budget.of(spec.sto)``).
        start: roll out from this state rather than the scene's (the receding-horizon controller's
            measured state; the robot's start is then not checked for collisions: it may be pushing).
    """
    budget = budget or Budget.of(spec.sto)
    started = time.perf_counter()
    collisions = () if start is not None else pool.world(spec).start_collisions
    if collisions:
        return LowLevelResult(
            initial,
            None,
            False,
            f"the robot starts in collision with {', '.join(collisions)}",
            optimise_s=time.perf_counter() - started,
            low_level=StoConfig.kind,
        )
    run = BudgetedRun(spec, pool, budget, start)
    result = LowLevelResult(initial, None, False, "not optimised", low_level=StoConfig.kind)
    try:
        _search(run, result, alternatives, progress, budget, started)
    except WorkersLost as error:  # the pool gave up on its dead workers: this optimisation failed
        result.success, result.failure_reason = False, str(error)
    result.rollouts, result.verifications, result.rejected = run.rollouts, run.verifications, run.rejected
    result.displaced_checks = run.verifications * len(run.displaced_specs())
    result.verify_s = run.verify_s
    result.optimise_s = time.perf_counter() - started
    return result


def _search(
    run: BudgetedRun,
    result: LowLevelResult,
    alternatives: Callable[[], Sequence[ControlSequence]] | None,
    progress: Callable[[int, float], None] | None,
    budget: Budget,
    started: float,
) -> None:
    """The optimisation proper, from ``result.sequence`` (the initial one), filling ``result``."""
    sto = run.spec.sto
    initial = result.sequence
    outcomes = run.roll([initial])
    run.settle([initial], outcomes, [0])  # may replace the outcome with its verification's
    (outcome,) = outcomes
    _accept(result, initial, outcome)
    result.costs, result.initial_cost = [outcome.cost], outcome.cost
    _try_alternatives(run, result, alternatives, budget)
    rng = np.random.default_rng(budget.seed)
    last_iteration_s = 0.0
    while not result.success and result.iterations < budget.max_iterations:
        spent = _budget_spent(run, result, budget, time.perf_counter() - started + last_iteration_s)
        if spent is not None:
            result.failure_reason = f"{result.outcome.failure_reason} ({spent} spent)"
            break
        iteration_started = time.perf_counter()
        _iterate(run, result, rng, sto, budget)
        last_iteration_s = time.perf_counter() - iteration_started
        if progress is not None:
            progress(result.iterations, result.outcome.cost)
        if budget.verify and run.verifications >= budget.max_verifications and not result.success:
            result.failure_reason = f"{result.failure_reason} (verifications spent)"
            break
    if not result.success and result.iterations >= budget.max_iterations and result.failure_reason:
        result.failure_reason = f"{result.failure_reason} (after {result.iterations} iterations)"


def _accept(result: LowLevelResult, sequence: ControlSequence, outcome: RolloutOutcome) -> None:
    """Make ``sequence`` (rolled out as ``outcome``) the result's."""
    result.sequence, result.outcome = sequence, outcome
    result.success, result.failure_reason = outcome.success, outcome.failure_reason


def _try_alternatives(
    run: BudgetedRun,
    result: LowLevelResult,
    alternatives: Callable[[], Sequence[ControlSequence]] | None,
    budget: Budget,
) -> None:
    """If the initial sequence failed, roll out the planner's other initial sequences (the budget's
    number of them, best first) and take the first that passes, or else the cheapest if it is cheaper."""
    if result.success or alternatives is None or budget.alternatives <= 0:
        return
    others = list(alternatives())[: budget.alternatives]
    if not others:
        return
    outcomes = run.roll(others)
    run.settle(others, outcomes, range(len(others)))
    passed = [i for i, o in enumerate(outcomes) if o.success]
    i = passed[0] if passed else int(np.argmin([o.cost for o in outcomes]))
    if passed or outcomes[i].cost < result.outcome.cost:
        result.start = i + 1
        _accept(result, others[i], outcomes[i])
    result.costs.append(result.outcome.cost)


def _budget_spent(
    run: BudgetedRun, result: LowLevelResult, budget: Budget, elapsed_next_s: float
) -> str | None:
    """What of the budget another iteration would overspend (``elapsed_next_s``: the time spent
    and the last iteration's), if anything."""
    per_iteration = budget.samples + (1 if run.spec.sto.update == "mppi" else 0)
    if run.rollouts + per_iteration > budget.max_rollouts:
        return f"rollout budget of {budget.max_rollouts}"
    if budget.time_budget_s > 0 and elapsed_next_s > budget.time_budget_s:
        return f"time budget of {budget.time_budget_s:g} s"
    return None


def _iterate(
    run: BudgetedRun, result: LowLevelResult, rng: np.random.Generator, sto: StoConfig, budget: Budget
) -> None:
    """One iteration: noisy planar velocities (``planar_shift``) round the result's sequence (and, with ``mppi``, their
    weighted mean) rolled out; the best is accepted if it passes or costs less (monotone)."""
    best, outcome = result.sequence, result.outcome
    noise = sample_base_noise(rng, best, sto.noise, budget.samples)
    shift = planar_shift(run.spec.model.robot, best)
    candidates = [shift(v) for v in noise]
    outcomes = run.roll(candidates)
    if sto.update == "mppi":
        weights = mppi_weights(np.array([o.cost for o in outcomes]), sto.mppi_temperature)
        mean = shift(np.einsum("k,knj->nj", weights, noise))
        candidates.append(mean)
        outcomes.extend(run.roll([mean]))
    run.settle(candidates, outcomes, np.argsort([o.cost for o in outcomes], kind="stable"))
    costs = [o.cost for o in outcomes]
    passing = [j for j, o in enumerate(outcomes) if o.success]  # verified, or none
    i = min(passing, key=costs.__getitem__) if passing else int(np.argmin(costs))
    if passing or outcomes[i].cost < outcome.cost:  # monotone acceptance, a pass first
        best, outcome = candidates[i], outcomes[i]
    result.iterations += 1
    _accept(result, best, outcome)
    result.costs.append(outcome.cost)


__all__ = ["Budget", "mppi_weights", "optimise", "sample_base_noise"]
