"""``ObservedScenePlanner``: the planner's initial sequence again, on the scene as measured.

The receding-horizon controller's ``initialiser`` (``RecedingHorizonController``): on the observed
scene (its ``scene`` input: the plant's poses or the cameras' perception) it runs the planning
diagram's planner and push transfer, and solves the plan's keypoints from the robot's measured
positions on (``KeypointSolver.solve(start=...)``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from hlp_drake.systems.control_sequence import ControlSequence
from hlp_drake.systems.planning_diagram import make_planning_diagram
from hlp_drake.systems.scene_source import SCENE_PORT

if TYPE_CHECKING:
    from hlp_drake.learners.models import DecisionModels
    from hlp_drake.scene.model import Scene
    from hlp_drake.systems.scenario import Scenario


class ObservedScenePlanner:
    """The planner's initial sequence on an observed scene, from the robot's measured state (its 11
    positions then velocities; None when there is no plan or a keypoint's IK fails)."""

    def __init__(self, scenario: Scenario, *, models: DecisionModels | None = None) -> None:
        self._scenario = scenario
        self._diagram = make_planning_diagram(scenario, models=models)
        self._solver = self._diagram.GetSubsystemByName("keypoint_ik").solver

    def __call__(self, scene: Scene, robot: np.ndarray) -> ControlSequence | None:
        context = self._diagram.CreateDefaultContext()
        self._diagram.GetInputPort(SCENE_PORT).FixValue(context, scene)
        plan = self._diagram.GetOutputPort("robot_plan").Eval(context)
        plant_context = self._solver.plant_context(self._solver.new_context())
        keyframes = self._solver.solve(plant_context, plan, start=robot[: len(robot) // 2])
        if not keyframes.ok:
            return None
        trajectory = self._solver.trajectory(plant_context, keyframes)
        return ControlSequence.from_trajectory(trajectory, self._scenario.optimiser.step_duration)


__all__ = ["ObservedScenePlanner"]
