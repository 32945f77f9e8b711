"""``ObservedScenePlanner``: the planner's initial sequence again, on the scene as measured.

The receding-horizon controller's ``initialiser`` (``RecedingHorizonController``): from the measured
model-instance states (``RolloutStart``'s form) it places the scenario's objects where they are
(``scene_at``), runs the planning diagram's planner and push transfer on that scene, and solves the
plan's keypoints from the robot's measured positions on (``KeypointSolver.solve(start=...)``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from pydrake.common.eigen_geometry import Quaternion
from pydrake.math import RigidTransform, RotationMatrix

from hlp_drake.systems.control_sequence import ControlSequence
from hlp_drake.systems.planning_diagram import make_planning_diagram
from hlp_drake.systems.robot import ROBOT_MODEL_NAME
from hlp_drake.systems.scene_source import SCENE_PORT, scene_at

if TYPE_CHECKING:
    from hlp_drake.learners.models import DecisionModels
    from hlp_drake.scene.model import Scene
    from hlp_drake.systems.scenario import Scenario


def measured_scene(template: Scene, states: dict[str, np.ndarray]) -> Scene:
    """``template`` with every object at its measured pose (a free body's positions: quaternion
    w, x, y, z, then x, y, z; objects without a state stay put)."""
    poses = {}
    for obj in template.objects:
        x = states.get(obj.name)
        if x is None:
            poses[obj.name] = RigidTransform(RotationMatrix.MakeZRotation(obj.yaw), [obj.x, obj.y, 0.0])
        else:
            q = np.asarray(x[:4], dtype=float)
            poses[obj.name] = RigidTransform(
                Quaternion(q / np.linalg.norm(q)), np.asarray(x[4:7], dtype=float)
            )
    return scene_at(template, poses)


class ObservedScenePlanner:
    """The planner's initial sequence on the measured scene, from the robot's measured positions
    (None when there is no plan or a keypoint's IK fails)."""

    def __init__(self, scenario: Scenario, *, models: DecisionModels | None = None) -> None:
        self._scenario = scenario
        self._diagram = make_planning_diagram(scenario, models=models)
        self._solver = self._diagram.GetSubsystemByName("keypoint_ik").solver

    def __call__(self, states: dict[str, np.ndarray]) -> ControlSequence | None:
        scene = measured_scene(self._scenario.scene, states)
        context = self._diagram.CreateDefaultContext()
        self._diagram.GetInputPort(SCENE_PORT).FixValue(context, scene)
        plan = self._diagram.GetOutputPort("robot_plan").Eval(context)
        plant_context = self._solver.plant_context(self._solver.new_context())
        robot = states[ROBOT_MODEL_NAME]
        keyframes = self._solver.solve(plant_context, plan, start=robot[: len(robot) // 2])
        if not keyframes.ok:
            return None
        trajectory = self._solver.trajectory(plant_context, keyframes)
        return ControlSequence.from_trajectory(trajectory, self._scenario.optimiser.step_duration)


__all__ = ["ObservedScenePlanner", "measured_scene"]
