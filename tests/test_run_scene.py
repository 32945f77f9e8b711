"""``python -m hlp_drake.run_scene`` end to end, the planning diagram and the push transfer."""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

from conftest import run_module
from hlp_drake.learners.bundled import default_models
from hlp_drake.planner import plan
from hlp_drake.planner.transfer import robot_plan
from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.io import scene_to_dict
from hlp_drake.systems.planning import make_planning_diagram
from hlp_drake.taskspace import DIRECTION_VECTORS, TaskSpace


def test_push_transfer_puts_the_tcp_behind_the_obstacle():
    scene = generate_scene("vr", 1)
    human = plan(scene, default_models())
    robot = robot_plan(human, scene)
    space = TaskSpace(scene)
    assert [k.action for k in robot.keypoints] == [k.action for k in human.keypoints]
    for k in robot.keypoints:
        if k.action == "move":
            rect, unit = space.rects[k.element], np.array(DIRECTION_VECTORS[k.direction], float)
            assert k.direction not in ("BB", "BL", "BR")  # the robot only pushes away or sideways
            # The push starts outside the obstacle, on the side opposite the push.
            offset = np.subtract(k.position, rect.center)
            assert offset @ unit < 0
            assert not rect.contains(np.array([k.position]))[0]


def test_planning_diagram_swaps_the_planner_block():
    scene = generate_scene("vr", 2)
    for planner, expected in (("hlp", None), ("sto", ["start", "target"])):
        diagram = make_planning_diagram(scene, planner=planner)
        context = diagram.CreateDefaultContext()
        diagram.GetInputPort("scene").FixValue(context, scene)
        actions = [k.action for k in diagram.GetOutputPort("plan").Eval(context).keypoints]
        assert actions[0] == "start" and actions[-1] == "target"
        if expected:
            assert actions == expected
        keyframes = diagram.GetOutputPort("keyframes").Eval(context)
        assert len(keyframes.success) == len(actions)


def test_run_scene_end_to_end_json(tmp_path):
    out = tmp_path / "run.json"
    result = run_module("hlp_drake.run_scene", "--kind", "vr", "--seed", "1", "--workers", "1", "--json", str(out))
    assert result.returncode in (0, 1), result.stderr
    report = json.loads(out.read_text())
    assert report["planner"] == "hlp" and report["robot_actuated_dofs"] == 10
    assert set(report["timings"]) >= {"plan_s", "ik_s", "optimise_s", "total_s"}
    assert [k["action"] for k in report["plan"]["keypoints"]][::len(report["plan"]["keypoints"]) - 1] == [
        "start", "target"]
    assert isinstance(report["objects_moved"], list) and isinstance(report["objects_dropped"], list)
    assert report["success"] == (result.returncode == 0) == (report["failure_reason"] is None)
    assert ("success" if report["success"] else "failure:") in result.stdout


def test_run_scene_bad_scene_file_is_one_line(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("table: [1, 2\n")
    out = tmp_path / "run.json"
    result = run_module("hlp_drake.run_scene", "--scene", str(bad), "--json", str(out))
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) >= 1 and all(line.startswith("error: ") for line in lines) and "Traceback" not in result.stderr
    assert not out.exists()
    scene = generate_scene("vr", 1)
    overlapping = tmp_path / "overlap.yaml"
    from dataclasses import replace

    second = replace(scene.obstacles[1], x=scene.obstacles[0].x, y=scene.obstacles[0].y)
    data = scene_to_dict(replace(scene, obstacles=(scene.obstacles[0], second, *scene.obstacles[2:])))
    overlapping.write_text(yaml.safe_dump(data))
    result = run_module("hlp_drake.run_scene", "--scene", str(overlapping), "--json", str(out))
    assert result.returncode == 2 and "overlap" in result.stderr and not out.exists()


def test_run_scene_without_arguments_runs_the_bundled_default(tmp_path):
    out = tmp_path / "default.json"
    result = run_module("hlp_drake.run_scene", "--json", str(out), cwd=tmp_path)
    assert result.returncode == 0, result.stdout + result.stderr
    report = json.loads(out.read_text())
    assert report["success"] and report["scene"].startswith("default") and report["objects_dropped"] == []
    assert any(k["action"] == "move" for k in report["plan"]["keypoints"])
    # The optimiser ran (on 2 worker processes by default) and the grasp was tried and held.
    assert report["rollouts"] >= 1 and report["iterations"] >= 0 and report["timings"]["optimise_s"] > 0
    assert report["optimisation"]["success"] and report["optimisation"]["final_cost"] <= report["optimisation"]["initial_cost"]
    assert report["grasp_held"] is True
    assert "rollouts" in result.stdout and "grasp: held" in result.stdout


def test_run_scene_rejects_a_bad_worker_count(tmp_path):
    out = tmp_path / "run.json"
    result = run_module("hlp_drake.run_scene", "--workers", "0", "--json", str(out))
    assert result.returncode == 2 and result.stderr.strip() == "error: --workers must be >= 1, got 0"
    assert not out.exists()


def test_pushes_stop_short_of_the_table_edge_and_the_other_objects():
    from hlp_drake.planner.transfer import EDGE_MARGIN, OBJECT_MARGIN, push_travel

    scene = generate_scene("gen1", 13)
    space = TaskSpace(scene)
    x_min, y_min, x_max, y_max = scene.table.bounds
    for name in scene_obstacle_names(scene):
        rect = space.rects[name]
        for unit in (np.array([0.0, 1.0]), np.array([0.0, -1.0]), np.array([1.0, 0.0])):
            travel = push_travel(space, scene, name, unit, 1.0)
            assert 0.0 <= travel < 1.0  # a 1 m push never fits on these tables
            dx, dy = travel * unit
            assert x_min + EDGE_MARGIN <= rect.x_min + dx and rect.x_max + dx <= x_max - EDGE_MARGIN
            assert y_min + EDGE_MARGIN <= rect.y_min + dy and rect.y_max + dy <= y_max - EDGE_MARGIN
            for other, r in space.rects.items():
                if other != name:
                    apart = (rect.x_min + dx >= r.x_max + OBJECT_MARGIN or r.x_min >= rect.x_max + dx + OBJECT_MARGIN
                             or rect.y_min + dy >= r.y_max + OBJECT_MARGIN or r.y_min >= rect.y_max + dy + OBJECT_MARGIN)
                    assert apart or travel == 0.0, (name, other, travel)
    # Unobstructed, the push goes as far as wanted.
    lone = scene_with_one_obstacle(scene)
    lone_space = TaskSpace(lone)
    assert push_travel(lone_space, lone, lone.obstacles[0].name, np.array([0.0, 1.0]), 0.02) == pytest.approx(0.02)


def scene_obstacle_names(scene):
    return [o.name for o in scene.obstacles]


def scene_with_one_obstacle(scene):
    from dataclasses import replace

    obstacle = replace(scene.obstacles[0], x=scene.table.length / 2, y=0.0)
    target = replace(scene.target, x=scene.table.length * 0.85, y=0.0)
    return replace(scene, obstacles=(obstacle,), target=target)
