"""Plan, solve IK, optimise and execute in the physics world: what ``python -m hlp_drake.run_scene`` runs.

``plan_and_execute(scenario, pool=...)`` builds one diagram: the world (the scenario's plant at its
own time step), the scene source feeding the planning diagram (``SceneFromPlant`` on the world's
body poses, or with ``perception.source: camera`` ``ScenePerception`` on its cameras: the planner,
IK and optimiser then work on the perceived scene while the world simulates the true one), and a
trajectory source driving the robot. It evaluates the plan, the keyframes and the optimisation at the start,
plays the optimised trajectory, checks the reach, then closes the gripper and lifts. A
``RunListener`` hears of every stage as it happens.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from pydrake.geometry import Meshcat
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder, EventStatus
from pydrake.trajectories import PiecewisePolynomial

from hlp_drake.learners.models import DecisionModels
from hlp_drake.planner import HighLevelPlan
from hlp_drake.scene.model import Scene
from hlp_drake.systems.control_sequence import ControlSequence
from hlp_drake.systems.grasp import grasp_knots
from hlp_drake.systems.keyframes import Keyframes
from hlp_drake.systems.meshcat_view import draw_perception, draw_plan, frame_table
from hlp_drake.systems.optimiser import StoResult
from hlp_drake.systems.perception import Perception
from hlp_drake.systems.perception_errors import perception_record
from hlp_drake.systems.planning_diagram import make_planning_diagram
from hlp_drake.systems.robot import TCP_FRAME
from hlp_drake.systems.rollout_cost import pregrasp_check, reach_problem
from hlp_drake.systems.rollout_pool import RolloutPool
from hlp_drake.systems.rollout_world import simulation_failure
from hlp_drake.systems.scene_models import fallen_objects, object_body, object_planar_poses
from hlp_drake.systems.scene_perception import add_scene_perception
from hlp_drake.systems.scene_source import SCENE_PORT, SceneFromPlant
from hlp_drake.systems.start_pose import tcp_keypoint_height
from hlp_drake.systems.world import add_position_trajectory, make_world_diagram, world_plant

if TYPE_CHECKING:
    from hlp_drake.systems.scenario import Scenario

SETTLE_S = 1.0  # simulated time after the trajectory ends, before objects are checked
MOVED_TOLERANCE = 0.01  # m: an object displaced further than this counts as moved
RECORDING_FPS = 32.0  # frames per second of a MeshCat recording


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


@dataclass
class ExecutionResult:
    """Outcome of planning and executing one scene."""

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

    Success (the paper's test): the optimiser found a sequence whose rollout passes, and in the
    execution (the world at its own time step) the target ends inside the gripper's pre-grasp region
    (the tcp within the target's radius + ``optimiser.cost.pregrasp_margin`` horizontally, at grasp
    height) with no object off the table. Then the fingers close and the tcp lifts;
    ``grasp_held`` says whether the target came up with it (not part of success).

    Args:
        pool: the optimiser's rollout workers (the caller's; its start-up is not timed here).
        meshcat: record the execution there, framed on the table, with the human and robot plans.
        contact_forces: draw the contact forces in MeshCat too.
        listener: told of every stage as it happens.
    """
    listener = listener or RunListener()
    scene = scenario.scene
    camera = scenario.perception.source == "camera"
    builder = DiagramBuilder()
    world = builder.AddSystem(
        make_world_diagram(scenario, meshcat=meshcat, contact_forces=contact_forces, cameras=camera)
    )
    plant, robot = world_plant(world)
    started = time.perf_counter()
    planning = builder.AddNamedSystem("planning", make_planning_diagram(scenario, pool=pool, models=models))
    if camera:
        source = add_scene_perception(builder, world, scenario)
    else:
        source = builder.AddNamedSystem("scene_from_plant", SceneFromPlant(plant, scene))
        builder.Connect(world.GetOutputPort("body_poses"), source.get_body_poses_input_port())
    builder.Connect(source.get_scene_output_port(), planning.GetInputPort(SCENE_PORT))
    start = plant.GetPositions(plant.CreateDefaultContext(), robot)
    hold = ControlSequence(np.array([0.0, 1.0]), np.vstack([start, start]))
    trajectory_source = add_position_trajectory(builder, world, hold.to_trajectory())
    simulator = Simulator(builder.Build())
    perception, perceive_s = None, 0.0
    if camera:  # rendering and perception, timed apart from the planner
        seen = time.perf_counter()
        perception = source.get_perception_output_port().Eval(
            source.GetMyContextFromRoot(simulator.get_context())
        )
        perceive_s = time.perf_counter() - seen
        listener.perceived(perception, perceive_s)
    context = planning.GetMyContextFromRoot(simulator.get_mutable_context())
    plan: HighLevelPlan = planning.GetOutputPort("plan").Eval(context)
    planned = time.perf_counter()
    listener.planned(plan, planned - started - perceive_s)
    keyframes: Keyframes = planning.GetOutputPort("keyframes").Eval(context)
    trajectory = planning.GetOutputPort("trajectory").Eval(context)
    solved = time.perf_counter()
    listener.solved(keyframes, trajectory, solved - planned)
    result = ExecutionResult(
        scenario.planner.kind, scene, plan, keyframes, planning.GetOutputPort("robot_plan").Eval(context)
    )
    result.timings = {"plan_s": planned - started - perceive_s, "ik_s": solved - planned, "optimise_s": 0.0}
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
        if not optimisation.success:
            result.failure_reason = f"the optimiser found no solution: {optimisation.failure_reason}"
    else:  # nothing to optimise: the (partial) IK trajectory is executed for inspection only
        sequence = ControlSequence.from_trajectory(trajectory, scenario.optimiser.step_duration)
    optimised = time.perf_counter()
    trajectory_source.UpdateTrajectory(sequence.to_trajectory())
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
    _execute(result, simulator, trajectory_source, sequence, scenario, meshcat, listener)
    executed = time.perf_counter()
    result.success = result.failure_reason is None
    result.timings.update(
        {"execute_s": executed - optimised, "total_s": executed - started, "pool_start_s": pool.startup_s}
    )
    listener.finished(result)
    return result


def _execute(
    result: ExecutionResult,
    simulator: Simulator,
    source,
    sequence: ControlSequence,
    scenario: Scenario,
    meshcat: Meshcat | None,
    listener: RunListener,
) -> None:
    """Simulate ``sequence`` in the world, check the reach, then grasp and lift; fills ``result``."""
    scene = result.scene
    world = simulator.get_system().GetSubsystemByName("world")
    plant, robot = world_plant(world)
    grasp = scenario.grasp
    listener.executing(sequence.duration + SETTLE_S + grasp.close_s + grasp.lift_s + grasp.hold_s)
    simulator.set_monitor(lambda context: listener.simulated(context.get_time()) or EventStatus.DidNothing())
    simulator.Initialize()
    plant_context = plant.GetMyContextFromRoot(simulator.get_context())
    names = [o.name for o in scene.objects]
    before = object_planar_poses(plant, plant_context, names)
    if meshcat is not None:
        meshcat.StartRecording(frames_per_second=RECORDING_FPS)
    try:
        simulator.AdvanceTo(sequence.duration + SETTLE_S)
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
            result.grasp_held = _grasp(simulator, source, sequence, scenario, plant, plant_context, scene)
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


def _grasp(simulator, source, sequence, scenario, plant, plant_context, scene) -> bool:
    """Close the fingers at the reach's end pose and lift; whether the target rose with the gripper."""
    grasp = grasp_knots(sequence.knots[-1], scenario.grasp)
    if grasp is None:
        return False
    times, knots = grasp
    source.UpdateTrajectory(
        sequence.followed_by(
            np.concatenate([[SETTLE_S], SETTLE_S + times]), np.vstack([sequence.knots[-1], knots])
        )
    )
    target = object_body(plant, scene.target.name)
    z0 = target.EvalPoseInWorld(plant_context).translation()[2]
    simulator.AdvanceTo(sequence.duration + SETTLE_S + times[-1])
    return bool(target.EvalPoseInWorld(plant_context).translation()[2] - z0 >= scenario.grasp.held_height)
