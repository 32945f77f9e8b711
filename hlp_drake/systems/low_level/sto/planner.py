"""``StoPlanner``: the stochastic trajectory optimiser as a low-level planner (the registry's ``sto``).

It samples the initial trajectory at its control steps (``step_duration``) and optimises the
sequence in rollouts of the scene in its world model (``optimise``); when the initial rollout
fails, it tries the initialiser's alternatives. ``replan`` re-optimises from a measured state
with a smaller budget: the receding-horizon controller's closed loop.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.protocol import LowLevelContext, LowLevelProblem, ReplanProblem
from hlp_drake.systems.low_level.result import LowLevelResult, held, unplanned
from hlp_drake.systems.low_level.sto.budget import Budget
from hlp_drake.systems.low_level.sto.config import StoConfig
from hlp_drake.systems.low_level.sto.optimiser import optimise
from hlp_drake.systems.low_level.sto.spec import RolloutSpec
from hlp_drake.systems.world.model import WorldModel
from hlp_drake.systems.world.success import SuccessConfig

if TYPE_CHECKING:
    from pydrake.trajectories import PiecewisePolynomial

    from hlp_drake.scene.model import Scene
    from hlp_drake.systems.low_level.sto.pool import RolloutPool


class StoPlanner:
    """The STO (see the module's docstring).

    Args:
        config: its settings.
        context: ``model``, the world model it rolls out in; ``pool``, the rollout workers (the
            caller's, who closes them); ``perceived``, whether it plans on a scene seen by cameras
            (then a passing sequence must also pass with the objects displaced, ``displaced_checks``).
    """

    kind = "sto"

    def __init__(self, config: StoConfig, context: LowLevelContext) -> None:
        if context.pool is None:
            raise ValueError("the STO rolls out: give it a RolloutPool")
        self.config, self.model, self.pool = config, context.model, context.pool
        self.perceived, self.success = context.perceived, context.success

    @classmethod
    def of(
        cls,
        config: StoConfig | None = None,
        *,
        pool: RolloutPool,
        model: WorldModel | None = None,
        perceived: bool = False,
        success: SuccessConfig | None = None,
    ) -> StoPlanner:
        """``StoPlanner`` from keyword arguments (defaults: a ``Scenario``'s settings and world model)."""
        context = LowLevelContext(model or WorldModel(), pool, perceived, success or SuccessConfig())
        return cls(config or StoConfig(), context)

    def spec(self, scene: Scene) -> RolloutSpec:
        """What its rollouts on ``scene`` simulate."""
        return RolloutSpec(scene, self.model, self.config, self.success)

    def as_commanded(self, trajectory: PiecewisePolynomial) -> ControlSequence:
        return ControlSequence.from_trajectory(trajectory, self.config.step_duration)

    def plan(self, problem: LowLevelProblem) -> LowLevelResult:
        if problem.initial.get_number_of_segments() == 0:
            start = None if problem.keyframes is None else problem.keyframes.start
            return unplanned(held(start), "no initial trajectory", self.kind)
        initial = self.as_commanded(problem.initial)

        def alternatives() -> list[ControlSequence]:
            return [self.as_commanded(t) for t in problem.alternatives()]

        budget = Budget.of(self.config, perceived=self.perceived)
        return optimise(
            self.spec(problem.scene), initial, self.pool, alternatives=alternatives, budget=budget
        )

    def replan(self, problem: ReplanProblem) -> LowLevelResult:
        """Re-optimise ``problem.initial`` from its measured ``start`` with its budget (its
        ``attempt``: the noise's seed), trying the first of its ``alternatives`` if the rollout
        fails; no verification (the execution goes on from there)."""
        budget = Budget(
            self.config.samples,
            problem.iterations,
            problem.rollouts,
            alternatives=0 if problem.alternatives is None else 1,
            seed=self.config.seed + 1 + problem.attempt,
        )
        spec, alternatives = self.spec(problem.scene), problem.alternatives
        return optimise(
            spec, problem.initial, self.pool, budget=budget, start=problem.start, alternatives=alternatives
        )


__all__ = ["StoPlanner"]
