"""HlpPlannerSystem on its own: fix the input, evaluate the plan output."""

from __future__ import annotations

from dataclasses import replace

import pytest

from hlp_drake.learners.bundled import default_models
from hlp_drake.planner import plan
from hlp_drake.scene.generators import generate_scene
from hlp_drake.systems.hlp_planner_system import HlpPlannerSystem


def test_plan_output_matches_the_planner_and_is_cached():
    system = HlpPlannerSystem()
    context = system.CreateDefaultContext()
    scene = generate_scene("gen1", 4)
    system.get_scene_input_port().FixValue(context, scene)
    first = system.get_plan_output_port().Eval(context)
    assert first.ok
    assert first.to_dict()["keypoints"] == plan(scene, default_models()).to_dict()["keypoints"]
    system.get_plan_output_port().Eval(context)
    assert system.plans_computed == 1  # evaluated twice, planned once
    moved = replace(scene, obstacles=(replace(scene.obstacles[0], y=scene.obstacles[0].y + 0.0004),
                                      *scene.obstacles[1:]))
    system.get_scene_input_port().FixValue(context, moved)
    system.get_plan_output_port().Eval(context)
    assert system.plans_computed == 1  # a sub-millimetre change keeps the plan
    other = generate_scene("gen1", 5)
    system.get_scene_input_port().FixValue(context, other)
    assert system.get_plan_output_port().Eval(context).scene == other.name
    assert system.plans_computed == 2


def test_unconnected_input_is_a_clear_error():
    system = HlpPlannerSystem()
    with pytest.raises(RuntimeError, match="connect or fix its 'scene'"):
        system.get_plan_output_port().Eval(system.CreateDefaultContext())


def test_plans_from_the_plants_body_poses_in_a_diagram():
    from pydrake.systems.framework import DiagramBuilder

    from hlp_drake.systems.world import make_world_diagram, world_plant

    scene = generate_scene("gen1", 3)
    builder = DiagramBuilder()
    world = builder.AddSystem(make_world_diagram(scene))
    plant, _ = world_plant(world)
    planner = builder.AddSystem(HlpPlannerSystem(plant=plant, template=scene))
    builder.Connect(world.GetOutputPort("body_poses"), planner.get_body_poses_input_port())
    builder.ExportOutput(planner.get_plan_output_port(), "plan")
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    seen = diagram.GetOutputPort("plan").Eval(context)
    # The objects rest where the scene puts them, so the plan equals the plan of the scene itself.
    assert seen.ok and seen.to_dict()["keypoints"] == plan(scene, default_models()).to_dict()["keypoints"]
