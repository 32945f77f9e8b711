"""Run an execution diagram: plan, solve IK, optimise, execute in the physics world and grasp; what
``python -m hlp_drake.run_scene`` runs (``plan_and_execute``: ``make_execution_diagram``, then
``run_execution``).

The run evaluates the plan, the keyframes and the optimisation at the start, plays the optimised
trajectory (open loop) or hands it to the receding-horizon controller (closed loop), checks the
reach, then closes the gripper and lifts. Open loop in the optimiser's own world, the reach is the
optimiser's accepted rollout (on the execution model itself): the execution starts from where that
ended. The run's record is ``ExecutionResult`` (``hlp_drake.systems.execution.result``).
A ``RunListener`` hears of every stage as it happens.
"""

from __future__ import annotations

import time
from dataclasses import replace
from typing import TYPE_CHECKING

import numpy as np
from pydrake.geometry import Meshcat
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import EventStatus

from hlp_drake.planner import HighLevelPlan
from hlp_drake.systems.execution.command import (
    ClosedLoopCommand,
    OpenLoopCommand,
    advance_through_reach,
    grasp_and_lift,
)
from hlp_drake.systems.execution.diagram import (
    ExecutionDiagram,
    execution_model_error,
    make_execution_diagram,
)
from hlp_drake.systems.execution.meshcat_view import (
    PLAN_LIFT,
    draw_perception,
    draw_plan,
    frame_table,
    highlight_pushes,
    push_times,
)
from hlp_drake.systems.execution.result import ExecutionResult, true_names
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.sto.cost import FinalState, pregrasp_check, reach_problem
from hlp_drake.systems.low_level.sto.pool import RolloutPool
from hlp_drake.systems.low_level.sto.rollout_world import simulation_failure
from hlp_drake.systems.perception.accuracy import perception_record
from hlp_drake.systems.perception.system import perceive_world
from hlp_drake.systems.planning.keyframes import Keyframes
from hlp_drake.systems.world.scene_models import fallen_objects, object_planar_poses
from hlp_drake.systems.world.scene_source import SCENE_PORT
from hlp_drake.systems.world.start_pose import tcp_keypoint_height
from hlp_drake.systems.world.world import world_plant

if TYPE_CHECKING:
    from pydrake.trajectories import PiecewisePolynomial

    from hlp_drake.learners.models import DecisionModels
    from hlp_drake.systems.low_level.sto.optimiser import StoResult
    from hlp_drake.systems.perception.perception import Perception
    from hlp_drake.systems.scenario import Scenario


MOVED_TOLERANCE = 0.01  # m: an object displaced further than this counts as moved
RECORDING_FPS = 32.0  # frames per second of a MeshCat recording


def plan_and_execute(
    scenario: Scenario,
    *,
    pool: RolloutPool,
    models: DecisionModels | None = None,
    meshcat: Meshcat | None = None,
    contact_forces: bool = False,
    listener: RunListener | None = None,
) -> ExecutionResult:
    """Plan ``scenario``'s scene with its planner, solve IK, optimise with the STO, execute with
    contact, and grasp: ``make_execution_diagram``, then ``run_execution``.

    Success (the paper's test): the optimiser found a sequence whose rollout passes (open loop; closed
    loop the controller may rescue one that does not), and in the execution (the world at its own time
    step) the target ends inside the gripper's pre-grasp region (the tcp within the target's radius +
    ``optimiser.cost.pregrasp_margin`` horizontally, at grasp height) with no object off the table.
    Then the fingers close and the tcp lifts; ``grasp_held`` says whether the target came up with it
    (not part of success).

    Args:
        pool: the optimiser's rollout workers (the caller's; its start-up is not timed here).
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
    pool: RolloutPool,
    meshcat: Meshcat | None = None,
    listener: RunListener | None = None,
    perceived: tuple[Perception | None, float] = (None, 0.0),
    started: float | None = None,
) -> ExecutionResult:
    """Run the execution diagram ``handles`` of ``scenario``: plan, IK, optimise, execute and grasp
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
    sequence, optimisation = _optimise(handles, scenario, simulator, listener, result, trajectory)
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
        reached = verified_reach(optimisation, scenario)
    result.reach_reused = reached is not None
    executing = handles.execution == "open" or result.failure_reason is None  # closed: an optimised sequence
    if executing:
        _execute(result, simulator, command, scenario, meshcat, listener, reached)
    if handles.controller is not None and executing:  # what the controller did, the execution failed or not
        result.closed_loop = handles.controller.record(simulator.get_context()).to_dict()
    executed = time.perf_counter()
    result.success = result.failure_reason is None
    result.timings.update(
        {"execute_s": executed - optimised, "total_s": executed - started, "pool_start_s": pool.startup_s}
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
    result = ExecutionResult(
        scenario.planner.kind, scenario.scene, plan, keyframes, robot_plan, execution=handles.execution
    )
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


def _optimise(handles, scenario, simulator, listener, result, trajectory):
    """The optimised sequence (or, with nothing to optimise, the IK trajectory's, executed for
    inspection only) and the optimisation (None if it did not run); fills ``result``."""
    if result.failure_reason is not None:
        return ControlSequence.from_trajectory(trajectory, scenario.optimiser.step_duration), None
    listener.optimising()
    context = handles.planning.GetMyContextFromRoot(simulator.get_mutable_context())
    optimisation: StoResult = handles.planning.GetOutputPort("optimisation").Eval(context)
    listener.optimised(optimisation)
    result.iterations, result.rollouts = optimisation.iterations, optimisation.rollouts
    result.optimisation = optimisation.to_dict()
    result.timings["optimise_s"] = optimisation.optimise_s
    if not optimisation.success and handles.execution == "open":  # closed: the controller may rescue it
        result.failure_reason = f"the optimiser found no solution: {optimisation.failure_reason}"
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


def verified_reach(optimisation: StoResult, scenario: Scenario) -> FinalState | None:
    """Where the optimised sequence's verification on the execution model ended (the accepted rollout
    itself, unless the reduced model rolled it out), if that was in ``scenario``'s own world from the scene's start (None otherwise, e.g. planned on a perceived
    scene): the execution model is deterministic, so the execution's reach would end there too."""
    outcome = optimisation.outcome
    final = None if outcome is None or outcome.verification is None else outcome.verification.final
    return final if final is not None and final.scenario_key == scenario.key else None


def _execute(
    result: ExecutionResult,
    simulator: Simulator,
    command: OpenLoopCommand | ClosedLoopCommand,
    scenario: Scenario,
    meshcat: Meshcat | None,
    listener: RunListener,
    reached: FinalState | None = None,
) -> None:
    """Simulate the commanded reach in the world (or start where ``reached`` says it ends), check
    it, then grasp and lift; fills ``result``."""
    scene = result.scene
    world = simulator.get_system().GetSubsystemByName("world")
    plant, robot = world_plant(world)
    grasp = scenario.grasp
    simulator.Initialize()
    root = simulator.get_mutable_context()
    settle_s = scenario.optimiser.settle_s  # after the trajectory ends, before objects are checked
    listener.executing(command.end(root) + settle_s + grasp.close_s + grasp.lift_s + grasp.hold_s)
    plant_context = plant.GetMyContextFromRoot(simulator.get_context())
    tcp_frame = plant.GetFrameByName(scenario.robot.tcp_frame, robot)
    track: list[tuple[float, np.ndarray]] = []  # recorded: the tcp over time, to time the pushes

    def monitor(context) -> EventStatus:
        listener.simulated(context.get_time())
        if meshcat is not None:
            track.append((context.get_time(), tcp_frame.CalcPoseInWorld(plant_context).translation()))
        return EventStatus.DidNothing()

    simulator.set_monitor(monitor)
    names = [o.name for o in scene.objects]
    before = object_planar_poses(plant, plant_context, names)
    if meshcat is not None:
        meshcat.StartRecording(frames_per_second=RECORDING_FPS)
    try:
        end = command.end(root)
        if reached is not None and reached.time == end + settle_s:  # the verification was this reach
            root.SetTime(reached.time)
            state = plant.GetMyMutableContextFromRoot(root)
            for name, x in reached.states.items():
                plant.SetPositionsAndVelocities(state, plant.GetModelInstanceByName(name), x)
            simulator.Initialize()
            listener.simulated(reached.time)
            settled = reached.time
        else:
            result.reach_reused = False
            settled = advance_through_reach(simulator, command, settle_s=settle_s)
        after = object_planar_poses(plant, plant_context, names)
        result.objects_moved = [
            n
            for n in names
            if n != scene.target.name
            and np.hypot(*np.subtract(after[n][:2], before[n][:2])) > MOVED_TOLERANCE
        ]
        result.objects_dropped = fallen_objects(plant, plant_context, scene)
        tcp = tcp_frame.CalcPoseInWorld(plant_context).translation()
        inside, result.target_distance = pregrasp_check(
            tcp,
            after[scene.target.name],
            scene,
            tcp_height=tcp_keypoint_height(scene, scenario.ik),
            margin=scenario.optimiser.cost.pregrasp_margin,
        )
        problem = reach_problem(result.objects_dropped, inside, result.target_distance)
        if problem is not None and result.failure_reason is None:
            result.failure_reason = f"in execution: {problem}"
        if problem is None:
            try:
                result.grasp_held = grasp_and_lift(
                    simulator, command, settled, scenario, plant, plant_context, scene
                )
            except (RuntimeError, SystemExit) as error:  # the reach was checked: its verdict stands
                result.grasp_held = False
                result.grasp_failure = f"simulation failed: {simulation_failure(error)}"
    except (RuntimeError, SystemExit) as error:
        failure = simulation_failure(error)
        if result.failure_reason is None:
            result.failure_reason = f"simulation failed: {failure}"
    finally:
        simulator.clear_monitor()
        result.simulated_s = float(simulator.get_context().get_time())
        if meshcat is not None:
            _highlight_pushes(meshcat, scenario, result, track)
            meshcat.StopRecording()
            meshcat.PublishRecording()


def _highlight_pushes(
    meshcat: Meshcat, scenario: Scenario, result: ExecutionResult, track: list[tuple[float, np.ndarray]]
) -> None:
    """Colour each object the robot plan pushes in the recording while the tcp (``track``: simulated
    time, position) goes from its push's start to its end (``highlight_pushes``)."""
    if not track:
        return
    times = np.array([t for t, _ in track])
    tcp = np.array([p for _, p in track])
    pushes = push_times(
        result.robot_plan,
        times,
        tcp,
        table_height=scenario.scene.table.height,
        keypoint_height=tcp_keypoint_height(scenario.scene, scenario.ik),
        names=result.true_names,
    )
    highlight_pushes(meshcat, result.scene, pushes)


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

    def optimising(self) -> None:
        """The optimiser starts (its rollouts arrive through the pool's ``on_rollout``)."""

    def optimised(self, result: StoResult) -> None:
        """The optimiser is done."""

    def executing(self, duration: float) -> None:
        """The execution starts: ``duration`` simulated seconds (reach, settling, grasp)."""

    def simulated(self, t: float) -> None:
        """The execution has reached simulated time ``t``."""

    def finished(self, result: ExecutionResult) -> None:
        """The run is over."""
