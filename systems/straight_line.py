"""The straight-line baseline's planner block: from the start straight to the target."""

from __future__ import annotations

from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem

from hlp_drake.planner import HighLevelPlan, PlanKeypoint
from hlp_drake.scene.model import Scene
from hlp_drake.systems.scene_source import declare_scene_input_port, scene_input


def straight_line_plan(scene: Scene) -> HighLevelPlan:
    """The baseline's initial plan: from the start straight to the target."""
    return HighLevelPlan(
        scene.name,
        (
            PlanKeypoint("start", (float(scene.start[0]), float(scene.start[1]))),
            PlanKeypoint("target", (float(scene.target.x), float(scene.target.y)), None, scene.target.name),
        ),
    )


class StraightLinePlanSystem(LeafSystem):
    """The straight-line baseline's planner block, with ``HlpPlannerSystem``'s ports: input ``scene``
    (abstract ``Scene``), output ``plan`` (abstract ``HighLevelPlan``)."""

    def __init__(self) -> None:
        super().__init__()
        self._scene_port = declare_scene_input_port(self)
        self._plan_port = self.DeclareAbstractOutputPort(
            name="plan",
            alloc=lambda: AbstractValue.Make(HighLevelPlan("", ())),
            calc=lambda context, output: output.set_value(
                straight_line_plan(scene_input(self._scene_port, context))
            ),
            prerequisites_of_calc={self.all_input_ports_ticket()},
        )

    def get_scene_input_port(self):
        return self._scene_port

    def get_plan_output_port(self):
        return self._plan_port
