"""``KeypointIk``: a high-level plan's keypoints -> robot keyframes (IK) -> a joint-space trajectory.

Input ports:
    ``plan`` (abstract, ``HighLevelPlan``): a robot plan for the scenario's scene (table and start).
    ``alternatives`` (abstract, tuple of ``HighLevelPlan``; optional): other plans for it.

Output ports (in Drake's cache, computed again only when their input changes):
    ``keyframes`` (abstract, ``Keyframes``): per keypoint the robot's 11 positions, a success flag and
        a message naming the keypoint when its IK failed. When a keypoint of the plan fails, the first
        of ``alternatives`` whose IK succeeds takes its place (``Keyframes.candidate``).
    ``trajectory`` (abstract, ``PiecewisePolynomial``): a first-order hold of the robot's 11 positions
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

Its settings are a ``Scenario``'s ``ik`` (``IkConfig``, also the start pose's) and ``motion``
(``MotionConfig``).
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING, Annotated

from pydrake.common.value import AbstractValue
from pydrake.systems.framework import Context, LeafSystem, ValueProducer
from pydrake.trajectories import PiecewisePolynomial

from hlp_drake.config.ranges import MAX_DURATION, Count, NonNegativeFloat, Positive, PositiveFloat
from hlp_drake.planner.plan import HighLevelPlan
from hlp_drake.systems.planning.keyframes import Keyframes
from hlp_drake.systems.planning.keypoint_solver import KeypointSolver

if TYPE_CHECKING:
    from hlp_drake.systems.scenario import Scenario

MIN_SPEED = 0.01
"""m/s: the slowest tcp speed (with MAX_DURATION per segment, a run's trajectory stays bounded)."""
SPEED = Positive(MIN_SPEED, 10.0)


@dataclass(frozen=True)
class IkConfig:
    """Keypoint inverse kinematics (``KeypointIk`` and the start configuration).

    The gripper approaches horizontally along world +x (tcp +z), its fingers opening sideways (tcp +y
    horizontal), with the tcp ``height`` above the table top at every keypoint.

    Attributes:
        height: tcp height above the table top at the keypoints, m (below the objects' tops, so the
            fingers can close round the target and push obstacles).
        position_tolerance: half-width of the box the tcp must reach around a keypoint, m.
        approach_tolerance: largest angle between the approach axis (tcp +z) and world +x, rad.
        roll_tolerance: largest angle between the finger axis (tcp +y) and the horizontal plane, rad.
        table_clearance: smallest distance between the robot and the table top (and between the
            robot's own links), m. Contact with objects is allowed (they may be pushed).
        base_under_table: how far the base's front may go under the table top past its front edge, m
            (the table has no legs and the deck is lower than the table top, but the riser under the
            arm, 0.015 m behind the base's front and as high as the table, must stay in front of it).
        base_lateral_margin: the base's centre stays within the table's width plus this on each side, m.
        base_max_yaw: largest turn of the base away from facing +x, rad.
        start_reach: horizontal distance from the base's centre to the tcp at the start, m.
        start_base_clearance: smallest gap between the base's front and the table edge at the start, m.
        max_iterations: SNOPT major-iteration limit per solve (minor iterations: 50 times it). A
            solve that stops at the limit counts when its iterate meets every constraint: SNOPT
            often lingers at a converged point of the clearance constraint, so 100 gives the keyframes
            500 gives (308 of 310 Gen I/II scenes the same within 1e-4) in 0.42 of the IK time.
        attempts: solves per keypoint (the previous keyframe, then seeds with the base shifted, then
            a continuation along the tcp's straight line).
    """

    height: PositiveFloat = 0.06
    position_tolerance: PositiveFloat = 0.001
    approach_tolerance: PositiveFloat = 0.35
    roll_tolerance: PositiveFloat = 0.05
    table_clearance: NonNegativeFloat = 0.01
    base_under_table: NonNegativeFloat = 0.0
    base_lateral_margin: NonNegativeFloat = 0.50
    base_max_yaw: PositiveFloat = math.pi / 2
    start_reach: PositiveFloat = 1.10
    start_base_clearance: NonNegativeFloat = 0.05
    max_iterations: Annotated[int, Count(1, 100_000)] = 100
    attempts: Annotated[int, Count(1, 1000)] = 5


@dataclass(frozen=True)
class MotionConfig:
    """Timing of the joint trajectory through the keyframes (straight lines in joint space).

    A segment lasts the longest of: its tcp path length over ``tcp_speed`` (``transit_speed`` on the
    way to or from a waypoint lifted clear of the objects), each joint's travel over
    ``joint_speed_fraction`` of its velocity limit, and ``min_segment_duration``.

    With ``closed_among_obstacles`` the gripper closes on the way to the first keyframe and stays
    closed through the pushes, gaps and transits, opening on the way to the "approach" keyframe
    (in place before sliding onto the target if there is none): open fingers straddle a small
    obstacle and carry it along into the target. Keyframes are solved open either way (the tcp
    does not depend on the fingers).
    """

    tcp_speed: Annotated[float, SPEED] = 0.1
    transit_speed: Annotated[float, SPEED] = 0.25
    joint_speed_fraction: Annotated[float, Positive(0.01, 1.0)] = 0.5
    min_segment_duration: Annotated[float, Positive(upper=MAX_DURATION)] = 0.25
    closed_among_obstacles: bool = True


class KeypointIk(LeafSystem):
    """Solves IK for a plan's keypoints on ``scenario``'s table from its start, and times a joint
    trajectory through them (see the module's docstring for the ports)."""

    def __init__(self, scenario: Scenario) -> None:
        super().__init__()
        solver = KeypointSolver(scenario)
        self._solver = solver
        empty_plan = HighLevelPlan(scene=scenario.scene.name, keypoints=(), reason="no plan given")
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


__all__ = ["MIN_SPEED", "IkConfig", "Keyframes", "KeypointIk", "MotionConfig"]
