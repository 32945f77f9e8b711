"""``RobotPlanTransfer``: the human-like plan -> the pushing robot's waypoints, as a Drake block.

Input ports ``scene`` (abstract ``Scene``) and ``plan`` (abstract ``HighLevelPlan``, a person's
plan); output ports ``robot_plan`` (abstract ``HighLevelPlan``: ``push_transfer.robot_plan``, with
the actions ``ROBOT_ACTIONS``) and ``robot_alternatives`` (abstract tuple of ``HighLevelPlan``: the
robot plans of at most ``optimiser.alternatives`` of the plan's other candidates, computed only when
evaluated). The clearances combine the scenario's ``transfer`` margins with the robot's sizes,
read from its model once (``transfer_geometry``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem

from hlp_drake.planner import HighLevelPlan
from hlp_drake.systems.world.scene_source import declare_scene_input_port, scene_input
from hlp_drake.transfer.push import robot_alternatives, robot_plan
from hlp_drake.transfer.rules import PushRules, gripper_geometry, push_rules

if TYPE_CHECKING:
    from hlp_drake.systems.scenario import Scenario


class RobotPlanTransfer(LeafSystem):
    """Turns a human-like plan into the pushing robot's waypoints (see the module's docstring)."""

    def __init__(self, scenario: Scenario) -> None:
        super().__init__()
        rules = push_rules(scenario.transfer, gripper_geometry())
        limit = scenario.optimiser.alternatives
        self._rules = rules
        self._scene_port = declare_scene_input_port(self)
        self._plan_port = self.DeclareAbstractInputPort(
            name="plan", model_value=AbstractValue.Make(HighLevelPlan("", ()))
        )
        ticket = {self.all_input_ports_ticket()}
        self._out_port = self.DeclareAbstractOutputPort(
            name="robot_plan",
            alloc=lambda: AbstractValue.Make(HighLevelPlan("", ())),
            calc=lambda context, output: output.set_value(
                robot_plan(self._plan_port.Eval(context), scene_input(self._scene_port, context), rules)
            ),
            prerequisites_of_calc=ticket,
        )
        self._alternatives_port = self.DeclareAbstractOutputPort(
            name="robot_alternatives",
            alloc=lambda: AbstractValue.Make(()),
            calc=lambda context, output: output.set_value(
                robot_alternatives(
                    self._plan_port.Eval(context), scene_input(self._scene_port, context), rules, limit
                )
            ),
            prerequisites_of_calc=ticket,
        )

    @property
    def rules(self) -> PushRules:
        """The clearances the transfer works with."""
        return self._rules

    def get_scene_input_port(self):
        return self._scene_port

    def get_plan_input_port(self):
        return self._plan_port

    def get_robot_plan_output_port(self):
        return self._out_port

    def get_robot_alternatives_output_port(self):
        return self._alternatives_port
