"""How an execution commands the robot: open loop (a ``TrajectorySource``) or closed loop (a
``RecedingHorizonController``), behind one interface the execution's reach and grasp use; the
grasp's settings (a ``Scenario``'s ``grasp``, ``GraspConfig``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Annotated

import numpy as np
from pydrake.math import RotationMatrix
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.solvers import Solve

from hlp_drake.config.ranges import MAX_DURATION, NonNegativeFloat, Positive, PositiveFloat
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.world.robot_description import MOBILE_UR5, RobotDescription
from hlp_drake.systems.world.scene_models import object_body
from hlp_drake.systems.world.start_pose import ik_solver_options, kinematic_robot

if TYPE_CHECKING:
    from pydrake.multibody.plant import MultibodyPlant
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import Context
    from pydrake.systems.primitives import TrajectorySource

    from hlp_drake.systems.execution.receding_horizon import RecedingHorizonController

PHASE = Positive(upper=MAX_DURATION)
"""The time of a grasp phase, s."""


@dataclass(frozen=True)
class GraspConfig:
    """The grasp after a successful reach: slide the tcp onto the target's centre, close the
    fingers, then lift the tcp straight up.

    Attributes:
        align: before closing, slide the open hand level until the tcp is over the target's centre as
            the world shows it at the reach's end (a wrist camera's last correction): the reach passes
            with the tcp up to ``success``'s tolerance off it, more than short fingers close round.
        align_s: time of that slide, s.
        close_s: time to close the fingers, s.
        lift_height: how far the tcp rises, m.
        lift_s: time of the lift, s.
        hold_s: time held at the top before the check, s.
        held_height: the grasp held when the target rose at least this far, m.
    """

    align: bool = True
    align_s: Annotated[float, PHASE] = 0.5
    close_s: Annotated[float, PHASE] = 1.0
    lift_height: NonNegativeFloat = 0.10
    lift_s: Annotated[float, PHASE] = 1.5
    hold_s: Annotated[float, Positive(upper=MAX_DURATION, zero_ok=True)] = 0.5
    held_height: PositiveFloat = 0.05

    @property
    def duration(self) -> float:
        """The grasp's simulated time at most, s."""
        return (self.align_s if self.align else 0.0) + self.close_s + self.lift_s + self.hold_s


class OpenLoopCommand:
    """``sequence`` played from time 0 by ``source``."""

    def __init__(self, source: TrajectorySource, sequence: ControlSequence) -> None:
        self._source, self._sequence = source, sequence

    def end(self, root_context: Context) -> float:
        """When the commanded reach ends, s of simulated time."""
        return self._sequence.duration

    def final(self, root_context: Context) -> np.ndarray:
        """The reach's last knot (the robot's positions)."""
        return self._sequence.knots[-1]

    def then(self, root_context: Context, t0: float, times: np.ndarray, knots: np.ndarray) -> None:
        """After holding the final knot, go through ``knots`` at ``t0 + times`` (e.g. the grasp)."""
        offset = t0 - self._sequence.duration
        self._source.UpdateTrajectory(
            self._sequence.followed_by(
                np.concatenate([[offset], offset + times]), np.vstack([self.final(root_context), knots])
            )
        )


class ClosedLoopCommand:
    """The sequence ``controller`` commands (re-optimised as the execution goes)."""

    def __init__(self, controller: RecedingHorizonController) -> None:
        self._controller = controller

    def end(self, root_context: Context) -> float:
        record = self._controller.record(root_context)
        return record.t0 + record.sequence.duration

    def final(self, root_context: Context) -> np.ndarray:
        return self._controller.record(root_context).sequence.knots[-1]

    def then(self, root_context: Context, t0: float, times: np.ndarray, knots: np.ndarray) -> None:
        sequence = ControlSequence(
            np.concatenate([[0.0], times]), np.vstack([self.final(root_context), knots])
        )
        self._controller.command(root_context, sequence, t0)


__all__ = ["ClosedLoopCommand", "GraspConfig", "OpenLoopCommand"]


# The grasp after a reach: close the fingers round the target, lift it, and check that it held.
def moved_configuration(
    q: np.ndarray,
    robot: RobotDescription = MOBILE_UR5,
    *,
    by: tuple[float, float, float] = (0.0, 0.0, 0.0),
    level_to: tuple[float, float] | None = None,
    max_iterations: int = 200,
) -> np.ndarray | None:
    """Robot positions with the tcp moved ``by`` from where it is at ``q`` (first, if given, level to
    the world point ``level_to``: same height), same orientation, the base and the fingers
    unchanged; None if the arm cannot."""
    plant, instance = kinematic_robot(robot)
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, instance, q)
    tcp = plant.GetFrameByName(robot.tcp_frame, instance)
    pose = tcp.CalcPoseInWorld(context)
    ik = InverseKinematics(plant, context, with_joint_limits=True)
    fixed = [*robot.base_columns, *robot.finger_columns]
    prog = ik.get_mutable_prog()
    prog.AddBoundingBoxConstraint(q[fixed], q[fixed], ik.q()[fixed])
    target = pose.translation().copy()
    if level_to is not None:
        target[:2] = level_to
    target += by
    ik.AddPositionConstraint(tcp, np.zeros(3), plant.world_frame(), target - 1e-3, target + 1e-3)
    ik.AddOrientationConstraint(plant.world_frame(), pose.rotation(), tcp, RotationMatrix(), 0.05)
    prog.AddQuadraticErrorCost(np.eye(len(q)), q, ik.q())
    result = Solve(prog, q, ik_solver_options(max_iterations))
    return result.GetSolution(ik.q()) if result.is_success() else None


def grasp_knots(
    q_end: np.ndarray,
    grasp: GraspConfig,
    robot: RobotDescription = MOBILE_UR5,
    *,
    centre: tuple[float, float] | None = None,
) -> tuple[np.ndarray, np.ndarray] | None:
    """Times (after the reach's end) and robot positions of the grasp: slide the open hand level
    onto the target's ``centre`` (world x, y; if given and ``grasp.align``, where the arm can),
    close the fingers, lift the tcp by ``grasp.lift_height``, hold. None if the lift has no IK
    solution."""
    aligned = None
    if grasp.align and centre is not None:
        aligned = moved_configuration(np.asarray(q_end, dtype=float), robot, level_to=centre)
    start = np.array(q_end if aligned is None else aligned, dtype=float)
    closed = start.copy()
    closed[list(robot.finger_columns)] = robot.gripper_closed
    lifted = (
        moved_configuration(closed, robot, by=(0.0, 0.0, grasp.lift_height))
        if grasp.lift_height > 0
        else closed
    )
    if lifted is None:
        return None
    phases = [grasp.close_s, grasp.lift_s, max(grasp.hold_s, 1e-3)]
    knots = [closed, lifted, lifted]
    if aligned is not None:
        phases, knots = [grasp.align_s, *phases], [aligned, *knots]
    return np.cumsum(phases), np.vstack(knots)


def advance_through_reach(
    simulator: Simulator, command: OpenLoopCommand | ClosedLoopCommand, *, settle_s: float
) -> float:
    """Simulate to the end of the commanded reach, then ``settle_s`` more (``success.settle_s``, as a
    rollout settles); return that time. A closed
    loop's re-plan may move the end while the simulation goes there: later (it goes on), or earlier
    than the time already simulated (the robot has held the reach's last pose since; the settling
    ends no earlier than now: going back would be Drake's "boundary_time >= context time" failure)."""
    root = simulator.get_mutable_context()
    end = command.end(root)
    while root.get_time() < end:
        simulator.AdvanceTo(end)
        end = command.end(root)
    settled = max(end + settle_s, root.get_time())
    simulator.AdvanceTo(settled)
    return settled


def grasp_and_lift(
    simulator: Simulator,
    command: OpenLoopCommand | ClosedLoopCommand,
    t0: float,
    *,
    plant: MultibodyPlant,
    target: str,
    grasp: GraspConfig,
    robot: RobotDescription = MOBILE_UR5,
) -> bool:
    """Slide onto the target, close the fingers and lift (``grasp``, from ``t0``, the reach's end
    pose); whether the object ``target`` of ``plant`` rose with the gripper."""
    root = simulator.get_mutable_context()
    body = object_body(plant, target)
    plant_context = plant.GetMyContextFromRoot(root)
    centre = body.EvalPoseInWorld(plant_context).translation()
    knots = grasp_knots(command.final(root), grasp, robot, centre=(float(centre[0]), float(centre[1])))
    if knots is None:
        return False
    times, knots = knots
    command.then(root, t0, times, knots)
    z0 = centre[2]
    simulator.AdvanceTo(t0 + times[-1])
    return bool(body.EvalPoseInWorld(plant_context).translation()[2] - z0 >= grasp.held_height)
