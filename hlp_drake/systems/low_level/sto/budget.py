"""What one optimisation may spend (``Budget``) and what it spent (``BudgetedRun``: its rollouts,
and the checks of a passing rollout: on the execution model after a reduced model's rollout, and in
the displaced worlds)."""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.outcome import RolloutOutcome
from hlp_drake.systems.low_level.sto.config import PERCEIVED_CHECKS, StoConfig
from hlp_drake.systems.low_level.sto.pool import RolloutPool
from hlp_drake.systems.world.uncertainty import displaced_scenes

MAX_ALTERNATIVES = 100
"""Alternatives an optimisation tries at most (``Budget.of``): all the initialiser offers."""

if TYPE_CHECKING:
    from hlp_drake.systems.low_level.outcome import RolloutStart
    from hlp_drake.systems.low_level.sto.spec import RolloutSpec


def displaced_checks(sto: StoConfig, *, perceived: bool = False) -> int:
    """``sto.displaced_checks``, or when it is None ``PERCEIVED_CHECKS`` on a ``perceived`` scene (seen
    by cameras) and 0 on the true one."""
    if sto.displaced_checks is not None:
        return sto.displaced_checks
    return PERCEIVED_CHECKS if perceived else 0


@dataclass(frozen=True)
class Budget:
    """How much one optimisation may do (``Budget.of(sto)`` by default; the receding-horizon
    controller gives its replans smaller ones).

    Attributes:
        samples: noisy rollouts per iteration.
        max_iterations, max_rollouts: the iteration and rollout budgets (no iteration starts that
            would pass ``max_rollouts``).
        time_budget_s: the optional wall-clock cap, s (0: none).
        alternatives: the initialiser's alternatives tried, at most, when the initial rollout fails
            (0: none).
        verify: verify a passing rollout on the execution model before declaring success.
        max_verifications: verifications at most.
        seed: seed of the noise.
        displaced_checks: worlds with displaced objects a verified sequence must pass in too
            (``displaced_checks``; 0: none).
    """

    samples: int
    max_iterations: int
    max_rollouts: int
    time_budget_s: float = 0.0
    alternatives: int = 0
    verify: bool = False
    max_verifications: int = 0
    seed: int = 0
    displaced_checks: int = 0

    @classmethod
    def of(cls, sto: StoConfig, *, perceived: bool = False) -> Budget:
        """The budget ``sto`` sets, on a scene seen by cameras if ``perceived``; every alternative
        the initialiser offers is tried (``planner.alternatives`` of them)."""
        return cls(
            sto.samples,
            sto.max_iterations,
            sto.max_rollouts,
            sto.time_budget_s,
            MAX_ALTERNATIVES,
            sto.verify,
            sto.max_verifications,
            sto.seed,
            displaced_checks(sto, perceived=perceived),
        )


class BudgetedRun:
    """One optimisation's rollouts and verifications, counted into its ``LowLevelResult``."""

    def __init__(
        self, spec: RolloutSpec, pool: RolloutPool, budget: Budget, start: RolloutStart | None
    ) -> None:
        self.spec, self.pool, self.budget, self.start = spec, pool, budget, start
        self.rollouts = self.verifications = self.rejected = 0
        self.verify_s = 0.0
        self._displaced: list[RolloutSpec] | None = None
        self._checks: list[RolloutSpec] | None = None

    def check_specs(self) -> list[RolloutSpec]:
        """The spec on the finer check model (``sto.check_step``; none when it is 0 or from a
        measured start), then its displaced copies."""
        if self._checks is None:
            step = self.spec.sto.check_step
            fine = []
            if step > 0 and self.start is None:
                fine = [replace(self.spec, model=self.spec.model.stepped(step))]
            self._checks = fine + self.displaced_specs()
        return self._checks

    def displaced_specs(self) -> list[RolloutSpec]:
        """The spec with its objects displaced, ``budget.displaced_checks`` times (none from a
        measured start: the closed loop's re-optimisations see where the objects are)."""
        if self._displaced is None:
            sto = self.spec.sto
            count = self.budget.displaced_checks if self.start is None else 0
            scenes = displaced_scenes(self.spec.scene, count, sto.displaced_sigma, sto.displaced_yaw_sigma)
            self._displaced = [replace(self.spec, scene=scene) for scene in scenes]
        return self._displaced

    def roll(self, sequences: list[ControlSequence]) -> list[RolloutOutcome]:
        """The rollouts of ``sequences`` (from the run's start)."""
        outcomes = self.pool.rollouts(self.spec, sequences, start=self.start)
        self.rollouts += len(sequences)
        return outcomes

    def settle(self, sequences: list[ControlSequence], outcomes: list[RolloutOutcome], order) -> None:
        """Check the passing outcomes in ``order`` (indices) until one holds (or the verifications
        run out): with the reduced model on the execution model, and in the displaced worlds. Each
        one that fails is replaced by the failing check's outcome, and once the verifications run
        out no passing rollout is trusted. A rollout on the execution model is its own verification."""
        if not self.budget.verify:
            return
        on_model = not self.spec.sto.reduced_model
        displaced = self.check_specs()  # the finer model's, then the displaced worlds
        fine = len(displaced) - len(self.displaced_specs())
        for i in order:
            if not outcomes[i].success:
                continue
            if on_model and not displaced:
                outcomes[i] = replace(outcomes[i], verification=outcomes[i])
                return
            if self.verifications >= self.budget.max_verifications:
                outcomes[i] = replace(
                    outcomes[i],
                    success=False,
                    failure_reason="passed its rollout, but the verifications ran out",
                )
                continue
            started = time.perf_counter()
            checked = self.pool.verifications(
                displaced if on_model else [self.spec, *displaced], sequences[i], start=self.start
            )
            verified, moved = (outcomes[i], checked) if on_model else (checked[0], checked[1:])
            self.verify_s += time.perf_counter() - started
            self.verifications += 1
            failed = next((k for k, o in enumerate(moved) if not o.success), None)
            if verified.success and failed is None:
                outcomes[i] = replace(outcomes[i], verification=verified)
                return
            self.rejected += 1
            outcomes[i] = (
                replace(
                    verified,
                    failure_reason=f"passed its rollout, failed its verification: {verified.failure_reason}",
                )
                if not verified.success
                else replace(
                    moved[failed],
                    failure_reason=(
                        f"passed its rollout, failed on the {self.spec.sto.check_step * 1000:g} ms check "
                        f"model: {moved[failed].failure_reason}"
                        if failed < fine
                        else f"passed its verification, failed with the objects displaced ({failed - fine + 1} "
                        f"of {len(moved) - fine}): {moved[failed].failure_reason}"
                    ),
                )
            )
