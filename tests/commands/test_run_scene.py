"""``python -m hlp_drake.run_scene`` end to end: its output, JSON, exit status, progress and bad input."""

from __future__ import annotations

import json
import os
from dataclasses import replace

import pytest
import yaml
from conftest import run_module
from meshcat_support import recorded, recorded_camera, three_js

from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.io import scene_to_dict
from hlp_drake.systems.conditions import Conditions
from hlp_drake.systems.execution.meshcat_view import camera_pose
from hlp_drake.systems.scenario import Scenario
from hlp_drake.systems.world.robot_description import MOBILE_UR5


def test_run_scene_end_to_end_json_and_html(tmp_path):
    out, html = tmp_path / "run.json", tmp_path / "run.html"
    result = run_module(
        "hlp_drake.run_scene",
        "--kind",
        "vr",
        "--seed",
        "1",
        "--workers",
        "1",
        "--json",
        str(out),
        "--html",
        str(html),
        env={"DRAKE_ALLOW_NETWORK": "meshcat"},  # a recording needs a local MeshCat server (CI sets none)
    )
    assert result.returncode in (0, 1) and "Traceback" not in result.stderr, result.stderr
    # The recording opens framed on the table from the person's side, the grid hidden, with both plans
    # as thick paths, the robot plan's markers and the legend, and no contact forces unless asked for.
    page = html.read_text()
    commands = recorded(page)
    eye, target = camera_pose(generate_scene("vr", 1))
    position, looked_at = recorded_camera(commands)
    assert position == pytest.approx(three_js(eye)) and looked_at == pytest.approx(three_js(target))
    for path in (
        b"/drake/plan/path/00",
        b"/drake/robot_plan/path/00",
        b"/drake/robot_plan/path/bend_01",
        b"/drake/robot_plan/00_start",
        b"/Grid",
    ):
        assert path in commands, path
    assert b"contact_forces" not in commands and b"animation" in commands
    assert 'id="hlp-legend"' in page and "the robot&#x27;s path" in page
    report = json.loads(out.read_text())
    assert report["planner"] == "hlp" and report["robot_actuated_dofs"] == 10
    # What ran: in the header, the summary and the JSON.
    ran = {
        "robot": MOBILE_UR5.name,
        "planner": "hlp",
        "initial": "hlp",
        "low_level": "sto",
        "execution": "open",
        "model_error_seed": None,
        "perception_source": "truth",
        "world": "reference",
        "scenario_file": None,
    }
    assert {key: report[key] for key in ran} == ran
    line = (
        f"robot {MOBILE_UR5.name}, initialiser hlp, low-level planner sto, execution open, model error none, "
    )
    line += "perception truth, world reference, scenario built-in default"
    assert result.stdout.count(f"run: {line}\n") == 1 and "ran: " not in result.stdout  # said once
    verdicts = [v for v in result.stdout.splitlines() if v.startswith("verdict: ")]
    assert len(verdicts) == 1 and verdicts[0].startswith(
        "verdict: reach success in the reference world (the paper's criterion, exit status 0); the planner's "
        "model: accepted; grasp "
        if report["success"]
        else "verdict: reach failure in the reference world: "
    )
    assert report["model_success"] is report["optimisation"]["success"]
    assert report["false_accept"] == (report["model_success"] and not report["success"])
    assert set(report["timings"]) >= {"plan_s", "ik_s", "optimise_s", "total_s"}
    assert [k["action"] for k in report["plan"]["keypoints"]][:: len(report["plan"]["keypoints"]) - 1] == [
        "start",
        "target",
    ]
    assert isinstance(report["objects_moved"], list) and isinstance(report["objects_dropped"], list)
    assert report["success"] == (result.returncode == 0) == (report["failure_reason"] is None)
    assert ("success" if report["success"] else "failure:") in result.stdout
    assert report["rollouts"] >= 1 and report["timings"]["optimise_s"] > 0
    assert report["optimisation"]["final_cost"] <= report["optimisation"]["initial_cost"]
    for stage in ("plan: start -> ", "IK: ", "optimise: ", "execute: "):  # each stage, as it happens
        assert stage in result.stdout, stage


@pytest.mark.slow  # ~20 s of CPU: the 2 ms execution with a re-optimisation every second
def test_run_scene_closed_loop_with_uncertainty_end_to_end(tmp_path):
    out, config = tmp_path / "run.json", tmp_path / "cheap.yaml"
    config.write_text(
        "planner: {low_level: {samples: 2, max_rollouts: 5, verify: false}}\n"
        "closed_loop: {replan_period: 1.0, iterations: 1, rollouts: 3}\n"
    )
    args = ["--kind", "gen1", "--seed", "7", "--workers", "1", "--config", str(config), "--json", str(out)]
    result = run_module("hlp_drake.run_scene", *args, "--execution", "closed", "--uncertainty", "5")
    assert result.returncode in (0, 1) and "Traceback" not in result.stderr, result.stderr
    report = json.loads(out.read_text())
    assert report["execution"] == "closed" and report["success"] == (result.returncode == 0)
    assert report["model_error_seed"] == 5 and report["scenario_file"] == str(config)
    assert f"execution closed, model error seed 5, perception truth, scenario {config}" in result.stdout
    loop = report["closed_loop"]
    assert loop["replans"] >= 1 and loop["replans"] <= loop["rollouts"] <= 3 * loop["replans"]
    assert "closed loop:" in result.stdout
    assert report["false_accept"] == (report["optimisation"]["success"] and not report["success"])


def test_what_ran_names_the_robot_initialiser_low_level_planner_execution_model_error_perception_and_file():
    from hlp_drake.config.what_ran import WhatRan
    from hlp_drake.systems.execution.result import what_ran

    plain = what_ran(Scenario())
    assert plain == WhatRan(
        (MOBILE_UR5.name,), ("hlp",), ("hlp",), ("sto",), ("open",), (None,), ("truth",), ("reference",)
    )
    assert plain.line() == (
        f"robot {MOBILE_UR5.name}, initialiser hlp, low-level planner sto, execution open, model error none, "
        "perception truth, world reference, scenario built-in default"
    )
    conditions = Conditions(initial="line", execution="closed", uncertainty=3, perception="camera")
    ran = what_ran(conditions.applied(Scenario()), "my.yaml")
    assert ran.line() == (
        f"robot {MOBILE_UR5.name}, initialiser line, low-level planner sto, execution closed, model error seed 3, "
        "perception camera, world reference, scenario my.yaml"
    )
    assert ran.to_dict() == {
        "robot": MOBILE_UR5.name,
        "planner": "sto",
        "initial": "line",
        "low_level": "sto",
        "execution": "closed",
        "model_error_seed": 3,
        "perception_source": "camera",
        "world": "reference",
        "scenario_file": "my.yaml",
    }
    assert WhatRan.from_dict(ran.to_dict()) == ran and WhatRan.from_dict({"planner": "hlp"}) is None
    both = replace(plain, planners=("hlp", "sto"), initials=("hlp", "line"), executions=("open", "closed"))
    assert "initialisers hlp and line, low-level planner sto, execution open and closed" in both.line()
    record = both.to_dict()
    assert record["planners"] == ["hlp", "sto"] and record["initials"] == ["hlp", "line"]
    assert record["low_level"] == "sto" and record["executions"] == ["open", "closed"]
    assert WhatRan.from_dict(record) == both


SUCCESS = "verdict: reach success in the reference world (the paper's criterion, exit status 0)"
FAILURE = "verdict: reach failure in the reference world: x (exit status 1); the planner's model: "


@pytest.mark.parametrize(
    ("success", "model", "grasp_held", "status", "line"),
    [
        (True, True, True, 0, f"{SUCCESS}; the planner's model: accepted; grasp held"),
        (True, True, False, 0, f"{SUCCESS}; the planner's model: accepted; grasp did not hold"),
        (
            False,
            True,
            None,
            1,
            FAILURE + "accepted: a false accept; grasp not attempted",
        ),
        (
            False,
            False,
            None,
            1,
            FAILURE + "not accepted; grasp not attempted",
        ),
    ],
)
def test_the_exit_status_follows_the_reach_whatever_the_grasp(success, model, grasp_held, status, line):
    from types import SimpleNamespace

    from hlp_drake.commands.run_scene import exit_status, verdict

    result = SimpleNamespace(
        success=success,
        grasp_held=grasp_held,
        grasp_failure=None,
        failure_reason=None if success else "x",
        world="reference",
        model_success=model,
        false_accept=model and not success,
    )
    assert exit_status(result) == status
    assert verdict(result) == f"{line} (reported, not part of success)"


def test_a_plan_on_a_perceived_scene_names_the_true_objects_with_the_perceived_names_beside():
    from hlp_drake.commands.progress import plan_steps
    from hlp_drake.planner import HighLevelPlan
    from hlp_drake.planner.plan import PlanKeypoint
    from hlp_drake.systems.execution.result import named_plan

    seen = HighLevelPlan(
        scene="seen",
        keypoints=(
            PlanKeypoint("start", (0.1, 0.0)),
            PlanKeypoint("move", (0.3, 0.0), row=1, element="object_2", direction="LL"),
            PlanKeypoint("release", (0.3, 0.1), row=1, element="object_2", direction="LL"),
            PlanKeypoint("gap", (0.4, 0.0), row=2, element="1"),
            PlanKeypoint("move", (0.5, 0.0), row=3, element="object_5", direction="RR"),
            PlanKeypoint("target", (0.6, 0.0), element="Target"),
        ),
    )
    names = {"object_2": "obstacle_9", "object_5": None, "Target": "Target"}
    assert plan_steps(seen, names) == (
        "start -> move obstacle_9 (seen as object_2) LL -> release -> gap 1 -> "
        "move object_5 (seen; matches no true object) RR -> target"
    )
    assert plan_steps(seen) == "start -> move object_2 LL -> release -> gap 1 -> move object_5 RR -> target"
    keypoints = named_plan(seen.to_dict(), names)["keypoints"]
    assert [(k["element"], k.get("perceived_as")) for k in keypoints] == [
        (None, None),
        ("obstacle_9", "object_2"),
        ("obstacle_9", "object_2"),
        ("1", None),
        (None, "object_5"),
        ("Target", "Target"),
    ]
    assert named_plan(seen.to_dict(), None) == seen.to_dict()


def test_a_run_logged_to_a_file_has_one_line_per_stage_and_no_carriage_returns(tmp_path):
    import subprocess
    import sys

    log = tmp_path / "run.log"
    with log.open("w") as file:  # stdout and stderr into one file, as `> run.log 2>&1`
        code = subprocess.run(
            [
                sys.executable,
                "-m",
                "hlp_drake.run_scene",
                "--workers",
                "1",
                "--html",
                str(tmp_path / "r.html"),
            ],
            stdout=file,
            stderr=subprocess.STDOUT,
            env={**os.environ, "DRAKE_ALLOW_NETWORK": "meshcat"},
            timeout=600,
            check=False,
        ).returncode
    text = log.read_text()
    assert code == 0 and "\r" not in text and "INFO:drake" not in text, text
    stages = ("scene ", "run: ", "plan: ", "IK: ", "optimise: ", "execute: ", "timings: ", "verdict: ")
    lines = text.splitlines()
    found = [next(i for i, line in enumerate(lines) if line.startswith(stage)) for stage in stages]
    assert found == sorted(found), text
    assert sum(line.startswith("optimise") for line in lines) == 1
    assert lines[-1] == f"wrote {tmp_path / 'r.html'}"


def test_progress_bars_only_on_a_terminal():
    import io
    from types import SimpleNamespace

    from hlp_drake.commands.progress import ProgressListener

    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    for stream, bars in ((io.StringIO(), False), (Terminal(), True)):
        listener = ProgressListener(stream=stream)
        listener.optimising("sto")
        listener.rollout(SimpleNamespace(cost=1.0))
        listener.executing(1.0)
        listener.simulated(0.5)
        listener.close()
        assert ("\r" in stream.getvalue()) == bars
    stream = Terminal()
    listener = ProgressListener(stream=stream)
    listener.optimising("sto")
    listener.rollout(SimpleNamespace(cost=1.0))
    listener.close()
    shown = stream.getvalue()
    assert "optimise: 0 rollouts [00:00, ? rollouts/s]" in shown and "0rollout" not in shown, shown
    quiet = Terminal()
    listener = ProgressListener(quiet=True, stream=quiet)
    listener.optimising("sto")
    listener.close()
    assert quiet.getvalue() == ""


def test_quiet_and_verbose_are_exclusive():
    result = run_module("hlp_drake.run_scene", "--quiet", "--verbose")
    assert result.returncode == 2
    assert result.stderr.startswith("error: argument --verbose: not allowed with argument --quiet")


def test_run_scene_bad_scene_file_is_one_line(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("table: [1, 2\n")
    out = tmp_path / "run.json"
    result = run_module("hlp_drake.run_scene", "--scene", str(bad), "--json", str(out))
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert (
        len(lines) >= 1
        and all(line.startswith("error: ") for line in lines)
        and "Traceback" not in result.stderr
    )
    assert not out.exists()
    scene = generate_scene("vr", 1)
    overlapping = tmp_path / "overlap.yaml"

    second = replace(scene.obstacles[1], x=scene.obstacles[0].x, y=scene.obstacles[0].y)
    data = scene_to_dict(replace(scene, obstacles=(scene.obstacles[0], second, *scene.obstacles[2:])))
    overlapping.write_text(yaml.safe_dump(data))
    result = run_module("hlp_drake.run_scene", "--scene", str(overlapping), "--json", str(out))
    assert result.returncode == 2 and "overlap" in result.stderr and not out.exists()


def test_run_scene_rejects_a_bad_execution_or_uncertainty_seed(tmp_path):
    out = tmp_path / "run.json"
    for args, problem in (
        (["--execution", "half"], "invalid choice: 'half'"),
        (["--uncertainty", "x"], "argument --uncertainty: expected an integer, got 'x'"),
    ):
        result = run_module("hlp_drake.run_scene", *args, "--json", str(out))
        assert result.returncode == 2 and problem in result.stderr and "Traceback" not in result.stderr
    assert not out.exists()


def test_run_scene_rejects_a_bad_worker_count(tmp_path):
    out = tmp_path / "run.json"
    result = run_module("hlp_drake.run_scene", "--workers", "0", "--json", str(out))
    assert result.returncode == 2
    assert result.stderr.strip().startswith("error: argument --workers: must be between 1 and 64, got 0")
    assert not out.exists()


def test_a_failed_closed_loop_execution_still_reports_what_the_controller_did(tmp_path):
    out, config = tmp_path / "run.json", tmp_path / "one_rollout.yaml"
    config.write_text(  # the straight line, never improved: it fails on this scene (as it did optimised)
        "planner: {low_level: {samples: 1, max_iterations: 1, max_rollouts: 1, verify: false}}\n"
        "closed_loop: {replan_period: 2.0, iterations: 1, rollouts: 1}\n"
    )
    args = ["--kind", "gen1", "--seed", "40", "--planner", "sto", "--workers", "1", "--config", str(config)]
    result = run_module("hlp_drake.run_scene", *args, "--execution", "closed", "--json", str(out))
    assert result.returncode == 1 and "Traceback" not in result.stderr, result.stderr
    report = json.loads(out.read_text())
    assert not report["success"] and "pre-grasp region" in report["failure_reason"]  # the world's verdict
    loop = report["closed_loop"]
    # one rollout per re-optimisation, and one more for the remainder where it re-planned the scene
    assert (
        loop["replans"] >= 1 and loop["replans"] <= loop["rollouts"] == loop["replans"] + loop["initialised"]
    )
    assert "closed loop:" in result.stdout


@pytest.mark.parametrize(
    ("module", "args", "line"),
    [
        (
            "hlp_drake.run_scene",
            ("--world", "moon"),
            "error: argument --world: invalid choice: 'moon' (choose from 'model', 'reference')",
        ),
        (
            "hlp_drake.experiments",
            ("gen1", "--world", "moon", "--out", "OUT"),
            "error: argument --world: invalid choice: 'moon' (choose from 'model', 'reference')",
        ),
        (
            "hlp_drake.run_scene",
            ("--config", "CONFIG"),
            "error: CONFIG: world.kind: expected one of model, reference",
        ),
    ],
)
def test_an_unknown_world_is_one_line_and_exit_status_2(tmp_path, module, args, line):
    config, out = tmp_path / "moon.yaml", tmp_path / "out"
    config.write_text("world: moon\n")
    args = [str(config) if a == "CONFIG" else str(out) if a == "OUT" else a for a in args]
    result = run_module(module, *args)
    line = line.replace("CONFIG", str(config))
    assert result.returncode == 2 and result.stdout == "", result.stdout
    assert len(result.stderr.splitlines()) == 1 and result.stderr.startswith(line), result.stderr
    assert not out.exists()
