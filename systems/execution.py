"""Plan, solve IK and execute in the physics world: what ``python -m hlp_drake.run_scene`` runs."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from pydrake.geometry import Meshcat, Rgba, Sphere
from pydrake.math import RigidTransform
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

from hlp_drake.atomic import write_text_atomic
from hlp_drake.learners.models import DecisionModels
from hlp_drake.planner import HighLevelPlan
from hlp_drake.scene.model import Scene
from hlp_drake.systems.control_sequence import ControlSequence
from hlp_drake.systems.grasp import grasp_knots
from hlp_drake.systems.keypoint_ik import Keyframes
from hlp_drake.systems.planning import make_planning_diagram
from hlp_drake.systems.robot import TCP_FRAME
from hlp_drake.systems.rollout import pregrasp_check, reach_problem, simulation_failure
from hlp_drake.systems.rollout_pool import RolloutPool
from hlp_drake.systems.scene_models import fallen_objects, object_body, object_planar_poses
from hlp_drake.systems.sto import StoResult
from hlp_drake.systems.world import (
    add_position_trajectory,
    make_world_diagram,
    tcp_keypoint_height,
    world_plant,
)
from hlp_drake.systems.world_config import WorldConfig

SETTLE_S = 1.0  # simulated time after the trajectory ends, before objects are checked
MOVED_TOLERANCE = 0.01  # m: an object displaced further than this counts as moved
ACTION_COLOURS = {"start": Rgba(0.1, 0.1, 0.1, 1), "gap": Rgba(0.2, 0.7, 0.2, 1), "move": Rgba(0.85, 0.2, 0.2, 1),
                  "release": Rgba(0.6, 0.3, 0.8, 1), "target": Rgba(1.0, 0.55, 0.0, 1)}


@dataclass
class ExecutionResult:
    """Outcome of planning and executing one scene."""

    planner: str
    scene: Scene
    plan: HighLevelPlan
    keyframes: Keyframes
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

    def to_dict(self) -> dict[str, Any]:
        return {
            "planner": self.planner, "scene": self.scene.name, "success": self.success,
            "failure_reason": self.failure_reason, "plan": self.plan.to_dict(),
            "ik": {"ok": self.keyframes.ok, "failures": self.keyframes.failures},
            "robot_actuated_dofs": 10, "timings": self.timings, "objects_moved": self.objects_moved,
            "objects_dropped": self.objects_dropped, "target_distance": self.target_distance,
            "simulated_s": self.simulated_s, "iterations": self.iterations, "rollouts": self.rollouts,
            "optimisation": self.optimisation, "grasp_held": self.grasp_held,
        }


def draw_plan(meshcat: Meshcat, plan: HighLevelPlan, height: float) -> None:
    """The plan's keypoints as small spheres (coloured by action) and a polyline at tcp height."""
    meshcat.Delete("plan")
    for i, keypoint in enumerate(plan.keypoints):
        path = f"plan/{i:02d}_{keypoint.action}"
        meshcat.SetObject(path, Sphere(0.012), ACTION_COLOURS.get(keypoint.action, Rgba(0.5, 0.5, 0.5, 1)))
        meshcat.SetTransform(path, RigidTransform([keypoint.position[0], keypoint.position[1], height]))


def plan_and_execute(scene: Scene, *, planner: str = "hlp", models: DecisionModels | None = None,
                     config: WorldConfig | None = None, meshcat: Meshcat | None = None,
                     html: str | Path | None = None, pool: RolloutPool | None = None) -> ExecutionResult:
    """Plan ``scene`` with ``planner``, solve IK, optimise with the STO, execute with contact, and grasp.

    Success (the paper's test): the optimiser found a sequence whose rollout passes, and in the
    execution (the world at its own time step) the target ends inside the gripper's pre-grasp region
    (the tcp within the target's radius + ``config.sto.cost.pregrasp_margin`` horizontally, at grasp
    height) with no object off the table. Then the fingers close and the tcp lifts;
    ``grasp_held`` says whether the target came up with it (not part of success).

    Args:
        pool: rollout workers to use (a pool of ``config.sto.workers`` made here by default; its
            start-up time is reported as ``timings["pool_start_s"]``, outside ``optimise_s``).
    """
    config = config or WorldConfig()
    own_pool = pool is None
    pool = RolloutPool(config.sto.workers) if own_pool else pool
    try:
        result = _plan_and_execute(scene, planner, models, config, meshcat, html, pool)
        result.timings["pool_start_s"] = pool.startup_s if own_pool else 0.0
        return result
    finally:
        if own_pool:
            pool.close()


def _plan_and_execute(scene, planner, models, config, meshcat, html, pool) -> ExecutionResult:
    started = time.perf_counter()
    planning = make_planning_diagram(scene, planner=planner, models=models, config=config, pool=pool)
    context = planning.CreateDefaultContext()
    planning.GetInputPort("scene").FixValue(context, scene)
    plan: HighLevelPlan = planning.GetOutputPort("plan").Eval(context)
    planned = time.perf_counter()
    keyframes: Keyframes = planning.GetOutputPort("keyframes").Eval(context)
    trajectory = planning.GetOutputPort("trajectory").Eval(context)
    solved = time.perf_counter()
    result = ExecutionResult(planner, scene, plan, keyframes)
    result.timings = {"plan_s": planned - started, "ik_s": solved - planned, "optimise_s": 0.0}
    if not plan.ok:
        result.failure_reason = f"no plan: {plan.reason}"
    elif not keyframes.ok:
        result.failure_reason = "IK failed: " + "; ".join(keyframes.failures)
    if result.failure_reason is None:
        optimisation: StoResult = planning.GetOutputPort("optimisation").Eval(context)
        sequence = optimisation.sequence
        result.iterations, result.rollouts = optimisation.iterations, optimisation.rollouts
        result.optimisation = optimisation.to_dict()
        result.timings["optimise_s"] = optimisation.optimise_s
        if not optimisation.success:
            result.failure_reason = f"the optimiser found no solution: {optimisation.failure_reason}"
    else:  # nothing to optimise: the (partial) IK trajectory is executed for inspection only
        sequence = ControlSequence.from_trajectory(trajectory, config.sto.step_duration)
    optimised = time.perf_counter()
    _execute(result, sequence, config, meshcat, html)
    executed = time.perf_counter()
    result.success = result.failure_reason is None
    result.timings.update({"execute_s": executed - optimised, "total_s": executed - started})
    return result


def _execute(result: ExecutionResult, sequence: ControlSequence, config: WorldConfig,
             meshcat: Meshcat | None, html: str | Path | None) -> None:
    """Simulate ``sequence`` in the world, check the reach, then grasp and lift; fills ``result``."""
    scene = result.scene
    builder = DiagramBuilder()
    world = builder.AddSystem(make_world_diagram(scene, config, meshcat=meshcat))
    source = add_position_trajectory(builder, world, sequence.to_trajectory())
    simulator = Simulator(builder.Build())
    simulator.Initialize()
    plant, robot = world_plant(world)
    plant_context = plant.GetMyContextFromRoot(simulator.get_context())
    names = [o.name for o in scene.objects]
    before = object_planar_poses(plant, plant_context, names)
    if meshcat is not None:
        draw_plan(meshcat, result.plan, tcp_keypoint_height(scene, config))
        meshcat.StartRecording()
    try:
        simulator.AdvanceTo(sequence.duration + SETTLE_S)
        after = object_planar_poses(plant, plant_context, names)
        result.objects_moved = [n for n in names if n != scene.target.name
                                and np.hypot(*np.subtract(after[n][:2], before[n][:2])) > MOVED_TOLERANCE]
        result.objects_dropped = fallen_objects(plant, plant_context, scene)
        tcp = plant.GetFrameByName(TCP_FRAME, robot).CalcPoseInWorld(plant_context).translation()
        inside, result.target_distance = pregrasp_check(
            tcp, after[scene.target.name], scene, tcp_height=tcp_keypoint_height(scene, config),
            margin=config.sto.cost.pregrasp_margin)
        problem = reach_problem(result.objects_dropped, inside, result.target_distance)
        if problem is not None and result.failure_reason is None:
            result.failure_reason = f"in execution: {problem}"
        if problem is None:
            result.grasp_held = _grasp(simulator, source, sequence, config, plant, plant_context, scene)
    except (RuntimeError, SystemExit) as error:
        failure = simulation_failure(error)
        if result.failure_reason is None:
            result.failure_reason = f"simulation failed: {failure}"
    finally:
        result.simulated_s = float(simulator.get_context().get_time())
        if meshcat is not None:
            meshcat.StopRecording()
            meshcat.PublishRecording()
            if html is not None:
                write_text_atomic(html, meshcat.StaticHtml())


def _grasp(simulator, source, sequence, config, plant, plant_context, scene) -> bool:
    """Close the fingers at the reach's end pose and lift; whether the target rose with the gripper."""
    grasp = grasp_knots(sequence.knots[-1], config)
    if grasp is None:
        return False
    times, knots = grasp
    source.UpdateTrajectory(sequence.followed_by(np.concatenate([[SETTLE_S], SETTLE_S + times]),
                                                 np.vstack([sequence.knots[-1], knots])))
    target = object_body(plant, scene.target.name)
    z0 = target.EvalPoseInWorld(plant_context).translation()[2]
    simulator.AdvanceTo(sequence.duration + SETTLE_S + times[-1])
    return bool(target.EvalPoseInWorld(plant_context).translation()[2] - z0 >= config.grasp.held_height)
