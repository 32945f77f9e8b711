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
