"""The initialisers' blocks: ``HlpPlannerSystem`` (the human-like planner) and
``StraightLinePlanSystem`` (the straight line of the paper's baseline), each with an input ``scene``
and an output ``plan`` (``INITIALISERS`` names them)."""

from __future__ import annotations

from pydrake.common.value import AbstractValue
from pydrake.systems.framework import Context, LeafSystem

from hlp_drake.learners.bundled import default_models
from hlp_drake.learners.models import DecisionModels
from hlp_drake.planner import HighLevelPlan, PlanKeypoint, PlannerConfig, plan
from hlp_drake.scene.model import Scene
from hlp_drake.systems.world.scene_source import declare_scene_input_port, scene_input


# ``HlpPlannerSystem``: the human-like planner as a Drake LeafSystem (scene in, HighLevelPlan out).
class HlpPlannerSystem(LeafSystem):
    """Plans with the human-like planner (``hlp_drake.planner.plan``).

    Input port ``scene`` (abstract ``Scene``; from ``SceneFromPlant`` to plan on a plant's body
    poses). Output port ``plan`` (abstract ``HighLevelPlan``), in Drake's cache: planned again only
    when the scene changes (to plan at a fixed rate in a simulation, put Drake's ``ZeroOrderHold``
    on the scene).

    Args:
        models: decision models (default: the bundled ones).
        config: planner settings (default: the models' mode).
    """

    def __init__(self, *, models: DecisionModels | None = None, config: PlannerConfig | None = None) -> None:
        super().__init__()
        self._models = models or default_models()
        self._config = config or PlannerConfig(mode=self._models.mode_)
        self._scene_port = declare_scene_input_port(self)
        self._plan_port = self.DeclareAbstractOutputPort(
            name="plan",
            alloc=lambda: AbstractValue.Make(HighLevelPlan("", ())),
            calc=self._calc_plan,
            prerequisites_of_calc={self.all_input_ports_ticket()},
        )

    def get_scene_input_port(self):
        return self._scene_port

    def get_plan_output_port(self):
        return self._plan_port

    def _calc_plan(self, context: Context, output: AbstractValue) -> None:
        output.set_value(plan(scene_input(self._scene_port, context), self._models, self._config))


# The straight-line baseline's planner block: from the start straight to the target.
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


__all__ = ["HlpPlannerSystem", "StraightLinePlanSystem", "straight_line_plan"]
