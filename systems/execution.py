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
from hlp_drake.systems.keypoint_ik import Keyframes
from hlp_drake.systems.planning import make_planning_diagram
from hlp_drake.systems.robot import TCP_FRAME
from hlp_drake.systems.scene_models import fallen_objects, object_planar_poses
from hlp_drake.systems.world import add_position_trajectory, make_world_diagram, tcp_keypoint_height, world_plant
from hlp_drake.systems.world_config import WorldConfig

SETTLE_S = 1.0  # simulated time after the trajectory ends, before objects are checked
MOVED_TOLERANCE = 0.01  # m: an object displaced further than this counts as moved
PREGRASP_MARGIN = 0.03  # m: the target is inside the pre-grasp region when the tcp is this close
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

    def to_dict(self) -> dict[str, Any]:
        return {
            "planner": self.planner, "scene": self.scene.name, "success": self.success,
            "failure_reason": self.failure_reason, "plan": self.plan.to_dict(),
            "ik": {"ok": self.keyframes.ok, "failures": self.keyframes.failures},
            "robot_actuated_dofs": 10, "timings": self.timings, "objects_moved": self.objects_moved,
            "objects_dropped": self.objects_dropped, "target_distance": self.target_distance,
            "simulated_s": self.simulated_s, "iterations": self.iterations, "rollouts": self.rollouts,
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
                     html: str | Path | None = None) -> ExecutionResult:
    """Plan ``scene`` with ``planner``, solve IK, and execute the joint trajectory with contact.

    Success (the paper's test): at the end the target is inside the gripper's pre-grasp region (the
    tcp within the target's radius + 3 cm horizontally, at grasp height) and no object fell off the
    table.
    """
    config = config or WorldConfig()
    started = time.perf_counter()
    planning = make_planning_diagram(scene, planner=planner, models=models, config=config)
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

    builder = DiagramBuilder()
    world = builder.AddSystem(make_world_diagram(scene, config, meshcat=meshcat))
    add_position_trajectory(builder, world, trajectory)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    simulator.Initialize()
    plant, robot = world_plant(world)
    plant_context = plant.GetMyContextFromRoot(simulator.get_context())
    before = object_planar_poses(plant, plant_context, [o.name for o in scene.objects])
    if meshcat is not None:
        draw_plan(meshcat, plan, tcp_keypoint_height(scene, config))
        meshcat.StartRecording()
    duration = trajectory.end_time() + SETTLE_S
    try:
        simulator.AdvanceTo(duration)
    except RuntimeError as error:
        result.failure_reason = f"simulation failed: {str(error).splitlines()[0]}"
    if meshcat is not None:
        meshcat.StopRecording()
        meshcat.PublishRecording()
        if html is not None:
            write_text_atomic(html, meshcat.StaticHtml())
    executed = time.perf_counter()
    result.simulated_s = float(simulator.get_context().get_time())
    after = object_planar_poses(plant, plant_context, [o.name for o in scene.objects])
    result.objects_moved = [n for n in before if np.hypot(*(np.subtract(after[n][:2], before[n][:2]))) > MOVED_TOLERANCE
                            and n != scene.target.name]
    result.objects_dropped = fallen_objects(plant, plant_context, scene)
    tcp = plant.GetFrameByName(TCP_FRAME, robot).CalcPoseInWorld(plant_context).translation()
    target = np.array(after[scene.target.name][:2])
    result.target_distance = float(np.hypot(*(tcp[:2] - target)))
    inside = (result.target_distance <= scene.target.size[0] / 2.0 + PREGRASP_MARGIN
              and abs(tcp[2] - tcp_keypoint_height(scene, config)) <= PREGRASP_MARGIN)
    if result.failure_reason is None:
        if result.objects_dropped:
            result.failure_reason = f"objects fell off the table: {', '.join(result.objects_dropped)}"
        elif not inside:
            result.failure_reason = f"the target is not in the gripper's pre-grasp region (tcp {result.target_distance:.3f} m away)"
    result.success = result.failure_reason is None
    result.timings.update({"execute_s": executed - solved, "total_s": executed - started})
    return result
