"""``python -m hlp_drake.run_scene`` end to end, the planning diagram and the push transfer."""

from __future__ import annotations

import json

import numpy as np
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
