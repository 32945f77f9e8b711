"""``RunListener``: what hears of a ``plan_and_execute`` run's stages as they happen."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from pydrake.trajectories import PiecewisePolynomial

    from hlp_drake.planner import HighLevelPlan
    from hlp_drake.systems.execution import ExecutionResult
    from hlp_drake.systems.keyframes import Keyframes
    from hlp_drake.systems.optimiser import StoResult
    from hlp_drake.systems.perception import Perception


class RunListener:
    """Hears of a run's stages as they happen (every method does nothing here; override what you need)."""

    def perceived(self, perception: Perception, seconds: float) -> None:
        """The cameras' frame is perceived (``seconds`` with the rendering; ``perception_s`` without)."""

    def planned(self, plan: HighLevelPlan, seconds: float) -> None:
        """The planner's plan is ready."""

    def solved(self, keyframes: Keyframes, trajectory: PiecewisePolynomial, seconds: float) -> None:
        """The robot plan's keyframes (IK) and the initial trajectory are ready."""

    def optimising(self) -> None:
        """The optimiser starts (its rollouts arrive through the pool's ``on_rollout``)."""

    def optimised(self, result: StoResult) -> None:
        """The optimiser is done."""

    def executing(self, duration: float) -> None:
        """The execution starts: ``duration`` simulated seconds (reach, settling, grasp)."""

    def simulated(self, t: float) -> None:
        """The execution has reached simulated time ``t``."""

    def finished(self, result: ExecutionResult) -> None:
        """The run is over."""


__all__ = ["RunListener"]
