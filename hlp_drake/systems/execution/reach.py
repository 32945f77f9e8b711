"""The executed reach: simulate the commanded motion in the world (or start where a planner's own run
in this very world ended), judge it by the paper's success test, then grasp and lift.

``execute_reach`` fills an ``ExecutionResult``: the objects moved and dropped, the target's distance,
the verdict (``failure_reason``), whether the grasp held, the simulated time; with MeshCat it records
the run and colours each pushed object while it is pushed.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from pydrake.systems.framework import EventStatus

from hlp_drake.systems.execution.command import advance_through_reach, grasp_and_lift
from hlp_drake.systems.execution.meshcat_view import highlight_pushes, push_times
from hlp_drake.systems.world.scene_models import fallen_objects, object_poses
from hlp_drake.systems.world.simulation import simulation_failure
from hlp_drake.systems.world.start_pose import tcp_keypoint_height
from hlp_drake.systems.world.success import ReachEnd
from hlp_drake.systems.world.world import world_plant

if TYPE_CHECKING:
    from pydrake.geometry import Meshcat
    from pydrake.systems.analysis import Simulator

    from hlp_drake.systems.execution.command import ClosedLoopCommand, OpenLoopCommand
    from hlp_drake.systems.execution.result import ExecutionResult
    from hlp_drake.systems.execution.run import RunListener
    from hlp_drake.systems.low_level.outcome import FinalState
    from hlp_drake.systems.scenario import Scenario

MOVED_TOLERANCE = 0.01  # m: an object displaced further than this counts as moved
RECORDING_FPS = 32.0  # frames per second of a MeshCat recording


def execute_reach(
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
    plant, robot = world_plant(simulator.get_system().GetSubsystemByName("world"))
    simulator.Initialize()
    root = simulator.get_mutable_context()
    grasp, settle_s = scenario.grasp, scenario.success.settle_s
    listener.executing(command.end(root) + settle_s + grasp.duration)
    plant_context = plant.GetMyContextFromRoot(simulator.get_context())
    tcp_frame = plant.GetFrameByName(scenario.robot.tcp_frame, robot)
    track: list[tuple[float, np.ndarray]] = []  # recorded: the tcp over time, to time the pushes

    def monitor(context) -> EventStatus:
        listener.simulated(context.get_time())
        if meshcat is not None:
            track.append((context.get_time(), tcp_frame.CalcPoseInWorld(plant_context).translation()))
        return EventStatus.DidNothing()

    simulator.set_monitor(monitor)
    names = [o.name for o in result.scene.objects]
    before = _centres(plant, plant_context, names)
    if meshcat is not None:
        meshcat.StartRecording(frames_per_second=RECORDING_FPS)
    try:
        settled = _reach(result, simulator, command, settle_s, listener, reached)
        if not np.all(np.isfinite(plant.GetPositionsAndVelocities(plant_context))):
            raise RuntimeError(f"the state is not finite at t = {settled:.2f} s")
        result.objects_dropped = fallen_objects(plant, plant_context, result.scene)
        tcp = tcp_frame.CalcPoseInWorld(plant_context).translation()
        problem = _judge(result, scenario, before, _centres(plant, plant_context, names), tcp)
        if problem is None:
            try:
                result.grasp_held = grasp_and_lift(
                    simulator, command, settled, plant=plant, target=result.scene.target.name, grasp=grasp,
                    robot=scenario.robot,
                )  # fmt: skip
            except (RuntimeError, SystemExit) as error:  # the reach was checked: its verdict stands
                result.grasp_held = False
                result.grasp_failure = f"simulation failed: {simulation_failure(error)}"
    except (RuntimeError, SystemExit) as error:
        failure = simulation_failure(error)
        if result.failure_reason is None:
            result.failure_reason = f"the world's simulation diverged: {failure}"
    finally:
        simulator.clear_monitor()
        result.simulated_s = float(simulator.get_context().get_time())
        if meshcat is not None:
            _highlight_pushes(meshcat, scenario, result, track)
            meshcat.StopRecording()
            meshcat.PublishRecording()


def _reach(result, simulator, command, settle_s: float, listener, reached: FinalState | None) -> float:
    """Simulate the commanded reach and the settling, or start where ``reached`` says they end (a
    planner's own run of this motion in this world); the simulated time then."""
    root = simulator.get_mutable_context()
    if reached is not None and reached.time == command.end(root) + settle_s:  # that run was this reach
        plant, _ = world_plant(simulator.get_system().GetSubsystemByName("world"))
        root.SetTime(reached.time)
        state = plant.GetMyMutableContextFromRoot(root)
        for name, x in reached.states.items():
            plant.SetPositionsAndVelocities(state, plant.GetModelInstanceByName(name), x)
        simulator.Initialize()
        listener.simulated(reached.time)
        return reached.time
    result.reach_reused = False
    return advance_through_reach(simulator, command, settle_s=settle_s)


def _centres(plant, context, names: list[str]) -> np.ndarray:
    """(m, 3) the objects' centres, in the order of ``names``."""
    poses = object_poses(plant, context, names)
    return np.array([poses[name].translation() for name in names])


def _judge(result, scenario: Scenario, before: np.ndarray, after: np.ndarray, tcp: np.ndarray) -> str | None:
    """The objects moved and the success test at the reach's end (``before`` and ``after``: the
    objects' centres, scene order; ``result.objects_dropped`` read already); fills ``result``,
    returns the failure (None: success)."""
    scene = result.scene
    names = [o.name for o in scene.objects]
    shifted = np.hypot(*(after[:, :2] - before[:, :2]).T)
    result.objects_moved = [n for n, d in zip(names[1:], shifted[1:]) if d > MOVED_TOLERANCE]
    end = ReachEnd(tcp, before, after, result.objects_dropped, tcp_keypoint_height(scene, scenario.ik))
    result.target_distance = end.distance()
    problem = end.problem(scene, scenario.success)
    if problem is not None and result.failure_reason is None:
        result.failure_reason = problem  # the world's verdict (the world is named beside it)
    return problem


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


__all__ = ["MOVED_TOLERANCE", "RECORDING_FPS", "execute_reach"]
