"""Plan, solve IK, optimise and execute in the physics world: what ``python -m hlp_drake.run_scene`` runs.

``plan_and_execute(scenario, pool=...)`` builds one diagram: the world (the scenario's plant at its
own time step), the scene source feeding the planning diagram (``SceneFromPlant`` on the world's
body poses, or with ``perception.source: camera`` the perceived scene: the planner, IK and
optimiser then work on it while the world simulates the true one; open loop one frame of the
world's cameras at the start, ``perceive_world``, so the executed world renders nothing; closed
loop ``ScenePerception`` on the executed world's cameras), and
what drives the robot: open loop a trajectory source, closed loop (``scenario.closed_loop.enabled``)
a ``RecedingHorizonController`` re-optimising on the measured state and the scene source's scene
(re-perceived at every re-plan with cameras). It evaluates the plan, the
keyframes and the optimisation at the start, plays the optimised trajectory, checks the reach, then
closes the gripper and lifts (open loop in the optimiser's own world, the reach is the optimiser's
verification of it on the execution model: the execution starts from where that ended). With ``scenario.uncertainty.enabled`` the world differs from what the
planners believe (``model_error``): without cameras the planning diagram then plans on the
scenario's scene, not the plant's. A ``RunListener`` hears of every stage as it happens.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from pydrake.geometry import Meshcat
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder, EventStatus

from hlp_drake.learners.models import DecisionModels
from hlp_drake.planner import HighLevelPlan
from hlp_drake.scene.model import Scene
from hlp_drake.systems.execution.command import ClosedLoopCommand, OpenLoopCommand, grasp_knots
from hlp_drake.systems.execution.meshcat_view import draw_perception, draw_plan, frame_table
from hlp_drake.systems.execution.receding_horizon import RecedingHorizonController
from hlp_drake.systems.optimiser.control_sequence import ControlSequence
from hlp_drake.systems.optimiser.cost import FinalState, pregrasp_check, reach_problem
from hlp_drake.systems.optimiser.optimiser import StoResult
from hlp_drake.systems.optimiser.pool import RolloutPool
from hlp_drake.systems.optimiser.rollout_world import simulation_failure
from hlp_drake.systems.perception.accuracy import perception_record
from hlp_drake.systems.perception.system import add_scene_perception, perceive_world
from hlp_drake.systems.planning.diagram import ObservedScenePlanner, make_planning_diagram
from hlp_drake.systems.planning.keyframes import Keyframes
from hlp_drake.systems.world.config import EXECUTION_SETTLE_S
from hlp_drake.systems.world.robot import TCP_FRAME
from hlp_drake.systems.world.scene_models import fallen_objects, object_body, object_planar_poses
from hlp_drake.systems.world.scene_source import SCENE_PORT, SceneFromPlant
from hlp_drake.systems.world.start_pose import tcp_keypoint_height
from hlp_drake.systems.world.uncertainty import sample_model_error
from hlp_drake.systems.world.world import (
    add_position_trajectory,
    connect_robot_command,
    make_world_diagram,
    world_plant,
)

if TYPE_CHECKING:
    from hlp_drake.systems.scenario import Scenario

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from pydrake.trajectories import PiecewisePolynomial

    from hlp_drake.planner import HighLevelPlan
    from hlp_drake.systems.optimiser.optimiser import StoResult
    from hlp_drake.systems.perception.perception import Perception
    from hlp_drake.systems.planning.keyframes import Keyframes

SETTLE_S = EXECUTION_SETTLE_S  # simulated time after the trajectory ends, before objects are checked
MOVED_TOLERANCE = 0.01  # m: an object displaced further than this counts as moved
RECORDING_FPS = 32.0  # frames per second of a MeshCat recording


@dataclass
class ExecutionResult:
    """Outcome of planning and executing one scene (``reach_reused``: the execution started where
    the optimised sequence's verification on the execution model ended, rather than simulating the
    reach again; see ``verified_reach``)."""

    planner: str
    scene: Scene
    plan: HighLevelPlan
    keyframes: Keyframes
    robot_plan: HighLevelPlan | None = None
    success: bool = False
    failure_reason: str | None = None
    timings: dict[str, float] = field(default_factory=dict)
    objects_moved: list[str] = field(default_factory=list)
    objects_dropped: list[str] = field(default_factory=list)
    target_distance: float | None = None
    simulated_s: float = 0.0
    iterations: int = 0
    rollouts: int = 0
    optimisation: dict[str, Any] = field(default_factory=dict)
    grasp_held: bool | None = None
    perception: dict[str, Any] | None = None
    execution: str = "open"
    closed_loop: dict[str, Any] = field(default_factory=dict)
    reach_reused: bool = False

    @property
    def rollout_passed_execution_failed(self) -> bool:
        """The optimiser accepted a sequence (its rollout passed), and the execution failed."""
        return bool(self.optimisation.get("success")) and not self.success

    def to_dict(self) -> dict[str, Any]:
        return {
            "planner": self.planner,
            "scene": self.scene.name,
            "success": self.success,
            "failure_reason": self.failure_reason,
            "plan": self.plan.to_dict(),
            "ik": {"ok": self.keyframes.ok, "failures": self.keyframes.failures},
            "robot_actuated_dofs": 10,
            "timings": self.timings,
            "objects_moved": self.objects_moved,
            "objects_dropped": self.objects_dropped,
            "target_distance": self.target_distance,
            "simulated_s": self.simulated_s,
            "iterations": self.iterations,
            "rollouts": self.rollouts,
            "optimisation": self.optimisation,
            "grasp_held": self.grasp_held,
            **({} if self.perception is None else {"perception": self.perception}),
            "execution": self.execution,
            "closed_loop": self.closed_loop,
            "reach_reused": self.reach_reused,
            "rollout_passed_execution_failed": self.rollout_passed_execution_failed,
        }


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
    contact, and grasp.

    Success (the paper's test): the optimiser found a sequence whose rollout passes (open loop; closed
    loop the controller may rescue one that does not), and in the execution (the world at its own time step) the target ends inside the gripper's pre-grasp region
    (the tcp within the target's radius + ``optimiser.cost.pregrasp_margin`` horizontally, at grasp
    height) with no object off the table. Then the fingers close and the tcp lifts;
    ``grasp_held`` says whether the target came up with it (not part of success).

    Args:
        pool: the optimiser's rollout workers (the caller's; its start-up is not timed here).
        meshcat: record the execution there, framed on the table, with the human and robot plans.
        contact_forces: draw the contact forces in MeshCat too.
        listener: told of every stage as it happens.

    Open loop plays the optimised sequence; closed loop (``scenario.closed_loop.enabled``) hands it
    to a ``RecedingHorizonController``.
    """
    execution = "closed" if scenario.closed_loop.enabled else "open"
    listener = listener or RunListener()
    scene = scenario.scene
    camera = scenario.perception.source == "camera"
    watching = camera and execution == "closed"  # cameras in the executed world, re-perceived at re-plans
    error = sample_model_error(scenario.uncertainty, scene) if scenario.uncertainty.enabled else None
    perception, perceive_s, fixed = None, 0.0, None  # fixed: the planners' scene, if not the source's
    if camera and not watching:  # one frame, in a world of its own: the executed one renders nothing
        perception, perceive_s = perceive_world(scenario, model_error=error)
        listener.perceived(perception, perceive_s)
        fixed = perception.scene
    elif error is not None and not camera:  # the scene the planners believe in
        fixed = scene
    builder = DiagramBuilder()
    world = builder.AddSystem(
        make_world_diagram(
            scenario, meshcat=meshcat, contact_forces=contact_forces, cameras=watching, model_error=error
        )
    )
    plant, robot = world_plant(world)
    started = time.perf_counter()
    planning = builder.AddNamedSystem("planning", make_planning_diagram(scenario, pool=pool, models=models))
    if watching:  # the planners see what the cameras see of the (true) world
        source = add_scene_perception(builder, world, scenario)
    else:  # the plant's poses (of the believed objects, under model error)
        source = builder.AddNamedSystem("scene_from_plant", SceneFromPlant(plant, scene))
        builder.Connect(world.GetOutputPort("body_poses"), source.get_body_poses_input_port())
    if fixed is None:
        builder.Connect(source.get_scene_output_port(), planning.GetInputPort(SCENE_PORT))
    if execution == "closed":  # it observes the scene through the same source at every re-plan
        replanner = ObservedScenePlanner(scenario, models=models)  # when objects have moved far
        controller = builder.AddNamedSystem(
            "controller", RecedingHorizonController(scenario, plant, pool, initialiser=replanner)
        )
        builder.Connect(world.GetOutputPort("state"), controller.GetInputPort("state"))
        builder.Connect(source.get_scene_output_port(), controller.GetInputPort(SCENE_PORT))
        if camera:
            builder.Connect(source.get_perception_output_port(), controller.GetInputPort("perception"))
        builder.Connect(planning.GetOutputPort("optimisation"), controller.GetInputPort("initial"))
        connect_robot_command(
            builder, world, controller.GetOutputPort("desired_trajectory_state"), name="controller"
        )
    else:
        start = plant.GetPositions(plant.CreateDefaultContext(), robot)
        hold = ControlSequence(np.array([0.0, 1.0]), np.vstack([start, start]))
        trajectory_source = add_position_trajectory(builder, world, hold.to_trajectory())
    simulator = Simulator(builder.Build())
    if watching:  # rendering and perception, timed apart from the planner
        seen = time.perf_counter()
        perception = source.get_perception_output_port().Eval(
            source.GetMyContextFromRoot(simulator.get_context())
        )
        perceive_s = time.perf_counter() - seen
        listener.perceived(perception, perceive_s)
    context = planning.GetMyContextFromRoot(simulator.get_mutable_context())
    if fixed is not None:
        planning.GetInputPort(SCENE_PORT).FixValue(context, fixed)
    plan: HighLevelPlan = planning.GetOutputPort("plan").Eval(context)
    planned = time.perf_counter()
    plan_s = planned - started - (perceive_s if watching else 0.0)  # open loop it was perceived before
    listener.planned(plan, plan_s)
    keyframes: Keyframes = planning.GetOutputPort("keyframes").Eval(context)
    trajectory = planning.GetOutputPort("trajectory").Eval(context)
    solved = time.perf_counter()
    listener.solved(keyframes, trajectory, solved - planned)
    result = ExecutionResult(
        scenario.planner.kind,
        scene,
        plan,
        keyframes,
        planning.GetOutputPort("robot_plan").Eval(context),
        execution=execution,
    )
    result.timings = {"plan_s": plan_s, "ik_s": solved - planned, "optimise_s": 0.0}
    if camera:
        result.perception = perception_record(scene, perception)
        result.timings["perceive_s"] = perceive_s
    if perception is not None and not perception.ok:
        result.failure_reason = f"perception failed: {perception.reason}"
    elif not plan.ok:
        result.failure_reason = f"no plan: {plan.reason}"
    elif not keyframes.ok:
        result.failure_reason = "IK failed: " + "; ".join(keyframes.failures)
    if result.failure_reason is None:
        listener.optimising()
        optimisation: StoResult = planning.GetOutputPort("optimisation").Eval(context)
        listener.optimised(optimisation)
        sequence = optimisation.sequence
        result.iterations, result.rollouts = optimisation.iterations, optimisation.rollouts
        result.optimisation = optimisation.to_dict()
        result.timings["optimise_s"] = optimisation.optimise_s
        if not optimisation.success and execution == "open":  # closed loop: the controller may rescue it
            result.failure_reason = f"the optimiser found no solution: {optimisation.failure_reason}"
    else:  # nothing to optimise: the (partial) IK trajectory is executed for inspection only
        sequence = ControlSequence.from_trajectory(trajectory, scenario.optimiser.step_duration)
    optimised = time.perf_counter()
    if execution == "closed":
        command = ClosedLoopCommand(controller)
    else:
        trajectory_source.UpdateTrajectory(sequence.to_trajectory())
        command = OpenLoopCommand(trajectory_source, sequence)
    if meshcat is not None:
        frame_table(meshcat, scene)
        heights = {
            "table_height": scene.table.height,
            "keypoint_height": tcp_keypoint_height(scene, scenario.ik),
        }
        draw_plan(meshcat, plan, path="plan", markers=False, **heights)
        draw_plan(meshcat, result.robot_plan, path="robot_plan", **heights)
        if perception is not None:
            draw_perception(meshcat, perception)
    reached = None
    if execution == "open" and error is None and meshcat is None and result.failure_reason is None:
        reached = verified_reach(optimisation, scenario)
    result.reach_reused = reached is not None
    executing = execution == "open" or result.failure_reason is None  # closed loop: an optimised sequence
    if executing:
        _execute(result, simulator, command, scenario, meshcat, listener, reached)
    if execution == "closed" and executing:  # what the controller did, the execution failed or not
        result.closed_loop = controller.record(simulator.get_context()).to_dict()
    executed = time.perf_counter()
    result.success = result.failure_reason is None
    result.timings.update(
        {"execute_s": executed - optimised, "total_s": executed - started, "pool_start_s": pool.startup_s}
    )
    listener.finished(result)
    return result


def verified_reach(optimisation: StoResult, scenario: Scenario) -> FinalState | None:
    """Where the optimised sequence's verification on the execution model ended, if that was in
    ``scenario``'s own world from the scene's start (None otherwise, e.g. planned on a perceived
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
    listener.executing(command.end(root) + SETTLE_S + grasp.close_s + grasp.lift_s + grasp.hold_s)
    simulator.set_monitor(lambda context: listener.simulated(context.get_time()) or EventStatus.DidNothing())
    plant_context = plant.GetMyContextFromRoot(simulator.get_context())
    names = [o.name for o in scene.objects]
    before = object_planar_poses(plant, plant_context, names)
    if meshcat is not None:
        meshcat.StartRecording(frames_per_second=RECORDING_FPS)
    try:
        end = command.end(root)
        if reached is not None and reached.time == end + SETTLE_S:  # the verification was this reach
            root.SetTime(reached.time)
            state = plant.GetMyMutableContextFromRoot(root)
            for name, x in reached.states.items():
                plant.SetPositionsAndVelocities(state, plant.GetModelInstanceByName(name), x)
            simulator.Initialize()
            listener.simulated(reached.time)
            settled = reached.time
        else:
            result.reach_reused = False
            settled = advance_through_reach(simulator, command)
        after = object_planar_poses(plant, plant_context, names)
        result.objects_moved = [
            n
            for n in names
            if n != scene.target.name
            and np.hypot(*np.subtract(after[n][:2], before[n][:2])) > MOVED_TOLERANCE
        ]
        result.objects_dropped = fallen_objects(plant, plant_context, scene)
        tcp = plant.GetFrameByName(TCP_FRAME, robot).CalcPoseInWorld(plant_context).translation()
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
            result.grasp_held = _grasp(simulator, command, settled, scenario, plant, plant_context, scene)
    except (RuntimeError, SystemExit) as error:
        failure = simulation_failure(error)
        if result.failure_reason is None:
            result.failure_reason = f"simulation failed: {failure}"
    finally:
        simulator.clear_monitor()
        result.simulated_s = float(simulator.get_context().get_time())
        if meshcat is not None:
            meshcat.StopRecording()
            meshcat.PublishRecording()


def advance_through_reach(simulator: Simulator, command: OpenLoopCommand | ClosedLoopCommand) -> float:
    """Simulate to the end of the commanded reach, then ``SETTLE_S`` more; return that time. A closed
    loop's re-plan may move the end while the simulation goes there: later (it goes on), or earlier
    than the time already simulated (the robot has held the reach's last pose since; the settling
    ends no earlier than now: going back would be Drake's "boundary_time >= context time" failure)."""
    root = simulator.get_mutable_context()
    end = command.end(root)
    while root.get_time() < end:
        simulator.AdvanceTo(end)
        end = command.end(root)
    settled = max(end + SETTLE_S, root.get_time())
    simulator.AdvanceTo(settled)
    return settled


def _grasp(simulator, command, t0, scenario, plant, plant_context, scene) -> bool:
    """Close the fingers at the reach's end pose (from ``t0``) and lift; whether the target rose
    with the gripper."""
    root = simulator.get_mutable_context()
    grasp = grasp_knots(command.final(root), scenario.grasp)
    if grasp is None:
        return False
    times, knots = grasp
    command.then(root, t0, times, knots)
    target = object_body(plant, scene.target.name)
    z0 = target.EvalPoseInWorld(plant_context).translation()[2]
    simulator.AdvanceTo(t0 + times[-1])
    return bool(target.EvalPoseInWorld(plant_context).translation()[2] - z0 >= scenario.grasp.held_height)


# ``RunListener``: what hears of a ``plan_and_execute`` run's stages as they happen.
class RunListener:
    """Hears of a run's stages as they happen (every method does nothing here; override what you need)."""

    def perceived(self, perception: Perception, seconds: float) -> None:
        """The cameras' frame is perceived (``seconds`` with the rendering; ``perception_s`` without)."""

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


__all__ = ["RunListener"]
