"""HlpPlannerSystem and SceneFromPlant on their own: fix the input, evaluate the output."""

from __future__ import annotations

from dataclasses import replace

import pytest

from hlp_drake.learners.bundled import default_models
from hlp_drake.planner import plan
from hlp_drake.scene.generators import generate_scene
from hlp_drake.systems.planning.initialiser_blocks import HlpPlannerSystem


def test_plan_output_matches_the_planner_and_is_cached_by_drake():
    system = HlpPlannerSystem()
    context = system.CreateDefaultContext()
    scene = generate_scene("gen1", 4)
    system.get_scene_input_port().FixValue(context, scene)
    first = system.get_plan_output_port().Eval(context)
    assert first.ok
    assert first.to_dict()["keypoints"] == plan(scene, default_models()).to_dict()["keypoints"]
    assert system.get_plan_output_port().Eval(context) is first  # evaluated twice, planned once
    other = generate_scene("gen1", 5)
    system.get_scene_input_port().FixValue(context, other)
    assert system.get_plan_output_port().Eval(context).scene == other.name


def test_unconnected_input_is_a_clear_error():
    system = HlpPlannerSystem()
    with pytest.raises(RuntimeError, match="connect or fix its 'scene'"):
        system.get_plan_output_port().Eval(system.CreateDefaultContext())


def test_plans_from_the_plants_body_poses_in_a_diagram_and_again_when_an_object_moves():
    from pydrake.math import RigidTransform, RotationMatrix
    from pydrake.systems.framework import DiagramBuilder

    from hlp_drake.systems.scenario import Scenario
    from hlp_drake.systems.world.scene_models import object_body
    from hlp_drake.systems.world.scene_source import SceneFromPlant
    from hlp_drake.systems.world.world import make_world_diagram, world_plant

    scene = generate_scene("gen2", 3, 5)  # objects turned about z: their yaws go through quaternions
    builder = DiagramBuilder()
    world = builder.AddSystem(make_world_diagram(Scenario(scene=scene)))
    plant, _ = world_plant(world)
    source = builder.AddSystem(SceneFromPlant(plant, scene))
    planner = builder.AddSystem(HlpPlannerSystem())
    builder.Connect(world.GetOutputPort("body_poses"), source.get_body_poses_input_port())
    builder.Connect(source.get_scene_output_port(), planner.get_scene_input_port())
    builder.ExportOutput(planner.get_plan_output_port(), "plan")
    builder.ExportOutput(source.get_scene_output_port(), "scene")
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    # The objects rest where the scene puts them: the scene reads back exactly, and so does the plan.
    assert diagram.GetOutputPort("scene").Eval(context) is scene
    seen = diagram.GetOutputPort("plan").Eval(context)
    assert seen.ok and seen.to_dict()["keypoints"] == plan(scene, default_models()).to_dict()["keypoints"]
    moved = scene.obstacles[0]
    plant_context = plant.GetMyMutableContextFromRoot(context)
    X = RigidTransform(RotationMatrix.MakeZRotation(moved.yaw + 0.3), [moved.x, moved.y - 0.05, 1.0])
    plant.SetFreeBodyPose(plant_context, object_body(plant, moved.name), X)
    now = diagram.GetOutputPort("scene").Eval(context)
    assert now.obstacles[0].position == pytest.approx((moved.x, moved.y - 0.05))
    assert now.obstacles[0].yaw == pytest.approx(moved.yaw + 0.3) and now.obstacles[1:] == scene.obstacles[1:]
    again = diagram.GetOutputPort("plan").Eval(context)
    assert again is not seen
    assert (
        again.to_dict()["keypoints"]
        == plan(replace(scene, obstacles=now.obstacles), default_models()).to_dict()["keypoints"]
    )
