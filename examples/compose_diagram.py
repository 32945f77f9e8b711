from pydrake.systems.framework import DiagramBuilder

from hlp_drake.systems import (
    RolloutPool,
    SceneFromPlant,
    load_scenario,
    make_planning_diagram,
    make_world_diagram,
    world_plant,
)

scenario = load_scenario(data="planner: {low_level: {workers: 1}}")  # the default scene; the STO, 1 process
with RolloutPool(scenario.low_level.workers) as pool:  # the STO rolls out: its pool is yours to close
    builder = DiagramBuilder()
    world = builder.AddNamedSystem("world", make_world_diagram(scenario))
    plant, _ = world_plant(world)
    scene = builder.AddNamedSystem("scene", SceneFromPlant(plant, scenario.scene))
    planning = builder.AddNamedSystem("planning", make_planning_diagram(scenario, pool=pool))
    builder.Connect(world.GetOutputPort("body_poses"), scene.get_body_poses_input_port())
    builder.Connect(scene.get_scene_output_port(), planning.GetInputPort("scene"))
    diagram = builder.Build()

    context = diagram.CreateDefaultContext()
    planning_context = planning.GetMyContextFromRoot(context)
    robot_plan = planning.GetOutputPort("robot_plan").Eval(planning_context)
    print("robot plan:", " -> ".join(k.action for k in robot_plan.keypoints))
    result = planning.GetOutputPort("optimisation").Eval(planning_context)  # the low-level planner's
    print(f"optimised: success {result.success} after {result.rollouts} rollout(s)")

    # Move an obstacle in the plant: the same diagram plans again from the new body poses.
    obstacle = scenario.scene.obstacles[0]
    plant_context = plant.GetMyMutableContextFromRoot(context)
    body = plant.GetBodyByName(obstacle.name)
    pose = plant.GetFreeBodyPose(plant_context, body)
    pose.set_translation(pose.translation() + [0.0, 0.05, 0.0])
    plant.SetFreeBodyPose(plant_context, body, pose)
    moved = planning.GetOutputPort("plan").Eval(planning_context)
    print(f"after moving {obstacle.name}: {len(moved.keypoints)} keypoints")
