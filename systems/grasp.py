"""The grasp after a reach: close the fingers round the target, lift it, and check that it held."""

from __future__ import annotations

import numpy as np
from pydrake.math import RotationMatrix
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.solvers import Solve

from hlp_drake.systems.control_sequence import BASE_COLUMNS
from hlp_drake.systems.robot import GRIPPER_CLOSED, GRIPPER_JOINTS, GRIPPER_MIMIC_JOINTS, TCP_FRAME
from hlp_drake.systems.start_pose import ik_solver_options, kinematic_robot, robot_position_names
from hlp_drake.systems.world_settings import GraspConfig

_NAMES = robot_position_names()
FINGER_COLUMNS = [_NAMES.index(name) for name in GRIPPER_JOINTS + GRIPPER_MIMIC_JOINTS]


def lifted_configuration(q: np.ndarray, height: float, *, max_iterations: int = 200) -> np.ndarray | None:
    """Robot positions (11) with the tcp ``height`` higher than at ``q``, same orientation, the base
    and the fingers unchanged; None if the arm cannot."""
    plant, robot = kinematic_robot()
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, robot, q)
    tcp = plant.GetFrameByName(TCP_FRAME, robot)
    pose = tcp.CalcPoseInWorld(context)
    ik = InverseKinematics(plant, context, with_joint_limits=True)
    fixed = [*BASE_COLUMNS, *FINGER_COLUMNS]
    prog = ik.get_mutable_prog()
    prog.AddBoundingBoxConstraint(q[fixed], q[fixed], ik.q()[fixed])
    target = pose.translation() + np.array([0.0, 0.0, height])
    ik.AddPositionConstraint(tcp, np.zeros(3), plant.world_frame(), target - 1e-3, target + 1e-3)
    ik.AddOrientationConstraint(plant.world_frame(), pose.rotation(), tcp, RotationMatrix(), 0.05)
    prog.AddQuadraticErrorCost(np.eye(len(q)), q, ik.q())
    result = Solve(prog, q, ik_solver_options(max_iterations))
    return result.GetSolution(ik.q()) if result.is_success() else None


def grasp_knots(q_end: np.ndarray, grasp: GraspConfig) -> tuple[np.ndarray, np.ndarray] | None:
    """Times (after the reach's end) and robot positions of the grasp: close the fingers at the end
    pose, lift the tcp by ``grasp.lift_height``, hold. None if the lift has no IK solution."""
    closed = np.array(q_end, dtype=float)
    closed[FINGER_COLUMNS] = GRIPPER_CLOSED
    lifted = lifted_configuration(closed, grasp.lift_height) if grasp.lift_height > 0 else closed
    if lifted is None:
        return None
    times = np.cumsum([grasp.close_s, grasp.lift_s, max(grasp.hold_s, 1e-3)])
    return times, np.vstack([closed, lifted, lifted])
