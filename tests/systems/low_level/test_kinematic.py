"""The kinematic low-level planners (``trajopt``, ``rrt``): their collision world alone, each planner
alone as a Drake block (fixed inputs, evaluated outputs), their fallback and budget, and through
``run_scene`` end to end."""

from __future__ import annotations

import json
import re
from itertools import pairwise

import numpy as np
import pytest
from sto_support import on

from hlp_drake.commands import command_main
from hlp_drake.commands.parsing import run_cli
from hlp_drake.scene.generators import generate_scene
from hlp_drake.systems.low_level.kinematic.rrt import RrtConfig, RrtPlanner
from hlp_drake.systems.low_level.kinematic.trajopt import TrajoptConfig, TrajoptPlanner
from hlp_drake.systems.low_level.kinematic.waypoints import allowed_objects, sub_goals
from hlp_drake.systems.low_level.kinematic.world import KinematicWorld
from hlp_drake.systems.low_level.protocol import LowLevelContext
from hlp_drake.systems.low_level.registry import low_level_entry
from hlp_drake.systems.low_level.system import LowLevelPlannerSystem
from hlp_drake.systems.planning.diagram import make_planning_diagram

DETOUR_SEED = 33
"""A Generalization I scene whose human-like plan has a leg that no straight motion takes clear."""


def initialised(scene, initial: str):
    """(keyframes, initial trajectory) of ``initial`` on ``scene``."""
    diagram = make_planning_diagram(on(scene, f"planner: {{initial: {initial}}}"))
    context = diagram.CreateDefaultContext()
    diagram.GetInputPort("scene").FixValue(context, scene)
    return diagram.GetOutputPort("keyframes").Eval(context), diagram.GetOutputPort("trajectory").Eval(context)


@pytest.fixture(scope="module")
def detour():
    scene = generate_scene("gen1", DETOUR_SEED)
    return scene, *initialised(scene, "hlp")


def block_result(planner, scene, keyframes, trajectory):
    """``planner`` as a Drake block with fixed inputs; its evaluated result."""
    block = LowLevelPlannerSystem(planner)
    context = block.CreateDefaultContext()
    block.get_scene_input_port().FixValue(context, scene)
    block.get_keyframes_input_port().FixValue(context, keyframes)
    block.get_initial_trajectory_input_port().FixValue(context, trajectory)
    return block.get_result_output_port().Eval(context)


def test_the_world_forbids_what_the_plan_does_not_push(scene, trajectories):
    keyframes, _ = initialised(scene, "hlp")
    pushed = allowed_objects(scene, keyframes)
    assert pushed == {"Target", "FailOnTouchObstacleLong", "FailOnTouchObstacleMed-1"}
    assert allowed_objects(scene, None) == {"Target"}  # the straight line pushes nothing
    goal = sub_goals(trajectories["line"])[-1]
    world = KinematicWorld(scene, on(scene).world_model, {"Target"})
    world.touching({"Target"})
    assert [name for name, _ in world.contacts(goal)] == ["FailOnTouchObstacleMed-1"]
    assert not world.free(goal)
    world.touching({"Target", "FailOnTouchObstacleMed-1"})
    assert world.free(goal) and world.contacts(goal) == []
    world.touching(())  # and back: only what the leg names
    assert [name for name, _ in world.contacts(goal)] == ["FailOnTouchObstacleMed-1"]


def test_sub_goals_are_the_initial_trajectorys_knots(trajectories):
    goals = sub_goals(trajectories["hlp"])
    times = trajectories["hlp"].get_segment_times()
    assert len(goals) == len(times) and np.allclose(goals[0], trajectories["hlp"].value(0.0).ravel())
    assert np.allclose(goals[-1], trajectories["hlp"].value(times[-1]).ravel())


@pytest.mark.parametrize(
    ("planner_class", "config"), [(RrtPlanner, RrtConfig()), (TrajoptPlanner, TrajoptConfig())]
)
def test_each_planner_alone_detours_around_what_it_may_not_touch(detour, planner_class, config):
    scene, keyframes, trajectory = detour
    model = on(scene).world_model
    planner = planner_class(config, LowLevelContext(model))
    result = block_result(planner, scene, keyframes, trajectory)
    assert result.success and result.low_level == planner.kind and result.fallback == ""
    assert result.iterations >= 1 and result.rollouts == 0  # one leg needed the planner
    knots = result.sequence.knots
    assert np.allclose(knots[0], sub_goals(trajectory)[0]) and np.allclose(
        knots[-1], sub_goals(trajectory)[-1]
    )
    world = KinematicWorld(scene, model, allowed_objects(scene, keyframes))
    world.touching(scene.target.name for _ in [0])  # what the last leg may touch at most
    fingers = list(model.robot.finger_columns)
    grip = knots.copy()
    grip[:, fingers] = np.max(knots[:, fingers])
    touched = {name for a, b in pairwise(grip) for name, _ in world.contacts(b)}
    assert touched <= {"Target", "FailOnTouchObstacleShort", "FailOnTouchObstacleMed"} | world.allowed
    assert "table" not in touched
    speeds = np.linalg.norm(np.diff([world.tcp(q) for q in knots], axis=0), axis=1) / result.sequence.steps
    assert np.max(speeds) <= config.timing.tcp_speed + 1e-6  # timed at the tcp's speed


@pytest.mark.parametrize("kind", ["trajopt", "rrt"])
def test_each_planner_in_the_planning_diagram_needs_no_pool(detour, kind):
    scene, _, trajectory = detour
    diagram = make_planning_diagram(on(scene, f"planner: {{low_level: {{kind: {kind}}}}}"))  # no pool given
    context = diagram.CreateDefaultContext()
    diagram.GetInputPort("scene").FixValue(context, scene)
    result = diagram.GetOutputPort("optimisation").Eval(context)
    assert result.success and result.low_level == kind and result.iterations >= 1
    planned = diagram.GetOutputPort("optimised_trajectory").Eval(context)
    assert np.allclose(planned.value(planned.end_time()).ravel(), sub_goals(trajectory)[-1])


def test_rrt_is_deterministic_per_seed(detour):
    scene, keyframes, trajectory = detour
    model = on(scene).world_model

    def knots(seed: int) -> np.ndarray:
        planner = RrtPlanner(RrtConfig(seed=seed, shortcut=False), LowLevelContext(model))
        return block_result(planner, scene, keyframes, trajectory).sequence.knots

    first = knots(0)
    assert np.array_equal(first, knots(0))
    assert not np.array_equal(first, knots(5))


def test_a_planner_out_of_budget_fails_with_its_reason_or_falls_back(detour):
    scene, keyframes, trajectory = detour
    model = on(scene).world_model
    strict = RrtPlanner(RrtConfig(iterations=1, fallback=False), LowLevelContext(model))
    result = block_result(strict, scene, keyframes, trajectory)
    assert not result.success and result.failure_reason == "rrt found no path in 1 iterations"
    lenient = RrtPlanner(RrtConfig(iterations=1), LowLevelContext(model))
    result = block_result(lenient, scene, keyframes, trajectory)
    assert result.success and result.fallback.startswith(
        "contact allowed with every object (rrt found no path"
    )


@pytest.mark.parametrize("kind", ["trajopt", "rrt"])
def test_run_scene_names_the_planner_and_succeeds_on_the_default_scene(kind, tmp_path, capsys):
    out = tmp_path / "run.json"
    status = run_cli(command_main("run-scene"), ["--low-level", kind, "--quiet", "--json", str(out)])
    report = json.loads(out.read_text())
    assert report["low_level"] == kind and report["optimisation"]["low_level"] == kind
    assert report["planner"] == f"hlp+{kind}" and report["rollouts"] == 0
    assert status == 0 and report["success"], report["failure_reason"]
    assert low_level_entry(kind).rolls_out is False
    timings = [line for line in capsys.readouterr().out.splitlines() if line.startswith("timings:")]
    assert timings and re.search(rf", {kind} \d+\.\d\d s", timings[0]), timings


@pytest.mark.parametrize(
    ("settings", "message"),
    [
        ("{kind: rrt, iterations: 0}", "planner.low_level.iterations"),
        ("{kind: trajopt, samples: 1}", "planner.low_level.samples"),
        ("{kind: rrt, timing: {tcp_speed: -1}}", "planner.low_level.timing.tcp_speed"),
        ("{kind: prm}", "unknown low-level planner"),
    ],
)
def test_a_bad_planner_setting_is_one_line_and_exit_2(settings, message, tmp_path, capsys):
    config = tmp_path / "bad.yaml"
    config.write_text(f"planner:\n  low_level: {settings}\n")
    assert run_cli(command_main("run-scene"), ["--config", str(config), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert run_cli(command_main("run-scene"), ["--low-level", "prm"]) == 2
