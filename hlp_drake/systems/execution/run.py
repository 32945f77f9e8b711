"""Run an execution diagram: plan, solve IK, plan the motion with the low-level planner, execute in
the physics world and grasp; what ``python -m hlp_drake.run_scene`` runs (``plan_and_execute``:
``make_execution_diagram``, then ``run_execution``).

The run evaluates the plan, the keyframes and the low-level plan at the start, plays its motion
(open loop) or hands it to the receding-horizon controller (closed loop), checks the reach
(``execute_reach``), then closes the gripper and lifts. Open loop in the low-level planner's own
world, the reach is its accepted rollout (the STO's, on the execution model itself): the execution
starts from where that ended. The run's record is ``ExecutionResult`` (``hlp_drake.systems.execution.result``).
A ``RunListener`` hears of every stage as it happens.
"""

from __future__ import annotations

import time
from dataclasses import replace
from typing import TYPE_CHECKING

from pydrake.geometry import Meshcat
from pydrake.systems.analysis import Simulator

from hlp_drake.planner import HighLevelPlan
from hlp_drake.systems.execution.command import ClosedLoopCommand, OpenLoopCommand
from hlp_drake.systems.execution.diagram import (
    ExecutionDiagram,
    execution_model_error,
    make_execution_diagram,
)
from hlp_drake.systems.execution.meshcat_view import PLAN_LIFT, draw_perception, draw_plan, frame_table
from hlp_drake.systems.execution.reach import execute_reach
from hlp_drake.systems.execution.result import ExecutionResult, labels_of, true_names
from hlp_drake.systems.low_level.registry import low_level_entry
from hlp_drake.systems.perception.accuracy import perception_record
from hlp_drake.systems.perception.system import perceive_world
from hlp_drake.systems.planning.diagram import low_level_planner
from hlp_drake.systems.planning.keyframes import Keyframes
from hlp_drake.systems.world.model import world_key
from hlp_drake.systems.world.scene_source import SCENE_PORT
from hlp_drake.systems.world.start_pose import tcp_keypoint_height

if TYPE_CHECKING:
    from pydrake.trajectories import PiecewisePolynomial

    from hlp_drake.learners.models import DecisionModels
    from hlp_drake.systems.low_level.outcome import FinalState
    from hlp_drake.systems.low_level.result import LowLevelResult
    from hlp_drake.systems.low_level.sto.pool import RolloutPool
    from hlp_drake.systems.perception.perception import Perception
    from hlp_drake.systems.scenario import Scenario


def plan_and_execute(
    scenario: Scenario,
    *,
    pool: RolloutPool | None = None,
    models: DecisionModels | None = None,
    meshcat: Meshcat | None = None,
    contact_forces: bool = False,
    listener: RunListener | None = None,
) -> ExecutionResult:
    """Plan ``scenario``'s scene with its initialiser, solve IK, plan the motion with its low-level
    planner, execute with contact, and grasp: ``make_execution_diagram``, then ``run_execution``.

    Success (the paper's test, ``success``): the low-level planner accepted a motion (open loop;
    closed loop the controller may rescue one it did not), and in the execution the target ends
    inside the gripper's pre-grasp region (the tcp within the target's radius +
    ``success.pregrasp_margin`` horizontally, at grasp height) with no object off the table. Then
    the fingers close and the tcp lifts; ``grasp_held`` says whether the target came up with it (not
    part of success).

    Args:
        pool: the rollout workers of a low-level planner that rolls out (the caller's; its start-up
            is not timed here).
        meshcat: record the execution there, framed on the table, with the human and robot plans.
        contact_forces: draw the contact forces in MeshCat too.
        listener: told of every stage as it happens.
    """
    listener = listener or RunListener()
    perception, perceive_s = None, 0.0
    if scenario.perception.source == "camera" and not scenario.closed_loop.enabled:
        # one frame, in a world of its own: the executed one renders nothing
        perception, perceive_s = perceive_world(scenario, model_error=execution_model_error(scenario))
        listener.perceived(perception, perceive_s)
    started = time.perf_counter()
    handles = make_execution_diagram(
        scenario,
        pool=pool,
        models=models,
        meshcat=meshcat,
        contact_forces=contact_forces,
        planned_scene=None if perception is None else perception.scene,
    )
    return run_execution(
        handles,
        scenario,
        pool=pool,
        meshcat=meshcat,
        listener=listener,
        perceived=(perception, perceive_s),
        started=started,
    )


def run_execution(
    handles: ExecutionDiagram,
    scenario: Scenario,
    *,
    pool: RolloutPool | None = None,
    meshcat: Meshcat | None = None,
    listener: RunListener | None = None,
    perceived: tuple[Perception | None, float] = (None, 0.0),
    started: float | None = None,
) -> ExecutionResult:
    """Run the execution diagram ``handles`` of ``scenario``: plan, IK, low-level plan, execute and grasp
    (``perceived``: the frame the planners' scene came from and its seconds, if perceived before the
    build; ``started``: when the run's clock started, by default now)."""
    listener = listener or RunListener()
    started = time.perf_counter() if started is None else started
    simulator = Simulator(handles.diagram)
    perception, perceive_s = perceived
    if handles.watching:  # rendering and perception, timed apart from the planner
        seen = time.perf_counter()
        perception = handles.source.get_perception_output_port().Eval(
            handles.source.GetMyContextFromRoot(simulator.get_context())
        )
        perceive_s = time.perf_counter() - seen
        listener.perceived(perception, perceive_s)
    result, trajectory = _plan(handles, scenario, simulator, listener, started, perception, perceive_s)
    sequence, optimisation = _low_level(handles, simulator, listener, result, trajectory)
    optimised = time.perf_counter()
    if handles.controller is not None:
        command = ClosedLoopCommand(handles.controller)
    else:
        handles.trajectory_source.UpdateTrajectory(sequence.to_trajectory())
        command = OpenLoopCommand(handles.trajectory_source, sequence)
    if meshcat is not None:
        _draw(meshcat, scenario, result, perception)
    reached = None
    if (
        handles.execution == "open"
        and not scenario.uncertainty.enabled
        and meshcat is None
        and result.failure_reason is None
    ):
        key = world_key(scenario.scene, scenario.executed_model, scenario.success.settle_s)
        reached = verified_reach(optimisation, key)
    result.reach_reused = reached is not None
    executing = handles.execution == "open" or result.failure_reason is None  # closed: an optimised sequence
    if executing:
        execute_reach(result, simulator, command, scenario, meshcat, listener, reached)
    if handles.controller is not None and executing:  # what the controller did, the execution failed or not
        result.closed_loop = handles.controller.record(simulator.get_context()).to_dict()
    executed = time.perf_counter()
    result.success = result.failure_reason is None
    result.timings.update(
        {
            "execute_s": executed - optimised,
            "total_s": executed - started,
            "pool_start_s": 0.0 if pool is None else pool.startup_s,
        }
    )
    listener.finished(result)
    return result


def _plan(handles, scenario, simulator, listener, started, perception, perceive_s):
    """Evaluate the plan, the keyframes and the initial trajectory; the result so far (failed if
    perception, the plan or IK failed) and the trajectory."""
    planning = handles.planning
    context = planning.GetMyContextFromRoot(simulator.get_mutable_context())
    if handles.planned_scene is not None:
        planning.GetInputPort(SCENE_PORT).FixValue(context, handles.planned_scene)
    plan: HighLevelPlan = planning.GetOutputPort("plan").Eval(context)
    planned = time.perf_counter()
    plan_s = planned - started - (perceive_s if handles.watching else 0.0)  # open loop: perceived before
    names = None if perception is None else true_names(scenario.scene, perception)
    if names is not None:
        listener.named(names)
    listener.planned(plan, plan_s)
    keyframes: Keyframes = planning.GetOutputPort("keyframes").Eval(context)
    trajectory = planning.GetOutputPort("trajectory").Eval(context)
    solved = time.perf_counter()
    listener.solved(keyframes, trajectory, solved - planned)
    robot_plan = planning.GetOutputPort("robot_plan").Eval(context)
    if keyframes.candidate:  # the plan's IK failed; an alternative's keypoints are run and drawn
        robot_plan = replace(robot_plan, keypoints=keyframes.keypoints)
    labels = labels_of(scenario)
    result = ExecutionResult(
        labels.planner, scenario.scene, plan, keyframes, robot_plan, execution=handles.execution
    )
    result.initial, result.low_level, result.world = labels.initial, labels.low_level, labels.world
    result.actuated_dofs = len(scenario.robot.actuated_joints)
    result.timings = {"plan_s": plan_s, "ik_s": solved - planned, "optimise_s": 0.0}
    result.true_names = names
    if scenario.perception.source == "camera":
        result.perception = perception_record(scenario.scene, perception)
        result.timings["perceive_s"] = perceive_s
    if perception is not None and not perception.ok:
        result.failure_reason = f"perception failed: {perception.reason}"
    elif not plan.ok:
        result.failure_reason = f"no plan: {plan.reason}"
    elif not keyframes.ok:
        result.failure_reason = "IK failed: " + "; ".join(keyframes.failures)
    return result, trajectory


def _low_level(handles, simulator, listener, result, trajectory):
    """The low-level planner's motion (or, with nothing to plan, the IK trajectory as it commands one,
    executed for inspection only) and its result (None if it did not run); fills ``result``."""
    if result.failure_reason is not None:
        return low_level_planner(handles.planning).as_commanded(trajectory), None
    listener.optimising(result.low_level)
    context = handles.planning.GetMyContextFromRoot(simulator.get_mutable_context())
    optimisation: LowLevelResult = handles.planning.GetOutputPort("optimisation").Eval(context)
    listener.optimised(optimisation)
    result.iterations, result.rollouts = optimisation.iterations, optimisation.rollouts
    result.model_success = optimisation.success
    result.optimisation = optimisation.to_dict()
    result.timings["optimise_s"] = optimisation.optimise_s
    if not optimisation.success and handles.execution == "open":  # closed: the controller may rescue it
        planner = low_level_entry(optimisation.low_level or result.low_level).noun
        result.failure_reason = f"{planner} found no solution: {optimisation.failure_reason}"
    return optimisation.sequence, optimisation


def _draw(
    meshcat: Meshcat, scenario: Scenario, result: ExecutionResult, perception: Perception | None
) -> None:
    """Frame the table and draw the human and robot plans (and what the cameras saw) in ``meshcat``."""
    scene = scenario.scene
    frame_table(meshcat, scene, fixed_base=not scenario.robot.mobile)
    table = scene.table.height
    on_table = table + PLAN_LIFT  # the person's plan on the table top, the robot's path at the tcp's height
    draw_plan(meshcat, result.plan, path="plan", markers=False, table_height=table, keypoint_height=on_table)
    keypoint_height = tcp_keypoint_height(scene, scenario.ik)
    draw_plan(
        meshcat, result.robot_plan, path="robot_plan", table_height=table, keypoint_height=keypoint_height
    )
    if perception is not None:
        draw_perception(meshcat, perception)


def verified_reach(optimisation: LowLevelResult, key: str) -> FinalState | None:
    """Where the planned motion's verification on the execution model ended (the STO's accepted
    rollout itself, unless the reduced model rolled it out), if that was in the world of ``key``
    (``world_key``) from the scene's start (None otherwise, e.g. planned on a perceived scene): the
    world is deterministic, so the execution's reach would end there too."""
    outcome = optimisation.outcome
    final = None if outcome is None or outcome.verification is None else outcome.verification.final
    return final if final is not None and final.world_key == key else None


class RunListener:
    """Hears of a run's stages as they happen (every method does nothing here; override what you need)."""

    def perceived(self, perception: Perception, seconds: float) -> None:
        """The cameras' frame is perceived (``seconds`` with the rendering; ``perception_s`` without)."""

    def named(self, names: dict[str, str | None]) -> None:
        """The perceived objects' true names (perceived -> true, None: matched to none), before
        ``planned`` of a plan on a perceived scene."""

    def planned(self, plan: HighLevelPlan, seconds: float) -> None:
        """The planner's plan is ready."""

    def solved(self, keyframes: Keyframes, trajectory: PiecewisePolynomial, seconds: float) -> None:
        """The robot plan's keyframes (IK) and the initial trajectory are ready."""

    def optimising(self, low_level: str) -> None:
        """The low-level planner ``low_level`` (its registry name) starts (a planner that rolls out:
        its rollouts arrive through the pool's ``on_rollout``)."""

    def optimised(self, result: LowLevelResult) -> None:
        """The low-level planner is done."""

    def executing(self, duration: float) -> None:
        """The execution starts: ``duration`` simulated seconds (reach, settling, grasp)."""

    def simulated(self, t: float) -> None:
        """The execution has reached simulated time ``t``."""

    def finished(self, result: ExecutionResult) -> None:
        """The run is over."""
