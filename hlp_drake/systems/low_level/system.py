"""``LowLevelPlannerSystem``: any low-level planner as a Drake block; ``StochasticTrajectoryOptimiser``,
the STO's.

Input ports:
    ``scene`` (abstract ``Scene``): the scene to plan on.
    ``keyframes`` (abstract ``Keyframes``, optional): the initialiser's keyframes (``KeypointIk``'s).
    ``initial_trajectory`` (abstract ``PiecewisePolynomial`` of the robot's positions, e.g.
        ``KeypointIk``'s ``trajectory``).
    ``alternative_trajectories`` (abstract tuple of them, best first, e.g. ``KeypointIk``'s; optional):
        evaluated only if the planner asks for them (the STO: when the initial rollout fails).

Output ports (computed once per input value, in Drake's cache):
    ``result`` (abstract ``LowLevelResult``) and ``trajectory`` (its commanded motion as a
    ``PiecewisePolynomial``).

The HLP-initialised and the straight-line-initialised runs use the same block and settings; only
the initial trajectory and keyframes (and the alternatives: the straight line has none) differ.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem
from pydrake.trajectories import PiecewisePolynomial

from hlp_drake.systems.low_level.protocol import LowLevelProblem
from hlp_drake.systems.low_level.result import EMPTY_RESULT, held, unplanned
from hlp_drake.systems.planning.keyframes import Keyframes
from hlp_drake.systems.world.scene_source import declare_scene_input_port, scene_input

if TYPE_CHECKING:
    from hlp_drake.systems.low_level.protocol import LowLevelPlanner
    from hlp_drake.systems.low_level.sto.config import StoConfig
    from hlp_drake.systems.low_level.sto.pool import RolloutPool
    from hlp_drake.systems.world.model import WorldModel
    from hlp_drake.systems.world.success import SuccessConfig


class LowLevelPlannerSystem(LeafSystem):
    """``planner`` as a Drake block (see the module's docstring for the ports)."""

    def __init__(self, planner: LowLevelPlanner) -> None:
        super().__init__()
        self._planner = planner
        self._scene = declare_scene_input_port(self)
        self._keyframes = self.DeclareAbstractInputPort(
            name="keyframes", model_value=AbstractValue.Make(Keyframes.empty(()))
        )
        self._input = self.DeclareAbstractInputPort(
            name="initial_trajectory", model_value=AbstractValue.Make(PiecewisePolynomial())
        )
        self._alternatives = self.DeclareAbstractInputPort(
            name="alternative_trajectories", model_value=AbstractValue.Make(())
        )
        ticket = {self.all_input_ports_ticket()}
        self._result = self.DeclareAbstractOutputPort(
            name="result",
            alloc=lambda: AbstractValue.Make(EMPTY_RESULT),
            calc=self._calc_result,
            prerequisites_of_calc=ticket,
        )
        self._trajectory = self.DeclareAbstractOutputPort(
            name="trajectory",
            alloc=lambda: AbstractValue.Make(PiecewisePolynomial()),
            calc=lambda context, output: output.set_value(
                self._result.Eval(context).sequence.to_trajectory()
            ),
            prerequisites_of_calc=ticket,
        )

    @property
    def planner(self) -> LowLevelPlanner:
        return self._planner

    def get_scene_input_port(self):
        return self._scene

    def get_keyframes_input_port(self):
        return self._keyframes

    def get_initial_trajectory_input_port(self):
        return self._input

    def get_alternatives_input_port(self):
        return self._alternatives

    def get_trajectory_output_port(self):
        return self._trajectory

    def get_result_output_port(self):
        return self._result

    def _calc_result(self, context, output) -> None:
        """The planner's result, or with no initial trajectory the robot held at its start."""
        keyframes = self._keyframes.Eval(context) if self._keyframes.HasValue(context) else None
        initial = self._input.Eval(context) if self._input.HasValue(context) else PiecewisePolynomial()
        if initial.get_number_of_segments() == 0:
            start = None if keyframes is None else keyframes.start
            output.set_value(unplanned(held(start), "no initial trajectory", self._planner.kind))
            return

        def alternatives() -> tuple:
            return self._alternatives.Eval(context) if self._alternatives.HasValue(context) else ()

        scene = scene_input(self._scene, context)
        output.set_value(self._planner.plan(LowLevelProblem(scene, keyframes, initial, alternatives)))


class StochasticTrajectoryOptimiser(LowLevelPlannerSystem):
    """The STO (``StoPlanner``) as a Drake block, with ``LowLevelPlannerSystem``'s ports.

    Args:
        config: its settings (default: a ``Scenario``'s).
        pool: the rollout workers, owned (and closed) by the caller.
        model: the world model it rolls out in (default: a ``Scenario``'s).
        perceived: it plans on a scene seen by cameras (``StoConfig.displaced_checks``).
        success: the success test of its rollouts (default: a ``Scenario``'s).
    """

    def __init__(
        self,
        config: StoConfig | None = None,
        *,
        pool: RolloutPool,
        model: WorldModel | None = None,
        perceived: bool = False,
        success: SuccessConfig | None = None,
    ) -> None:
        from hlp_drake.systems.low_level.sto.planner import StoPlanner

        super().__init__(StoPlanner.of(config, pool=pool, model=model, perceived=perceived, success=success))


__all__ = ["LowLevelPlannerSystem", "StochasticTrajectoryOptimiser"]
