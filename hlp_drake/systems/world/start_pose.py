"""The robot's start pose and the kinematics it is solved on (shared by the world, IK and the grasp).

Frames and start pose: the world frame is the scene's (z up, x into the table from the middle of its
front edge). A mobile base starts in front of the table facing +x, a fixed one stands where its
description puts it; at the start the gripper points along +x (horizontal approach; within the
keypoints' tolerance where that is out of reach), fingers opening along y, its tcp above
``scene.start`` at ``ik.height`` above the table top (``scene.start_yaw`` is not used: the gripper
faces +x).
"""

from __future__ import annotations

import functools
import math
from typing import TYPE_CHECKING

import numpy as np
from pydrake.math import RotationMatrix
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import ModelInstanceIndex
from pydrake.solvers import SnoptSolver, Solve, SolverOptions

from hlp_drake.errors import HlpError
from hlp_drake.scene.model import Scene
from hlp_drake.systems.world.robot import add_robot
from hlp_drake.systems.world.robot_description import MOBILE_UR5, RobotDescription

if TYPE_CHECKING:
    from hlp_drake.systems.planning.ik import IkConfig


def robot_position_names(robot: RobotDescription = MOBILE_UR5) -> tuple[str, ...]:
    """The joints of the robot's positions, in model-instance order: the actuated, then the mimics."""
    return robot.position_names


def robot_base_pose(
    scene: Scene, ik: IkConfig, robot: RobotDescription = MOBILE_UR5
) -> tuple[float, float, float]:
    """(x, y, yaw) of the base at the start: a fixed base's pose; a mobile base in front of the
    table, facing +x, behind ``scene.start``.

    A mobile base's centre stands ``ik.start_reach`` behind the start point on its line, but never
    closer to the table than ``ik.start_base_clearance`` (its front edge then stays at
    x <= -clearance, outside the table's footprint).
    """
    if not robot.mobile:
        return tuple(float(v) for v in robot.base.pose)
    start_x, start_y = scene.start
    x = min(start_x - ik.start_reach, -(robot.base.footprint[0] / 2.0 + ik.start_base_clearance))
    return (float(x), float(start_y), 0.0)


def tcp_rotation(approach_yaw: float = 0.0) -> RotationMatrix:
    """The gripper's keypoint orientation: tcp +z horizontal at heading ``approach_yaw`` (0: +x),
    tcp +y horizontal (fingers open sideways), tcp +x pointing down."""
    c, s = math.cos(approach_yaw), math.sin(approach_yaw)
    z = np.array([c, s, 0.0])
    y = np.array([-s, c, 0.0])
    return RotationMatrix(np.column_stack([np.cross(y, z), y, z]))


def tcp_keypoint_height(scene: Scene, ik: IkConfig) -> float:
    """World z of the tcp at the keypoints."""
    return scene.table.height + ik.height


@functools.lru_cache(maxsize=4)
def kinematic_robot(robot: RobotDescription = MOBILE_UR5) -> tuple[MultibodyPlant, ModelInstanceIndex]:
    """A robot-only continuous plant for kinematics (built once per robot, shared; do not modify it)."""
    plant = MultibodyPlant(time_step=0.0)
    instance = add_robot(plant, robot)
    plant.Finalize()
    return plant, instance


def _to_plant_order(
    plant: MultibodyPlant, instance: ModelInstanceIndex, values: dict[str, float]
) -> np.ndarray:
    """The robot's positions in ``plant``'s own order for ``instance``, from joint names."""
    starts = np.arange(plant.num_positions())
    instance_starts = plant.GetPositionsFromArray(instance, starts)
    local = {int(index): i for i, index in enumerate(instance_starts)}
    q = np.zeros(len(instance_starts))
    for name, value in values.items():
        q[local[plant.GetJointByName(name, instance).position_start()]] = value
    return q


def ik_solver_options(max_iterations: int) -> SolverOptions:
    options = SolverOptions()
    snopt = SnoptSolver().solver_id()
    options.SetOption(snopt, "Major iterations limit", int(max_iterations))
    options.SetOption(snopt, "Iterations limit", int(50 * max_iterations))
    return options


def start_configuration(
    scene: Scene,
    ik: IkConfig,
    plant: MultibodyPlant,
    instance: ModelInstanceIndex,
    robot: RobotDescription = MOBILE_UR5,
) -> np.ndarray:
    """The robot's start positions, in ``plant``'s order for ``instance`` (as ``SetPositions`` takes them).

    The base stands at ``robot_base_pose(scene, ik, robot)``; the arm (solved by IK on a robot-only
    kinematic model, seeded and regularised towards ``robot.home``; a fixed arm also from up to
    ``START_ATTEMPTS - 1`` seeded random postures) puts the tcp above
    ``scene.start`` at ``ik.height`` above the table top, pointing along +x with the fingers opening
    along y; the gripper is open. Where that exact orientation is out of reach (a start close in front
    of a fixed arm's pedestal, where the wrist cannot fold back far enough), the start takes the
    keypoints' own tolerance instead: the approach axis within ``ik.approach_tolerance`` of +x, the
    finger axis within ``ik.roll_tolerance`` of the horizontal.

    Raises:
        HlpError: the start point is out of the arm's reach from that base pose.
    """
    base = robot_base_pose(scene, ik, robot)
    if robot.mobile:  # solved relative to the base: one solve serves every start on the same line
        target = (round(scene.start[0] - base[0], 9), 0.0, round(tcp_keypoint_height(scene, ik), 9))
    else:
        target = (*(round(float(v), 9) for v in scene.start), round(tcp_keypoint_height(scene, ik), 9))
    arm = _start_arm(robot, target, ik.max_iterations) or _start_arm(
        robot, target, ik.max_iterations, (ik.approach_tolerance, ik.roll_tolerance)
    )
    if arm is None:
        where = "the base pose" if robot.mobile else f"robot {robot.name}'s base (robot.base.pose)"
        raise HlpError(
            f"scene {scene.name or '<unnamed>'}: the arm cannot put the tcp above the start "
            f"{tuple(scene.start)} at height {tcp_keypoint_height(scene, ik):.3f} m "
            f"from {where} {base}: out of its reach"
        )
    values = {**dict(zip(robot.base_joints, base)), **dict(zip(robot.arm_joints, arm, strict=True))}
    values.update({name: robot.gripper_open for name in robot.gripper_joints})
    return _to_plant_order(plant, instance, values)


START_ATTEMPTS = 12
"""Starts of a fixed arm's start-pose IK: its home, then seeded random postures within its limits."""
START_SEED = 0


@functools.lru_cache(maxsize=64)
def _start_arm(
    robot: RobotDescription,
    target: tuple[float, float, float],
    max_iterations: int,
    tolerance: tuple[float, float] | None = None,
) -> tuple[float, ...] | None:
    """Arm angles putting the tcp at ``target`` (a mobile base at the origin; a fixed one where it
    stands), horizontal along +x: exactly, or with ``tolerance`` = (the approach axis' largest angle
    from +x, the finger axis' from the horizontal), rad (cached)."""
    plant, instance = kinematic_robot(robot)
    context = plant.CreateDefaultContext()
    ik = InverseKinematics(plant, context, with_joint_limits=True)
    q = ik.q()
    seed = _to_plant_order(
        plant,
        instance,
        {
            **dict(
                zip(robot.base_joints + robot.arm_joints, (0.0,) * len(robot.base_joints) + tuple(robot.home))
            ),
            **{name: robot.gripper_open for name in robot.gripper_joints},
        },
    )
    fixed = np.full(len(seed), True)
    for name in robot.arm_joints:
        fixed[plant.GetJointByName(name, instance).position_start()] = False
    prog = ik.get_mutable_prog()
    prog.AddBoundingBoxConstraint(seed[fixed], seed[fixed], q[fixed])
    tcp = plant.GetFrameByName(robot.tcp_frame, instance)
    goal = np.array(target)
    world = plant.world_frame()
    ik.AddPositionConstraint(tcp, np.zeros(3), world, goal - 1e-4, goal + 1e-4)
    if tolerance is None:
        ik.AddOrientationConstraint(world, tcp_rotation(0.0), tcp, RotationMatrix(), 1e-3)
    else:
        approach, roll = tolerance
        ik.AddAngleBetweenVectorsConstraint(world, [1.0, 0.0, 0.0], tcp, [0.0, 0.0, 1.0], 0.0, approach)
        ik.AddAngleBetweenVectorsConstraint(
            world, [0.0, 0.0, 1.0], tcp, [0.0, 1.0, 0.0], math.pi / 2 - roll, math.pi / 2 + roll
        )
    prog.AddQuadraticErrorCost(np.eye(int(np.sum(~fixed))), seed[~fixed], q[~fixed])
    options = ik_solver_options(max_iterations)
    result = Solve(prog, seed, options)
    if not result.is_success() and not robot.mobile:  # a fixed arm: more starts, the same on every run
        rng = np.random.default_rng(START_SEED)
        lower = np.maximum(plant.GetPositionLowerLimits(), -math.pi)
        upper = np.minimum(plant.GetPositionUpperLimits(), math.pi)
        for _ in range(START_ATTEMPTS - 1):
            other = np.where(fixed, seed, rng.uniform(lower, upper))
            result = Solve(prog, other, options)
            if result.is_success():
                break
    if not result.is_success():
        return None
    solution = result.GetSolution(q)
    return tuple(
        float(solution[plant.GetJointByName(name, instance).position_start()]) for name in robot.arm_joints
    )
