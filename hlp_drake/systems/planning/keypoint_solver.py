"""``KeypointSolver``: a plan's keypoints -> robot keyframes (IK) -> a joint-space trajectory.

Each keypoint's IK (SNOPT) runs on a planning model of the robot and the table, built once (the
scene's objects play no part: pushing them is allowed). Constraints:

* the tcp at the keypoint's (x, y) and ``ik.height`` above the table top (within
  ``ik.position_tolerance``), or the keypoint's own height for lifted waypoints;
* the approach axis (tcp +z) within ``ik.approach_tolerance`` of world +x and the finger axis (tcp
  +y) within ``ik.roll_tolerance`` of horizontal: the horizontal grasp of the start configuration;
* joint limits, the gripper kept open, the base within its workspace (its front at most
  ``ik.base_under_table`` past the table's front edge, its centre within the table's width plus
  ``ik.base_lateral_margin``);
* at least ``ik.table_clearance`` between the robot and the table top and between the robot's own links.

The cost keeps each keyframe near the previous one (and, with the robot's ``approach_weight``, the
approach axis near +x). A keypoint is solved from up to ``ik.attempts``
seeds (the previous keyframe; it with the base moved along with the tcp; the start posture moved
to the keypoint; a continuation along the tcp's straight line) and checked by forward kinematics;
a keypoint that fails is reported in ``Keyframes`` and skipped by the trajectory (the next keypoint
is seeded from the last success). The solver holds no state: the caller gives it a context.
"""

from __future__ import annotations

import math
import time
from collections.abc import Iterable
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
from pydrake.geometry import CollisionFilterDeclaration, GeometrySet
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.solvers import Solve
from pydrake.systems.framework import Context
from pydrake.trajectories import PiecewisePolynomial

from hlp_drake.planner.plan import HighLevelPlan, PlanKeypoint
from hlp_drake.systems.planning.config import IkConfig, MotionConfig
from hlp_drake.systems.planning.keyframes import Keyframes, PlanningModel, describe_keypoint
from hlp_drake.systems.world.robot_description import MOBILE_UR5, RobotDescription
from hlp_drake.systems.world.scene_models import BodiesConfig, ContactConfig
from hlp_drake.systems.world.start_pose import ik_solver_options, start_configuration, tcp_keypoint_height
from hlp_drake.transfer.push import TRANSFERRED

if TYPE_CHECKING:
    from hlp_drake.scene.model import Scene

START_MATCH_TOLERANCE = 1e-3
"""A "start" keypoint this close (m) to ``scene.start`` uses the start configuration without IK."""
POSTURE_WEIGHT = 0.05
"""Weight of the pull of the arm's joints towards their start posture, against 1 for the step."""
FK_CHECK_FACTOR = 2.0
"""A solution whose tcp is farther than this times ``ik.position_tolerance`` from its target fails."""
CONTINUATION_STEPS = 4
"""Steps of the continuation seed along the straight tcp line to a keypoint (``_continued``)."""
GRASP_ACTIONS = ("approach", "target")
"""Keypoint actions reached with the gripper open (``motion.closed_among_obstacles``)."""


def _grandparents(plant, robot) -> list[tuple]:
    """(body, its parent's parent) for every body of model instance ``robot`` that has one."""
    parent = {}
    for index in plant.GetJointIndices(robot):
        joint = plant.get_joint(index)
        parent[joint.child_body().index()] = joint.parent_body().index()
    return [(plant.get_body(child), plant.get_body(parent[p])) for child, p in parent.items() if p in parent]


class KeypointSolver:
    """Solves a plan's keypoints on ``scene``'s table from its start (see the module's docstring).

    Args:
        scene: the table and the start (its objects play no part).
        robot: the robot.
        ik: the IK's settings (and the start pose's).
        motion: the trajectory's timing.
        contact, bodies: how the table becomes a body (default: a ``Scenario``'s).
    """

    def __init__(
        self,
        scene: Scene,
        *,
        robot: RobotDescription = MOBILE_UR5,
        ik: IkConfig | None = None,
        motion: MotionConfig | None = None,
        contact: ContactConfig | None = None,
        bodies: BodiesConfig | None = None,
    ) -> None:
        self._scene = scene
        self._ik = ik = ik or IkConfig()
        self._motion = motion or MotionConfig()
        self._model = PlanningModel(scene, robot=robot, contact=contact, bodies=bodies, with_objects=False)
        self._plant, self._robot = plant, instance = self._model.plant, self._model.robot
        self._robot_description = description = robot
        self._tcp = plant.GetFrameByName(description.tcp_frame, instance)
        if plant.num_positions() != plant.num_positions(instance):
            raise RuntimeError("the planning model must have no positions besides the robot's")
        self._start = start_configuration(scene, ik, plant, instance, description)
        self._names = description.position_names
        self._index = {name: plant.GetJointByName(name, instance).position_start() for name in self._names}
        if list(self._index.values()) != list(range(len(self._names))):
            raise RuntimeError(f"unexpected position order of the robot: {self._index}")
        self._velocity_limits = np.array(
            [plant.GetJointByName(name, instance).velocity_upper_limits()[0] for name in self._names]
        )
        self._lower = plant.GetPositionLowerLimits().copy()
        self._upper = plant.GetPositionUpperLimits().copy()
        table = scene.table
        self._base = [self._index[name] for name in description.base_joints]
        if self._base:  # a mobile base's workspace
            x, y, yaw = self._base
            self._upper[x] = ik.base_under_table - description.base.footprint[0] / 2.0
            y_limit = table.width / 2.0 + ik.base_lateral_margin
            self._lower[y], self._upper[y] = -y_limit, y_limit
            self._lower[yaw], self._upper[yaw] = -ik.base_max_yaw, ik.base_max_yaw
        self._gripper = [self._index[name] for name in description.gripper_joints]
        for i in self._gripper:  # keep the gripper as at the start (open)
            self._lower[i] = self._upper[i] = self._start[i]
        self._height = tcp_keypoint_height(scene, ik)
        self._options = ik_solver_options(ik.max_iterations)

    def new_context(self) -> Context:
        """A context of the planning model for the solves (they write the robot's positions into it).

        Pushing objects is allowed, so the model has none; the distance constraint is robot-vs-table
        and robot-vs-robot, less the links one joint apart (the plant's own filter) or two (by
        design within a few mm, e.g. forearm and wrist 2), which this context's filter hides.
        """
        plant, model = self._plant, self._model
        context = model.diagram.CreateDefaultContext()
        declaration = CollisionFilterDeclaration()
        for body, grandparent in _grandparents(plant, self._robot):
            declaration.ExcludeBetween(
                GeometrySet(plant.GetCollisionGeometriesForBody(body)),
                GeometrySet(plant.GetCollisionGeometriesForBody(grandparent)),
            )
        model.scene_graph.collision_filter_manager(
            model.scene_graph.GetMyMutableContextFromRoot(context)
        ).Apply(declaration)
        return context

    def plant_context(self, context: Context) -> Context:
        """The plant's part of a ``new_context``."""
        return self._plant.GetMyMutableContextFromRoot(context)

    @property
    def scene(self) -> Scene:
        return self._scene

    @property
    def planning_model(self) -> PlanningModel:
        return self._model

    @property
    def start(self) -> np.ndarray:
        """The robot's start positions."""
        return self._start.copy()

    def tcp_position(self, plant_context: Context, q: np.ndarray) -> np.ndarray:
        """World position of the tcp at robot positions ``q`` (set in ``plant_context``)."""
        self._plant.SetPositions(plant_context, self._robot, q)
        return self._tcp.CalcPoseInWorld(plant_context).translation().copy()

    def solve(
        self, plant_context: Context, plan: HighLevelPlan, start: np.ndarray | None = None
    ) -> Keyframes:
        """The keyframes of ``plan``, solved in ``plant_context`` (the plant's part of ``new_context()``).

        Args:
            start: the robot's positions at the plan's "start" keypoint (default: the start
                configuration; the receding-horizon controller's plans start where the robot is).
        """
        first = self._start if start is None else np.asarray(start, dtype=float)
        if plan.scene and self._scene.name and plan.scene != self._scene.name:
            return Keyframes.empty(
                self._start, f"the plan is for scene {plan.scene!r}, this KeypointIk for {self._scene.name!r}"
            )
        if any(k.action == "move" for k in plan.keypoints) and not plan.details.get(TRANSFERRED):
            return Keyframes.empty(
                first,
                "the plan's moves are a person's (the obstacles' centres): put a "
                "RobotPlanTransfer between the planner and KeypointIk",
            )
        if not plan.ok:
            return Keyframes.empty(first, f"no plan: {plan.reason or 'fewer than two keypoints'}")
        started = time.perf_counter()
        positions, success, messages = [], [], []
        previous = first
        for index, keypoint in enumerate(plan.keypoints):
            if start is not None and keypoint.action == "start":
                q, message = first.copy(), ""
            else:
                q, message = self._solve_keypoint(plant_context, index, keypoint, previous)
            positions.append(q)
            success.append(message == "")
            messages.append(message)
            if message == "":
                previous = q
        positions = np.array(positions)
        return Keyframes(
            keypoints=tuple(plan.keypoints),
            positions=positions,
            success=tuple(success),
            messages=tuple(messages),
            tcp_positions=np.array([self.tcp_position(plant_context, q) for q in positions]),
            start=first.copy(),
            solve_time_s=time.perf_counter() - started,
        )

    def solve_first(
        self, plant_context: Context, plans: Iterable[HighLevelPlan], start: np.ndarray | None = None
    ) -> Keyframes:
        """The keyframes of the first of ``plans`` (a plan, then its alternatives) whose IK succeeds
        (``Keyframes.candidate``: its index, ``replaced``: the first plan's failures); else the first
        plan's. A plan with a keypoint the robot cannot reach (a push start close before a fixed arm's
        pedestal) so gives way to the next candidate; a plan-level problem does not. ``plans`` is
        read past the first only when the first fails (a generator defers the alternatives)."""
        remaining = iter(plans)
        first = self.solve(plant_context, next(remaining), start)
        if first.ok or first.problems:
            return first
        for index, plan in enumerate(remaining, start=1):
            keyframes = self.solve(plant_context, plan, start)
            if keyframes.ok:
                return replace(keyframes, candidate=index, replaced=tuple(first.failures))
        return first

    def _target(self, keypoint: PlanKeypoint) -> np.ndarray:
        height = self._height if keypoint.height is None else self._scene.table.height + keypoint.height
        return np.array([keypoint.position[0], keypoint.position[1], height], dtype=float)

    def _shifted(
        self, plant_context: Context, reference: np.ndarray, target: np.ndarray
    ) -> np.ndarray | None:
        """``reference`` with a mobile base moved by the tcp's offset to ``target`` (clipped to the
        bounds); None for a fixed base."""
        if not self._base:
            return None
        shifted = reference.copy()
        shift = target - self.tcp_position(plant_context, reference)
        shifted[self._base[0]] += shift[0]
        shifted[self._base[1]] += shift[1]
        return np.clip(shifted, self._lower, self._upper)

    def _continued(
        self, plant_context: Context, previous: np.ndarray, target: np.ndarray
    ) -> np.ndarray | None:
        """The posture reached by solving ``CONTINUATION_STEPS - 1`` evenly spaced points of the
        straight tcp line from ``previous`` towards ``target`` (without the clearance constraint),
        each from the last; None if one fails. A far keypoint may need the arm to unfold while the
        base stops at its bounds, which SNOPT does not find in one solve from a folded seed (a
        straight line from a Generalization II start)."""
        q, start = previous.copy(), self.tcp_position(plant_context, previous)
        for fraction in np.linspace(0.0, 1.0, CONTINUATION_STEPS + 1)[1:-1]:
            point = start + fraction * (target - start)
            _, q, feasible = self._solve(*self._program(plant_context, point, q, clearance=False), q)
            if not feasible:
                return None
        return q

    def _solve(self, program, variables, seed: np.ndarray) -> tuple:
        """(SNOPT's result, the solution, whether it meets every constraint) from ``seed``. SNOPT
        often stops at its iteration limit on a point that meets every constraint: such an iterate
        counts when the constraints check out."""
        result = Solve(program, seed, self._options)
        solution = result.GetSolution(variables)
        return (
            result,
            solution,
            result.is_success() or program.CheckSatisfied(program.GetAllConstraints(), solution, 1e-6),
        )

    def _program(
        self, plant_context: Context, target: np.ndarray, previous: np.ndarray, *, clearance: bool
    ) -> tuple:
        """The IK program of one keypoint: (program, decision variables)."""
        ik_config = self._ik
        tolerance = ik_config.position_tolerance
        world = self._plant.world_frame()
        ik = InverseKinematics(self._plant, plant_context, with_joint_limits=False)
        q = ik.q()
        prog = ik.get_mutable_prog()
        prog.AddBoundingBoxConstraint(self._lower, self._upper, q)
        ik.AddPositionConstraint(self._tcp, np.zeros(3), world, target - tolerance, target + tolerance)
        ik.AddAngleBetweenVectorsConstraint(
            world, [1.0, 0.0, 0.0], self._tcp, [0.0, 0.0, 1.0], 0.0, ik_config.approach_tolerance
        )
        ik.AddAngleBetweenVectorsConstraint(
            world,
            [0.0, 0.0, 1.0],
            self._tcp,
            [0.0, 1.0, 0.0],
            math.pi / 2 - ik_config.roll_tolerance,
            math.pi / 2 + ik_config.roll_tolerance,
        )
        if self._robot_description.approach_weight > 0.0:
            ik.AddAngleBetweenVectorsCost(
                world, [1.0, 0.0, 0.0], self._tcp, [0.0, 0.0, 1.0], self._robot_description.approach_weight
            )
        if clearance:
            ik.AddMinimumDistanceLowerBoundConstraint(
                ik_config.table_clearance, ik_config.table_clearance + 0.05
            )
        prog.AddQuadraticErrorCost(np.eye(len(previous)), previous, q)
        # A weak pull towards the start posture of the arm keeps it from folding up over many keypoints.
        arm = [self._index[name] for name in self._robot_description.arm_joints]
        prog.AddQuadraticErrorCost(POSTURE_WEIGHT * np.eye(len(arm)), self._start[arm], q[arm])
        return prog, q

    def _solve_keypoint(
        self, plant_context: Context, index: int, keypoint: PlanKeypoint, previous: np.ndarray
    ) -> tuple[np.ndarray, str]:
        """(positions, "") on success, else (the best iterate, the failure message).

        Seeds, in order, up to ``ik.attempts``: the previous keyframe; the solution of the same
        program without the clearance constraint (from the previous keyframe); the previous
        keyframe with the base moved along with the tcp; the start posture moved likewise; the
        end of a continuation along the straight tcp line (``_continued``), from which the keypoint
        is solved with the cost pulling towards that posture instead of the previous keyframe.
        """
        target = self._target(keypoint)
        start_distance = np.hypot(*np.subtract(keypoint.position, self._scene.start))
        if keypoint.action == "start" and start_distance <= START_MATCH_TOLERANCE:
            return self._start.copy(), ""
        tolerance = self._ik.position_tolerance
        prog, q = self._program(plant_context, target, previous, clearance=True)
        best, reasons = previous.copy(), []

        def seeds():  # (seed, program, its variables)
            yield previous.copy(), prog, q
            loose, loose_q = self._program(plant_context, target, previous, clearance=False)
            result = Solve(loose, previous, self._options)
            if result.is_success():
                yield result.GetSolution(loose_q), prog, q
            for reference in (previous, self._start):
                shifted = self._shifted(plant_context, reference, target)
                if shifted is not None:
                    yield shifted, prog, q
            continued = self._continued(plant_context, previous, target)
            if continued is not None:  # its last step: the cost pulls towards the last posture on the way
                yield continued, *self._program(plant_context, target, continued, clearance=True)

        attempts = 0
        for seed, program, variables in seeds():
            if attempts == self._ik.attempts:
                break
            attempts += 1
            result, solution, feasible = self._solve(program, variables, seed)  # the FK check follows
            if not feasible:
                best = solution
                reasons.append(str(result.get_solution_result()).split(".")[-1])
                continue
            error = np.linalg.norm(self.tcp_position(plant_context, solution) - target)
            if error > FK_CHECK_FACTOR * tolerance * math.sqrt(3):
                best = solution
                reasons.append(f"tcp {error * 1000:.1f} mm off")
                continue
            return solution, ""
        return best, (
            f"{describe_keypoint(index, keypoint)}: IK failed after {attempts} attempt(s) "
            f"(SNOPT: {', '.join(reasons)}); "
            f"the tcp target {np.round(target, 3).tolist()} may be out of reach"
        )

    def _with_gripper(self, q: np.ndarray, opening: float) -> np.ndarray:
        q = np.array(q, dtype=float)
        q[self._gripper] = opening
        return q

    def trajectory(self, plant_context: Context, keyframes: Keyframes) -> PiecewisePolynomial:
        """The first-order hold from ``keyframes.start`` through their successful keyframes, timed by
        ``motion`` (the tcp's path computed in ``plant_context``)."""
        motion = self._motion
        knots, lifted = [keyframes.start], [False]
        for q, ok, keypoint in zip(keyframes.positions, keyframes.success, keyframes.keypoints):
            if not ok:
                continue
            if motion.closed_among_obstacles and keypoint.action not in ("start", *GRASP_ACTIONS):
                q = self._with_gripper(q, self._robot_description.gripper_closed)
            elif keypoint.action == "target" and np.any(knots[-1][self._gripper] != q[self._gripper]):
                knots.append(self._with_gripper(knots[-1], q[self._gripper][0]))  # open before sliding on
                lifted.append(lifted[-1])
            if np.max(np.abs(q - knots[-1])) > 1e-9:
                knots.append(q)
                lifted.append(keypoint.height is not None)  # lifted clear of the objects
        if len(knots) == 1:
            knots.append(keyframes.start)  # hold the start
            lifted.append(False)
        times = [0.0]
        tcp = [self.tcp_position(plant_context, q) for q in knots]
        for i in range(1, len(knots)):
            joint_time = np.max(
                np.abs(knots[i] - knots[i - 1]) / (motion.joint_speed_fraction * self._velocity_limits)
            )
            speed = motion.transit_speed if lifted[i] or lifted[i - 1] else motion.tcp_speed
            tcp_time = np.linalg.norm(tcp[i] - tcp[i - 1]) / speed
            times.append(times[-1] + max(motion.min_segment_duration, float(joint_time), float(tcp_time)))
        return PiecewisePolynomial.FirstOrderHold(times, np.column_stack(knots))
