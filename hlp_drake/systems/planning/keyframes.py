"""``Keyframes``: the IK result of a plan (per keypoint the robot's positions, a flag, a message)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from pydrake.geometry import SceneGraph
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, MultibodyPlant
from pydrake.systems.framework import DiagramBuilder

from hlp_drake.planner.plan import PlanKeypoint
from hlp_drake.systems.world.robot import add_robot
from hlp_drake.systems.world.robot_description import MOBILE_UR5, RobotDescription
from hlp_drake.systems.world.scene_models import BodiesConfig, ContactConfig, SceneModels, add_scene

if TYPE_CHECKING:
    from hlp_drake.scene.model import Scene


SKIPPABLE_ACTIONS = ("transit",)
"""The keypoints a trajectory can go without: a lifted waypoint the arm cannot reach (over the table
close before a fixed arm's pedestal) is left out, and the way goes straight on to the next keypoint."""


@dataclass(frozen=True)
class Keyframes:
    """The IK result of a plan.

    Attributes:
        keypoints: the plan's keypoints.
        positions: (n, positions) the robot's positions per keypoint (for a failed keypoint: the solver's last
            iterate, not to be executed).
        success: per keypoint, whether its IK succeeded.
        messages: per keypoint, "" on success, else why it failed (naming the keypoint).
        tcp_positions: (n, 3) tcp positions of ``positions`` (forward kinematics).
        start: the robot's start positions.
        problems: plan-level problems (no plan, wrong scene); empty normally.
        solve_time_s: wall-clock time of all the solves.
        candidate: 0 for the plan's own keyframes; k when a keypoint of the plan failed and these are
            its k-th alternative's, the first whose IK succeeds (``KeypointSolver.solve_first``).
        replaced: with a candidate, the failures of the plan it replaced.
    """

    keypoints: tuple[PlanKeypoint, ...]
    positions: np.ndarray
    success: tuple[bool, ...]
    messages: tuple[str, ...]
    tcp_positions: np.ndarray
    start: np.ndarray
    problems: tuple[str, ...] = ()
    solve_time_s: float = 0.0
    candidate: int = 0
    replaced: tuple[str, ...] = ()
    details: dict = field(default_factory=dict, compare=False)

    @property
    def ok(self) -> bool:
        """True when there are keyframes, all but skippable ones succeeded, and the plan had no problem."""
        return not self.problems and len(self.success) > 0 and not self._failed(skippable=False)

    @property
    def failures(self) -> list[str]:
        """Every problem and the failure messages of the keypoints the trajectory needs."""
        return [*self.problems, *self._failed(skippable=False)]

    @property
    def skipped(self) -> list[str]:
        """The failure messages of the skippable keypoints (``SKIPPABLE_ACTIONS``) the trajectory left out."""
        return self._failed(skippable=True)

    def _failed(self, *, skippable: bool) -> list[str]:
        return [
            message
            for message, ok, keypoint in zip(self.messages, self.success, self.keypoints)
            if not ok and (keypoint.action in SKIPPABLE_ACTIONS) == skippable
        ]

    @classmethod
    def empty(cls, start: np.ndarray, problem: str | None = None) -> Keyframes:
        n = len(start)
        return cls(
            keypoints=(),
            positions=np.zeros((0, n)),
            success=(),
            messages=(),
            tcp_positions=np.zeros((0, 3)),
            start=np.array(start, dtype=float),
            problems=() if problem is None else (problem,),
        )


def describe_keypoint(index: int, keypoint: PlanKeypoint) -> str:
    element = f" {keypoint.element}" if keypoint.element else ""
    x, y = keypoint.position
    return f"keypoint {index} ({keypoint.action}{element}) at ({x:.3f}, {y:.3f})"


# ``PlanningModel``: the robot and the table (and the scene's objects, welded), for kinematics.
class PlanningModel:
    """``robot`` + ``scene``'s table (+ its objects welded at their poses), for kinematics (IK, distance
    queries).

    A continuous plant (no dynamics) with its SceneGraph in a Diagram; it holds no context (make one
    with ``diagram.CreateDefaultContext()``).

    Attributes:
        diagram, plant, scene_graph: the model.
        robot: the robot's model instance.
        scene_models: the table's and objects' model instances.
    """

    def __init__(
        self,
        scene: Scene,
        *,
        robot: RobotDescription = MOBILE_UR5,
        contact: ContactConfig | None = None,
        bodies: BodiesConfig | None = None,
        with_objects: bool = True,
    ) -> None:
        builder = DiagramBuilder()
        plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
        self.robot = add_robot(plant, robot)
        self.scene_models: SceneModels = add_scene(
            plant,
            scene,
            contact=contact or ContactConfig(),
            bodies=bodies or BodiesConfig(),
            weld_objects=True,
            with_objects=with_objects,
        )
        plant.Finalize()
        self.diagram = builder.Build()
        self.diagram.set_name("planning_model")
        self.plant: MultibodyPlant = plant
        self.scene_graph: SceneGraph = scene_graph

    def robot_geometries(self) -> list:
        return [
            geometry
            for body in self.plant.GetBodyIndices(self.robot)
            for geometry in self.plant.GetCollisionGeometriesForBody(self.plant.get_body(body))
        ]

    def object_geometries(self) -> list:
        return [
            geometry
            for instance in self.scene_models.objects.values()
            for body in self.plant.GetBodyIndices(instance)
            for geometry in self.plant.GetCollisionGeometriesForBody(self.plant.get_body(body))
        ]
