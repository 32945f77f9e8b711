"""``KeypointIk``: a high-level plan's keypoints -> robot keyframes (IK) -> a joint-space trajectory.

Input ports:
    ``plan`` (abstract, ``HighLevelPlan``): a robot plan for the scenario's scene (table and start).
    ``alternatives`` (abstract, tuple of ``HighLevelPlan``; optional): other plans for it.

Output ports (in Drake's cache, computed again only when their input changes):
    ``keyframes`` (abstract, ``Keyframes``): per keypoint the robot's positions, a success flag and
        a message naming the keypoint when its IK failed. When a keypoint of the plan fails, the first
        of ``alternatives`` whose IK succeeds takes its place (``Keyframes.candidate``).
    ``trajectory`` (abstract, ``PiecewisePolynomial``): a first-order hold of the robot's positions
        from the start configuration through the successful keyframes (straight lines in joint space),
        timed by the scenario's ``motion``; the gripper closed among the obstacles if
        ``motion.closed_among_obstacles``.
    ``alternative_trajectories`` (abstract, tuple of ``PiecewisePolynomial``): the same for each of
        ``alternatives`` whose every keypoint's IK succeeds, in order, after the one ``keyframes`` took;
        computed only when evaluated.

The positions are in the robot model instance's order (``robot_position_names()``: base x, y, yaw,
the six UR5 joints, left finger, right (mimic) finger), the same in the world diagram's plant, so
``add_position_trajectory`` can play the trajectory. The solves (``KeypointSolver``) work in a
planning-model context kept in this system's Context (a cache entry), made once per Context.

Its settings are ``IkConfig`` (also the start pose's) and ``MotionConfig``
(``hlp_drake.systems.planning.config``; a ``Scenario``'s ``ik`` and ``motion``).
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING

from pydrake.common.value import AbstractValue
from pydrake.systems.framework import Context, LeafSystem, ValueProducer
from pydrake.trajectories import PiecewisePolynomial

from hlp_drake.planner.plan import HighLevelPlan
from hlp_drake.systems.planning.config import MIN_SPEED, IkConfig, MotionConfig
from hlp_drake.systems.planning.keyframes import Keyframes
from hlp_drake.systems.planning.keypoint_solver import KeypointSolver
from hlp_drake.systems.world.robot_description import MOBILE_UR5, RobotDescription
from hlp_drake.systems.world.scene_models import BodiesConfig, ContactConfig

if TYPE_CHECKING:
    from hlp_drake.scene.model import Scene


class KeypointIk(LeafSystem):
    """Solves IK for a plan's keypoints on ``scene``'s table from its start, and times a joint
    trajectory through them (see the module's docstring for the ports).

    Args:
        scene: the table and the start (its objects play no part: they may be pushed).
        robot, ik, motion, contact, bodies: as ``KeypointSolver``'s (default: a ``Scenario``'s).
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
        super().__init__()
        solver = KeypointSolver(scene, robot=robot, ik=ik, motion=motion, contact=contact, bodies=bodies)
        self._solver = solver
        empty_plan = HighLevelPlan(scene=scene.name, keypoints=(), reason="no plan given")
        self._plan_port = self.DeclareAbstractInputPort(
            name="plan", model_value=AbstractValue.Make(empty_plan)
        )
        self._alternatives_port = self.DeclareAbstractInputPort(
            name="alternatives", model_value=AbstractValue.Make(())
        )
        self._scratch = self.DeclareCacheEntry(
            description="planning model context",
            value_producer=ValueProducer(
                allocate=lambda: AbstractValue.Make(solver.new_context()), calc=lambda context, value: None
            ),
            prerequisites_of_calc={self.nothing_ticket()},
        )
        plans_ticket = {
            self.input_port_ticket(self._plan_port.get_index()),
            self.input_port_ticket(self._alternatives_port.get_index()),
        }
        self._keyframes_port = self.DeclareAbstractOutputPort(
            name="keyframes",
            alloc=lambda: AbstractValue.Make(Keyframes.empty(solver.start)),
            calc=self._calc_keyframes,
            prerequisites_of_calc=plans_ticket,
        )
        self._trajectory_port = self.DeclareAbstractOutputPort(
            name="trajectory",
            alloc=lambda: AbstractValue.Make(PiecewisePolynomial()),
            calc=self._calc_trajectory,
            prerequisites_of_calc=plans_ticket,
        )
        self._alternative_trajectories_port = self.DeclareAbstractOutputPort(
            name="alternative_trajectories",
            alloc=lambda: AbstractValue.Make(()),
            calc=self._calc_alternative_trajectories,
            prerequisites_of_calc=plans_ticket,
        )

    @property
    def solver(self) -> KeypointSolver:
        """The IK and timing (to call directly, with a context of ``solver.new_context()``)."""
        return self._solver

    def get_plan_input_port(self):
        return self._plan_port

    def get_alternatives_input_port(self):
        return self._alternatives_port

    def get_keyframes_output_port(self):
        return self._keyframes_port

    def get_trajectory_output_port(self):
        return self._trajectory_port

    def get_alternative_trajectories_output_port(self):
        return self._alternative_trajectories_port

    def _plant_context(self, context: Context) -> Context:
        return self._solver.plant_context(self._scratch.Eval(context))

    def _calc_keyframes(self, context: Context, output: AbstractValue) -> None:
        if not self._plan_port.HasValue(context):
            output.set_value(
                Keyframes.empty(self._solver.start, "no plan: the plan input port is not connected")
            )
            return
        output.set_value(self._solver.solve_first(self._plant_context(context), self._plans(context)))

    def _calc_trajectory(self, context: Context, output: AbstractValue) -> None:
        output.set_value(
            self._solver.trajectory(self._plant_context(context), self._keyframes_port.Eval(context))
        )

    def _alternatives(self, context: Context) -> tuple:
        return self._alternatives_port.Eval(context) if self._alternatives_port.HasValue(context) else ()

    def _plans(self, context: Context) -> Iterator[HighLevelPlan]:
        """The plan, then (evaluated only if asked for) its alternatives."""
        yield self._plan_port.Eval(context)
        yield from self._alternatives(context)

    def _calc_alternative_trajectories(self, context: Context, output: AbstractValue) -> None:
        # Those up to the one ``keyframes`` took failed their IK there, or were taken: not solved again.
        taken = self._keyframes_port.Eval(context).candidate if self._plan_port.HasValue(context) else 0
        plans = self._alternatives(context)[taken:]
        plant_context = self._plant_context(context)
        solved = (self._solver.solve(plant_context, plan) for plan in plans)
        output.set_value(tuple(self._solver.trajectory(plant_context, k) for k in solved if k.ok))


__all__ = [
    "MIN_SPEED",
    "IkConfig",
    "Keyframes",
    "KeypointIk",
    "MotionConfig",
]  # the settings: planning.config
