"""``RobotPlanTransfer``: the human-like plan -> the pushing robot's waypoints, as a Drake block.

Input ports ``scene`` (abstract ``Scene``) and ``plan`` (abstract ``HighLevelPlan``, a person's
plan); output ports ``robot_plan`` (abstract ``HighLevelPlan``: ``push_transfer.robot_plan``, with
the actions ``ROBOT_ACTIONS``) and ``robot_alternatives`` (abstract tuple of ``HighLevelPlan``: the
robot plans of at most ``alternatives`` of the plan's other candidates, computed only when
evaluated). The clearances combine the ``transfer`` margins with the robot's sizes, read from its
model once (``gripper_geometry``).
"""

from __future__ import annotations

import functools
import math

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder, LeafSystem

from hlp_drake.planner import HighLevelPlan
from hlp_drake.systems.planning.config import DEFAULT_ALTERNATIVES
from hlp_drake.systems.world.robot import add_robot
from hlp_drake.systems.world.robot_description import MOBILE_UR5, RobotDescription
from hlp_drake.systems.world.scene_source import declare_scene_input_port, scene_input
from hlp_drake.transfer.push import robot_alternatives, robot_plan
from hlp_drake.transfer.rules import (
    SIZE_RESOLUTION,
    GripperGeometry,
    PushRules,
    TransferConfig,
    length,
    push_rules,
)


def _rounded_up(value: float) -> float:
    return length(math.ceil(value / SIZE_RESOLUTION - 1e-6) * SIZE_RESOLUTION)


def _extent(plant, scene_graph, context, bodies, frame) -> np.ndarray:
    """(2, 3) lower and upper corners, in ``frame``, of the box holding the bodies' collision geometry."""
    inspector = scene_graph.model_inspector()
    X_FW = frame.CalcPoseInWorld(context).inverse()
    corners = []
    signs = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], dtype=float)
    for body in bodies:
        X_FB = X_FW @ plant.EvalBodyPoseInWorld(context, body)
        for geometry in plant.GetCollisionGeometriesForBody(body):
            box = inspector.GetObbInGeometryFrame(geometry)
            X_FO = X_FB @ inspector.GetPoseInFrame(geometry) @ box.pose()
            corners += [X_FO @ (s * box.half_width()) for s in signs]
    corners = np.array(corners)
    return np.array([corners.min(axis=0), corners.max(axis=0)])


@functools.lru_cache(maxsize=4)
def gripper_geometry(robot: RobotDescription = MOBILE_UR5) -> GripperGeometry:
    """The robot's sizes, read from its model's collision geometry (once per robot): the fingers open
    (the way onto the target) and closed (the pushes), the palm (the other ``gripper_links``)."""
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    instance = add_robot(plant, robot)
    plant.Finalize()
    diagram = builder.Build()
    context = plant.GetMyMutableContextFromRoot(diagram.CreateDefaultContext())
    tcp = plant.GetFrameByName(robot.tcp_frame, instance)
    fingers = [plant.GetBodyByName(name, instance) for name in robot.finger_links]

    def fingers_at(opening: float) -> np.ndarray:
        for name in robot.gripper_joints:
            plant.GetJointByName(name, instance).set_translation(context, opening)
        return _extent(plant, scene_graph, context, fingers, tcp)

    closed_box = fingers_at(robot.gripper_closed)
    finger_box = fingers_at(robot.gripper_open)
    palm = [
        plant.GetBodyByName(name, instance) for name in robot.gripper_links if name not in robot.finger_links
    ]
    palm_box = _extent(plant, scene_graph, context, palm, tcp) if palm else closed_box
    flange = plant.GetFrameByName(robot.flange_frame, instance)
    offset = flange.CalcPose(context, tcp).translation()
    wrist = plant.GetBodyByName(robot.wrist_link, instance)
    wrist_box = _extent(plant, scene_graph, context, [wrist], flange)
    return GripperGeometry(
        tcp_offset=_rounded_up(float(np.linalg.norm(offset))),
        fingertip_reach=_rounded_up(float(finger_box[1, 2])),
        finger_half_width=_rounded_up(float(np.max(np.abs(finger_box[:, 1])))),
        wrist_radius=_rounded_up(float(np.max(wrist_box[1, :2]))),
        closed_half_width=_rounded_up(float(np.max(np.abs(closed_box[:, 1])))),
        palm_half_width=_rounded_up(float(np.max(np.abs(palm_box[:, 1])))),
        palm_front=length(max(math.floor(-palm_box[1, 2] / SIZE_RESOLUTION + 1e-6) * SIZE_RESOLUTION, 0.0)),
    )


class RobotPlanTransfer(LeafSystem):
    """Turns a human-like plan into the pushing robot's waypoints (see the module's docstring).

    Args:
        robot: the robot, whose sizes the clearances take (``gripper_geometry``).
        transfer: the transfer's margins (a ``Scenario``'s ``transfer``).
        alternatives: at most this many alternative robot plans (a ``Scenario``'s
            ``planner.alternatives``).
        pushes_closed: whether the hand pushes with its fingers closed (a ``Scenario``'s
            ``motion.closed_among_obstacles``) or open.
    """

    def __init__(
        self,
        *,
        robot: RobotDescription = MOBILE_UR5,
        transfer: TransferConfig | None = None,
        alternatives: int = DEFAULT_ALTERNATIVES,
        pushes_closed: bool = True,
    ) -> None:
        super().__init__()
        rules = push_rules(transfer or TransferConfig(), gripper_geometry(robot), closed=pushes_closed)
        limit = alternatives
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
