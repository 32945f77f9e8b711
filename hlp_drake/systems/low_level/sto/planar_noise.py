"""How the optimiser's planar noise moves a robot: a mobile base's x, y and yaw, or a fixed arm's tcp.

The STO family perturbs a sequence by a planar velocity per control step (vx, vy, heading rate;
``BaseNoise``). A mobile base takes it on its own joints, the arm keeping its motion. A fixed arm
has no base: the same velocity moves its tcp in the table plane and turns it about the vertical,
through the arm's Jacobian at each knot (damped least squares; the tcp's height and tilt held, the
fingers kept), so both kinds of robot explore the same planar detours round the obstacles.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from pydrake.multibody.tree import JacobianWrtVariable

from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.world.robot_description import RobotDescription
from hlp_drake.systems.world.start_pose import kinematic_robot

DAMPING = 1e-2
"""Damping of the least-squares inverse of the tcp's Jacobian (near singular postures stay bounded)."""


def planar_maps(robot: RobotDescription, knots: np.ndarray) -> np.ndarray:
    """(knots, positions, 3): per knot the joint displacement moving a fixed arm's tcp by (dx, dy,
    dheading), its height, tilt and fingers held."""
    plant, instance = kinematic_robot(robot)
    context = plant.CreateDefaultContext()
    tcp = plant.GetFrameByName(robot.tcp_frame, instance)
    world = plant.world_frame()
    arm = [plant.GetJointByName(name, instance).position_start() for name in robot.arm_joints]
    target = np.zeros((6, 3))  # (vx, vy, wz) -> the spatial velocity held to the plane
    target[3, 0] = target[4, 1] = target[2, 2] = 1.0
    maps = np.zeros((len(knots), knots.shape[1], 3))
    for k, q in enumerate(knots):
        plant.SetPositions(context, instance, q)
        jacobian = plant.CalcJacobianSpatialVelocity(
            context, JacobianWrtVariable.kQDot, tcp, np.zeros(3), world, world
        )[:, arm]
        inverse = jacobian.T @ np.linalg.inv(jacobian @ jacobian.T + DAMPING**2 * np.eye(6))
        maps[k][arm] = inverse @ target
    return maps


def planar_shift(
    robot: RobotDescription, sequence: ControlSequence
) -> Callable[[np.ndarray], ControlSequence]:
    """``sequence`` moved by an (n, 3) planar velocity: on a mobile base's joints, else through the
    arm's Jacobians at its knots (computed once here)."""
    if robot.mobile:
        return sequence.with_base_velocity
    maps = planar_maps(robot, sequence.knots)
    return lambda velocity: sequence.with_planar_velocity(velocity, maps)


__all__ = ["planar_maps", "planar_shift"]
