"""``StochasticTrajectoryOptimiser``: the STO (``hlp_drake.systems.low_level.sto.optimiser``) as a Drake block.

Input ports:
    ``scene`` (abstract ``Scene``): the scene the rollouts simulate.
    ``initial_trajectory`` (abstract ``PiecewisePolynomial`` of the robot's 11 positions, e.g.
        ``KeypointIk``'s ``trajectory``).
    ``alternative_trajectories`` (abstract tuple of them, best first, e.g. ``KeypointIk``'s; optional):
        evaluated only when the initial rollout fails, at most ``optimiser.alternatives`` used.

Output ports (computed once per input value, in Drake's cache):
    ``result`` (abstract ``StoResult``) and ``trajectory`` (the optimised ``PiecewisePolynomial``).

The HLP-initialised and the straight-line-initialised runs use this same block and settings; only
the initial trajectory (and the alternatives: the straight line has none) differs.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem
from pydrake.trajectories import PiecewisePolynomial

from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.sto.optimiser import EMPTY_RESULT, StoResult, optimise
from hlp_drake.systems.low_level.sto.pool import RolloutPool
from hlp_drake.systems.world.scene_source import declare_scene_input_port, scene_input, with_scene

if TYPE_CHECKING:
    from hlp_drake.systems.scenario import Scenario


class StochasticTrajectoryOptimiser(LeafSystem):
    """The STO as a Drake block (see the module's docstring for the ports).

    Args:
        scenario: the optimiser's and the world's settings (its scene is not used: the ``scene``
            input port's is).
        pool: the rollout workers, owned (and closed) by the caller.
    """

    def __init__(self, scenario: Scenario, pool: RolloutPool) -> None:
        super().__init__()
        self._scenario = scenario
        self._pool = pool
        self._scene = declare_scene_input_port(self)
        self._input = self.DeclareAbstractInputPort(
            name="initial_trajectory", model_value=AbstractValue.Make(PiecewisePolynomial())
        )
        self._alternatives = self.DeclareAbstractInputPort(
            name="alternative_trajectories", model_value=AbstractValue.Make(())
        )
        ticket = {
            self.input_port_ticket(port.get_index())
            for port in (self._scene, self._input, self._alternatives)
        }
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

    def get_scene_input_port(self):
        return self._scene

    def get_initial_trajectory_input_port(self):
        return self._input

    def get_alternatives_input_port(self):
        return self._alternatives

    def get_trajectory_output_port(self):
        return self._trajectory

    def get_result_output_port(self):
        return self._result

    def _calc_result(self, context, output) -> None:
        trajectory = self._input.Eval(context) if self._input.HasValue(context) else PiecewisePolynomial()
        if trajectory.get_number_of_segments() == 0:
            output.set_value(StoResult(EMPTY_RESULT.sequence, None, False, "no initial trajectory"))
            return
        scenario = with_scene(self._scenario, scene_input(self._scene, context))
        step = scenario.optimiser.step_duration
        initial = ControlSequence.from_trajectory(trajectory, step)

        def alternatives() -> list[ControlSequence]:
            if not self._alternatives.HasValue(context):
                return []
            return [ControlSequence.from_trajectory(t, step) for t in self._alternatives.Eval(context)]

        output.set_value(optimise(scenario, initial, self._pool, alternatives=alternatives))


__all__ = ["StochasticTrajectoryOptimiser"]
