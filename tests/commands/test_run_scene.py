"""``python -m hlp_drake.run_scene`` end to end, the planning diagram and the push transfer."""

from __future__ import annotations

import dataclasses
import json
import os
from dataclasses import replace
from itertools import pairwise

import numpy as np
import pytest
import yaml
from conftest import run_module
from human_plans import GEN1_19, GEN1_27, GEN2_9_12, GEN2_9_39, GEN2_9_39_NEXT, human_plan

from hlp_drake.learners.bundled import default_models
from hlp_drake.planner import plan
from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.io import scene_to_dict
from hlp_drake.systems.execution.meshcat_view import camera_pose
from hlp_drake.systems.planning.diagram import make_planning_diagram
from hlp_drake.systems.planning.transfer import gripper_geometry
from hlp_drake.systems.scenario import Scenario, with_conditions
from hlp_drake.systems.world.robot_description import MOBILE_UR5
from hlp_drake.taskspace import DIRECTION_VECTORS, TaskSpace
from hlp_drake.transfer.push import ROBOT_ACTIONS, robot_alternatives, robot_plan
from hlp_drake.transfer.rules import TransferConfig, push_rules

RULES = push_rules(TransferConfig(), gripper_geometry())


def test_the_transfers_clearances_are_the_robot_models_sizes_plus_the_margins():
    geometry = gripper_geometry()  # the tcp 14 cm ahead of the flange, the fingertips 2 cm ahead of it
    sizes = {"tcp_offset": 0.14, "fingertip_reach": 0.02, "finger_half_width": 0.055, "wrist_radius": 0.045}
    assert dataclasses.asdict(geometry) == sizes
    clearances = {
        "forward_clearance": 0.05,
        "sideways_clearance": 0.075,
        "corridor_half_width": 0.08,
        "way_clearance": 0.055,
        "transit_clearance": 0.07,
        "arm_shadow_length": 0.35,
        "arm_shadow_half_width": 0.06,
    }
    assert {name: getattr(RULES, name) for name in clearances} == clearances
    wider = push_rules(TransferConfig(sideways_margin=0.03), geometry)
    assert wider.sideways_clearance == 0.085 and wider.forward_clearance == RULES.forward_clearance


def test_push_transfer_puts_the_tcp_behind_the_obstacle():
    scene = generate_scene("vr", 0)
    human = plan(scene, default_models())
    robot = robot_plan(human, scene, RULES)
    space = TaskSpace(scene)
    assert [k.action for k in robot.keypoints if k.action != "transit"] == [k.action for k in human.keypoints]
    assert {k.action for k in robot.keypoints} <= set(ROBOT_ACTIONS)
    lifted = max(o.size[2] for o in scene.objects) + 0.07
    transits = [i for i, k in enumerate(robot.keypoints) if k.action == "transit"]
    for i in transits[1::2]:  # lifted above the previous waypoint, then above the next one
        before, up, over, after = robot.keypoints[i - 2 : i + 2]
        assert (up.position, over.position) == (before.position, after.position)
        assert up.height == over.height == pytest.approx(lifted)
    for k in robot.keypoints:
        if k.action == "move":
            assert k.height is None
            rect, unit = space.rects[k.element], np.array(DIRECTION_VECTORS[k.direction], float)
            assert k.direction not in ("BB", "BL", "BR")  # the robot only pushes away or sideways
            # The push starts outside the obstacle, on the side opposite the push.
            offset = np.subtract(k.position, rect.center)
            assert offset @ unit < 0
            assert not rect.contains(np.array([k.position]))[0]


def test_robot_alternatives_are_the_next_distinct_candidates_in_rank_order():
    scene = generate_scene("gen2", 39, 9)
    human = human_plan(scene, GEN2_9_39, GEN2_9_39_NEXT)
    chosen = robot_plan(human, scene, RULES)
    candidates = [
        robot_plan(replace(human, keypoints=c.keypoints), scene, RULES).keypoints for c in human.alternatives
    ]
    alternatives = robot_alternatives(human, scene, RULES, 3)
    assert len(alternatives) == 3 and all(a.ok for a in alternatives)
    found = [a.keypoints for a in alternatives]
    assert len({chosen.keypoints, *found}) == 4  # distinct from the chosen plan and from each other
    ranks = [candidates.index(k) for k in found]
    assert ranks == sorted(ranks)  # best first, the first of equal robot plans
    assert all(k in (chosen.keypoints, *found) for k in candidates[: ranks[-1]])  # none skipped
    assert robot_alternatives(human, scene, RULES, 1) == alternatives[:1]
    assert robot_alternatives(human, scene, RULES, 0) == ()
    assert robot_alternatives(replace(human, keypoints=(), reason="no plan"), scene, RULES, 3) == ()


def test_planning_diagram_swaps_the_planner_block():
    scene = generate_scene("vr", 2)
    for planner, expected in (("hlp", None), ("sto", ["start", "target"])):
        diagram = make_planning_diagram(Scenario(scene=scene).updated(f"planner: {{kind: {planner}}}"))
        context = diagram.CreateDefaultContext()
        diagram.GetInputPort("scene").FixValue(context, scene)
        actions = [k.action for k in diagram.GetOutputPort("plan").Eval(context).keypoints]
        assert actions[0] == "start" and actions[-1] == "target"
        if expected:
            assert actions == expected
        keyframes = diagram.GetOutputPort("keyframes").Eval(context)
        assert len(keyframes.success) == len(actions)


def recorded(html: str) -> bytes:
    """The MeshCat commands a static HTML recording replays (its base64 data URLs, decoded)."""
    import base64
    import re

    return b"".join(base64.b64decode(b) for b in re.findall(r"base64,([A-Za-z0-9+/=]+)\"\)", html))


def messages(html: str) -> list[dict]:
    """The MeshCat messages a static HTML recording replays, decoded (MessagePack)."""
    import base64
    import re

    import msgpack

    found = re.findall(r"base64,([A-Za-z0-9+/=]+)\"\)", html)
    return [msgpack.unpackb(base64.b64decode(b), raw=False, strict_map_key=False) for b in found]


def animation_tracks(html: str) -> dict[str, dict[str, list[tuple[int, object]]]]:
    """The recording's animation: per scene-tree path, per track (``.position``, ``.visible``, ...),
    its (frame, value) keys."""
    (animation,) = [m for m in messages(html) if m["type"] == "set_animation"]
    return {
        a["path"]: {t["name"]: [(k["time"], k["value"]) for k in t["keys"]] for t in a["clip"]["tracks"]}
        for a in animation["animations"]
    }


def three_js(point) -> tuple[float, float, float]:
    """A world point (z up) in MeshCat's three.js frame (y up): (x, z, -y)."""
    x, y, z = (float(v) for v in point)
    return x, z, -y


def recorded_camera(commands: bytes) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """The camera's position and target (three.js frame) last set in a recording's ``commands``
    (MessagePack: a 3-array of float64 after the property's or the message's name)."""
    import struct

    def triple(marker: bytes) -> tuple[float, ...]:
        at = commands.rindex(marker) + len(marker)
        at = commands.index(b"value\x93", at) + len(b"value\x93")
        values = []
        for _ in range(3):
            assert commands[at] == 0xCB, commands[at : at + 9]  # float64
            values.append(struct.unpack(">d", commands[at + 1 : at + 9])[0])
            at += 9
        return tuple(values)

    return triple(b"/Cameras/default/rotated/<object>\xa8property\xa8position"), triple(b"set_target")


@pytest.mark.parametrize(
    "scene",
    [generate_scene("vr", 1), generate_scene("gen1", 3), generate_scene("gen2", 4, 9)],
    ids=lambda scene: scene.name,
)
def test_the_view_looks_at_the_table_from_the_persons_side_and_fills_the_frame(scene):
    """MeshCat's camera (a 75 degree vertical field of view; a 1280 x 800 window): above the person's
    side (x < 0), 55 degrees up, to the left (the arm reaches from the right); every corner of the
    table top in view, the table over nearly half of the frame's width (0.47-0.6 on Gen I and II)."""
    eye, target = camera_pose(scene)
    table = scene.table
    view = target - eye
    assert eye[0] < 0.0 < target[0] < table.length and eye[1] > 0.0
    assert np.degrees(np.arcsin(-view[2] / np.linalg.norm(view))) == pytest.approx(55.0)
    forward = view / np.linalg.norm(view)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    focal = 1.0 / np.tan(np.radians(75.0) / 2.0)
    corners = [(x, y, table.height) for x in (0.0, table.length) for y in (-table.width / 2, table.width / 2)]
    seen = np.array(
        [
            (focal * (d @ right) / (d @ forward) / 1.6, focal * (d @ up) / (d @ forward))
            for d in np.array(corners) - eye
        ]
    )
    assert np.all(np.abs(seen) < 1.0), seen  # normalised image coordinates
    assert np.ptp(seen[:, 0]) / 2.0 > 0.45


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
        "execution": "open",
        "model_error_seed": None,
        "perception_source": "truth",
        "scenario_file": None,
    }
    assert {key: report[key] for key in ran} == ran
    line = f"robot {MOBILE_UR5.name}, planner hlp, execution open, model error none, perception truth, "
    line += "scenario built-in default"
    assert f"run: {line}\n" in result.stdout and f"ran: {line}\n" in result.stdout
    verdicts = [v for v in result.stdout.splitlines() if v.startswith("verdict: ")]
    assert len(verdicts) == 1 and verdicts[0].startswith(
        "verdict: reach success (the paper's criterion, exit status 0); grasp "
        if report["success"]
        else "verdict: reach failure: "
    )
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


def test_the_recording_highlights_each_pushed_obstacle_while_it_is_pushed_and_says_what_ran(tmp_path):
    """The default scene's two pushes: each obstacle's highlight is hidden at the start, shown from
    about when the robot starts pushing it (it has barely moved yet) to its release (it has moved
    several centimetres meanwhile), then hidden; the heading names the scene and the verdict."""
    out, html = tmp_path / "run.json", tmp_path / "run.html"
    args = ("--workers", "1", "--quiet", "--json", str(out), "--html", str(html))
    result = run_module("hlp_drake.run_scene", *args, env={"DRAKE_ALLOW_NETWORK": "meshcat"})
    assert result.returncode == 0, result.stderr
    report = json.loads(out.read_text())
    moves = [k["element"] for k in report["plan"]["keypoints"] if k["action"] == "move"]
    page = html.read_text()
    tracks = animation_tracks(page)
    highlighted = {
        path.split("/")[3]: t[".visible"] for path, t in tracks.items() if path.endswith("/pushed")
    }
    assert sorted(highlighted) == sorted(moves) and len(moves) == 2
    for name, keys in highlighted.items():
        assert [shown for _, shown in keys] == [False, True, False], (name, keys)
        start, end = keys[1][0], keys[2][0]
        position = np.array([value for _, value in tracks[f"/drake/visualizer/{name}/{name}"][".position"]])
        before = np.linalg.norm(position[start, :2] - position[0, :2])
        during = np.linalg.norm(position[end, :2] - position[start, :2])
        assert during > 0.05 and before < 0.25 * during, (name, before, during)
    title = "scene default (gen1 seed 3), human-like planner on the true scene: reach success, grasp "
    assert title in page and 'id="hlp-clock"' in page


@pytest.mark.slow  # ~20 s of CPU: the 2 ms execution with a re-optimisation every second
def test_run_scene_closed_loop_with_uncertainty_end_to_end(tmp_path):
    out, config = tmp_path / "run.json", tmp_path / "cheap.yaml"
    config.write_text(
        "optimiser: {samples: 2, max_rollouts: 5, verify: false}\n"
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
    assert report["rollout_passed_execution_failed"] == (
        report["optimisation"]["success"] and not report["success"]
    )


def test_what_ran_names_the_robot_planner_execution_model_error_perception_and_scenario_file():
    from hlp_drake.config.what_ran import WhatRan
    from hlp_drake.systems.execution.result import what_ran

    plain = what_ran(Scenario())
    assert plain == WhatRan(MOBILE_UR5.name, ("hlp",), "open", None, "truth", None)
    assert plain.line() == (
        f"robot {MOBILE_UR5.name}, planner hlp, execution open, model error none, perception truth, "
        "scenario built-in default"
    )
    changed = with_conditions(
        Scenario().updated("planner: {kind: sto}"), execution="closed", uncertainty=3, perception="camera"
    )
    ran = what_ran(changed, "my.yaml")
    assert ran.line() == (
        f"robot {MOBILE_UR5.name}, planner sto, execution closed, model error seed 3, perception camera, "
        "scenario my.yaml"
    )
    assert ran.to_dict() == {
        "robot": MOBILE_UR5.name,
        "planner": "sto",
        "execution": "closed",
        "model_error_seed": 3,
        "perception_source": "camera",
        "scenario_file": "my.yaml",
    }
    assert WhatRan.from_dict(ran.to_dict()) == ran and WhatRan.from_dict({"planner": "hlp"}) is None
    both = what_ran(Scenario(), planners=("hlp", "sto"))
    assert "planners hlp and sto" in both.line() and both.to_dict()["planners"] == ["hlp", "sto"]
    assert WhatRan.from_dict(both.to_dict()) == both


@pytest.mark.parametrize(
    ("success", "grasp_held", "status", "line"),
    [
        (True, True, 0, "verdict: reach success (the paper's criterion, exit status 0); grasp held"),
        (True, False, 0, "verdict: reach success (the paper's criterion, exit status 0); grasp did not hold"),
        (False, None, 1, "verdict: reach failure: in execution: x (exit status 1); grasp not attempted"),
    ],
)
def test_the_exit_status_follows_the_reach_whatever_the_grasp(success, grasp_held, status, line):
    from types import SimpleNamespace

    from hlp_drake.commands.run_scene import exit_status, verdict

    result = SimpleNamespace(
        success=success,
        grasp_held=grasp_held,
        grasp_failure=None,
        failure_reason=None if success else "in execution: x",
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
    stages = ("scene ", "run: ", "plan: ", "IK: ", "optimise: ", "execute: ", "ran: ", "verdict: ")
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
        listener.optimising()
        listener.rollout(SimpleNamespace(cost=1.0))
        listener.executing(1.0)
        listener.simulated(0.5)
        listener.close()
        assert ("\r" in stream.getvalue()) == bars
    quiet = Terminal()
    listener = ProgressListener(quiet=True, stream=quiet)
    listener.optimising()
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
    from dataclasses import replace

    second = replace(scene.obstacles[1], x=scene.obstacles[0].x, y=scene.obstacles[0].y)
    data = scene_to_dict(replace(scene, obstacles=(scene.obstacles[0], second, *scene.obstacles[2:])))
    overlapping.write_text(yaml.safe_dump(data))
    result = run_module("hlp_drake.run_scene", "--scene", str(overlapping), "--json", str(out))
    assert result.returncode == 2 and "overlap" in result.stderr and not out.exists()


def test_run_scene_rejects_a_bad_execution_or_uncertainty_seed(tmp_path):
    out = tmp_path / "run.json"
    for args, problem in (
        (["--execution", "half"], "invalid choice: 'half'"),
        (["--uncertainty", "x"], "invalid int value: 'x'"),
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


def test_pushes_stop_short_of_the_table_edge_and_the_other_objects():
    from hlp_drake.transfer.push import push_travel

    EDGE_MARGIN, OBJECT_MARGIN = RULES.edge_margin, RULES.object_margin

    scene = generate_scene("gen1", 13)
    space = TaskSpace(scene)
    x_min, y_min, x_max, y_max = scene.table.bounds
    for name in scene_obstacle_names(scene):
        rect = space.rects[name]
        for unit in (np.array([0.0, 1.0]), np.array([0.0, -1.0]), np.array([1.0, 0.0])):
            travel = push_travel(RULES, space, scene, name, unit, 1.0)
            assert 0.0 <= travel < 1.0  # a 1 m push never fits on these tables
            dx, dy = travel * unit
            assert x_min + EDGE_MARGIN <= rect.x_min + dx and rect.x_max + dx <= x_max - EDGE_MARGIN
            assert y_min + EDGE_MARGIN <= rect.y_min + dy and rect.y_max + dy <= y_max - EDGE_MARGIN
            for other, r in space.rects.items():
                if other != name:
                    apart = (
                        rect.x_min + dx >= r.x_max + OBJECT_MARGIN
                        or r.x_min >= rect.x_max + dx + OBJECT_MARGIN
                        or rect.y_min + dy >= r.y_max + OBJECT_MARGIN
                        or r.y_min >= rect.y_max + dy + OBJECT_MARGIN
                    )
                    assert apart or travel == 0.0, (name, other, travel)
    # Unobstructed, the push goes as far as wanted.
    lone = scene_with_one_obstacle(scene)
    lone_space = TaskSpace(lone)
    assert push_travel(
        RULES, lone_space, lone, lone.obstacles[0].name, np.array([0.0, 1.0]), 0.02
    ) == pytest.approx(0.02)


def test_pushes_stop_short_of_where_earlier_pushes_left_the_other_objects():
    from hlp_drake.taskspace import Rect
    from hlp_drake.transfer.push import push_travel

    OBJECT_MARGIN = RULES.object_margin

    scene = generate_scene("gen1", 13)
    space = TaskSpace(scene)
    name, other = scene_obstacle_names(scene)[:2]
    rect = space.rects[name]
    unit = np.array([0.0, 1.0])
    # Another object moved to 5 cm beyond the pushed one's left face: the push stops 1 cm short of it.
    moved = dict(space.rects)
    moved[other] = Rect(rect.x_min, rect.y_max + 0.05, rect.x_max, rect.y_max + 0.10)
    travel = push_travel(RULES, space, scene, name, unit, 0.2, footprints=moved)
    assert (
        travel == pytest.approx(0.05 - OBJECT_MARGIN, abs=0.005 + 1e-9)
        and travel < 0.05 - OBJECT_MARGIN + 1e-9
    )
    # With every other object pushed far away, nothing but the table's edge limits it.
    cleared = {n: (r if n == name else Rect(-10.0, -10.0, -9.9, -9.9)) for n, r in space.rects.items()}
    assert push_travel(RULES, space, scene, name, unit, 0.2, footprints=cleared) >= push_travel(
        RULES, space, scene, name, unit, 0.2
    )


def scene_obstacle_names(scene):
    return [o.name for o in scene.obstacles]


def scene_with_one_obstacle(scene):
    from dataclasses import replace

    obstacle = replace(scene.obstacles[0], x=scene.table.length / 2, y=0.0)
    target = replace(scene.target, x=scene.table.length * 0.85, y=0.0)
    return replace(scene, obstacles=(obstacle,), target=target)


def test_a_push_with_no_room_to_move_the_obstacle_is_left_out():
    from hlp_drake.transfer.push import _robot_direction, _unit, _wanted, push_travel

    MIN_PUSH_TRAVEL = RULES.min_push_travel

    # gen1 seed 27: the person's plan moves FailOnTouchObstacleMed back-left (for the robot a push
    # to the left), then pushes FailOnTouchObstacleLong-1 to the right; the first push has no room,
    # so the robot plan leaves it out and keeps the second.
    scene = generate_scene("gen1", 27)
    space = TaskSpace(scene)
    human = human_plan(scene, GEN1_27)
    robot = robot_plan(human, scene, RULES)
    moves = [(k.element, k.direction) for k in human.keypoints if k.action == "move"]
    assert moves == [("FailOnTouchObstacleMed", "BL"), ("FailOnTouchObstacleLong-1", "RR")]
    name = moves[0][0]
    direction = _robot_direction(RULES, space, scene, name, moves[0][1])
    wanted = _wanted(space, name, direction)
    assert wanted > MIN_PUSH_TRAVEL > push_travel(RULES, space, scene, name, _unit(direction), wanted)
    pushes = [k for k in robot.keypoints if k.action in ("move", "release")]
    assert [(k.action, k.element) for k in pushes] == [("move", moves[1][0]), ("release", moves[1][0])]
    assert np.hypot(*np.subtract(pushes[1].position, pushes[0].position)) >= MIN_PUSH_TRAVEL


def test_an_obstacle_already_near_an_edge_can_be_pushed_along_it_but_not_towards_it():
    from hlp_drake.transfer.push import push_travel

    EDGE_MARGIN = RULES.edge_margin

    scene = generate_scene("gen1", 13)
    lone = scene_with_one_obstacle(scene)
    obstacle = lone.obstacles[0]
    half = TaskSpace(lone).rects[obstacle.name].width / 2
    y_max = lone.table.bounds[3]
    near = replace(
        lone, obstacles=(replace(obstacle, y=y_max - half - EDGE_MARGIN / 2),)
    )  # 1.5 cm from the edge
    space = TaskSpace(near)
    assert push_travel(RULES, space, near, obstacle.name, np.array([1.0, 0.0]), 0.05) == pytest.approx(0.05)
    assert push_travel(RULES, space, near, obstacle.name, np.array([0.0, 1.0]), 0.05) == 0.0
    assert push_travel(RULES, space, near, obstacle.name, np.array([0.0, -1.0]), 0.05) == pytest.approx(0.05)


def test_a_backward_move_becomes_the_sideways_push_that_clears_the_corridor():
    from hlp_drake.transfer.push import _robot_direction

    scene = generate_scene("gen1", 14)
    space = TaskSpace(scene)
    # Long lies right of the start-target line (y = 0) with Short close on its right: pushed right it
    # moves 4 cm out of the corridor, pushed left it would cross the line. Both count as backward.
    assert scene.start[1] == scene.target.y == 0.0
    long = space.rects["FailOnTouchObstacleLong"]
    assert long.center[1] < 0.0 < long.y_max
    for direction in ("BL", "BR", "BB"):
        assert _robot_direction(RULES, space, scene, "FailOnTouchObstacleLong", direction) == "RR"
    # On the left of the line, with room on both sides, it goes left whatever the person's side.
    assert {
        _robot_direction(RULES, space, scene, "FailOnTouchObstacleMed", d) for d in ("BL", "BR", "BB")
    } == {"LL"}
    # Forward and sideways moves are kept.
    assert _robot_direction(RULES, space, scene, "FailOnTouchObstacleLong", "LL") == "LL"
    assert _robot_direction(RULES, space, scene, "FailOnTouchObstacleLong", "FR") == "FR"


def _websocket_frames(url: str, *, seconds: float) -> bytes:
    """Every payload a WebSocket server at ``url`` (ws://host:port) sends in ``seconds`` (a minimal
    client: the upgrade handshake, then unmasked server frames read until the time is up)."""
    import base64
    import os
    import socket
    import time

    host, port = url.removeprefix("ws://").split(":")
    with socket.create_connection((host, int(port)), timeout=seconds) as sock:
        key = base64.b64encode(os.urandom(16)).decode()
        sock.sendall(
            (
                f"GET / HTTP/1.1\r\nHost: {host}:{port}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                f"Sec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n\r\n"
            ).encode()
        )
        data, deadline = b"", time.monotonic() + seconds
        while time.monotonic() < deadline:
            sock.settimeout(max(deadline - time.monotonic(), 0.01))
            try:
                chunk = sock.recv(1 << 16)
            except TimeoutError:
                break
            if not chunk:
                break
            data += chunk
    header, _, frames = data.partition(b"\r\n\r\n")
    assert header.startswith(b"HTTP/1.1 101"), header[:100]
    payloads, i = b"", 0
    while i + 2 <= len(frames):
        length, i = frames[i + 1] & 0x7F, i + 2
        if length == 126:
            length, i = int.from_bytes(frames[i : i + 2], "big"), i + 2
        elif length == 127:
            length, i = int.from_bytes(frames[i : i + 8], "big"), i + 8
        payloads += frames[i : i + length]
        i += length
    return payloads


def test_run_scene_meshcat_serves_the_run_live(tmp_path):
    """``--meshcat``: the URL is printed, the viewer page is served, a browser's WebSocket receives
    the robot, the objects, the plans' path lines and the robot plan's keypoints, and Ctrl-C ends
    the run cleanly."""
    import signal
    import subprocess
    import sys
    import urllib.request

    out = tmp_path / "run.json"
    process = subprocess.Popen(
        [sys.executable, "-m", "hlp_drake.run_scene", "--meshcat", "--workers", "1", "--json", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, "DRAKE_ALLOW_NETWORK": "meshcat"},
    )
    try:
        lines = []
        for line in process.stdout:
            lines.append(line)
            if "keeps serving" in line:
                break
        url = next(
            (line.split("MeshCat: ")[1].strip() for line in lines if line.startswith("MeshCat: ")), None
        )
        if url is None:
            pytest.skip(
                f"MeshCat did not start here: {process.stderr.read() if process.poll() is not None else lines}"
            )
        page = urllib.request.urlopen(url, timeout=10).read()
        assert b"<title>Drake MeshCat</title>" in page
        scene_tree = _websocket_frames(url.replace("http://", "ws://"), seconds=3.0)
        for path in (
            b"/drake/robot_plan/00_start",
            b"/drake/robot_plan/path",
            b"/drake/plan/path",
            b"mobile_ur5",
            b"Target",
            b"table",
        ):
            assert path in scene_tree, path
        process.send_signal(signal.SIGINT)
        assert process.wait(timeout=30) == 0
    finally:
        if process.poll() is None:
            process.kill()
    assert json.loads(out.read_text())["success"] is True


def test_transit_goes_over_the_objects_where_the_arm_can_come_down():
    from hlp_drake.planner.plan import PlanKeypoint
    from hlp_drake.taskspace import Rect
    from hlp_drake.transfer.push import transit

    ARM_SHADOW_LENGTH = RULES.arm_shadow_length

    previous = PlanKeypoint("release", (0.30, -0.20), row=0, element="a")
    push = PlanKeypoint("move", (0.60, 0.20), row=1, element="b", direction="RR")
    # Nothing under the arm at the push start: up, across, and straight down onto it.
    beside = [Rect(0.10, -0.50, 0.15, -0.40), Rect(0.40, 0.27, 0.45, 0.35), Rect(0.62, 0.15, 0.70, 0.25)]
    up, over = transit(RULES, previous, push, 0.25, beside)
    assert (up.position, over.position) == (previous.position, push.position)
    assert up.action == over.action == "transit" and up.height == over.height == 0.25
    assert (over.row, over.element) == (push.row, push.element)
    # An object under the wrist there: no transit, the push start is reached at push height.
    assert transit(RULES, previous, push, 0.25, [*beside, Rect(0.40, 0.25, 0.45, 0.30)]) == []
    assert (
        transit(
            RULES,
            previous,
            push,
            0.25,
            [Rect(0.60 - ARM_SHADOW_LENGTH - 0.05, 0.1, 0.60 - ARM_SHADOW_LENGTH + 0.01, 0.3)],
        )
        == []
    )
    assert (
        len(
            transit(
                RULES,
                previous,
                push,
                0.25,
                [Rect(0.60 - ARM_SHADOW_LENGTH - 0.05, 0.1, 0.60 - ARM_SHADOW_LENGTH - 0.01, 0.3)],
            )
        )
        == 2
    )


def test_a_way_that_would_pass_over_an_object_goes_over_it():
    from hlp_drake.taskspace import Rect
    from hlp_drake.transfer.push import crosses, transit_height

    PATH_CLEARANCE = RULES.path_clearance

    box = Rect(0.40, 0.00, 0.50, 0.10)
    assert crosses(RULES, (0.30, 0.05), (0.60, 0.05), [box])  # straight through
    assert crosses(RULES, (0.30, 0.10 + PATH_CLEARANCE - 0.005), (0.60, 0.10 + PATH_CLEARANCE - 0.005), [box])
    assert not crosses(
        RULES, (0.30, 0.10 + PATH_CLEARANCE + 0.005), (0.60, 0.10 + PATH_CLEARANCE + 0.005), [box]
    )
    assert not crosses(RULES, (0.30, 0.05), (0.60, 0.05), [])
    # gen2 seed 12, 9 obstacles: from where obstacle_4's push ends, the way to the next gap would
    # sweep the gripper through obstacle_5 at push height; the robot plan goes over it instead.
    scene = generate_scene("gen2", 12, 9)
    space = TaskSpace(scene)
    keypoints = robot_plan(human_plan(scene, GEN2_9_12), scene, RULES).keypoints
    i = next(i for i, k in enumerate(keypoints) if k.action == "release" and k.element == "obstacle_4")
    release, up, over, gap = keypoints[i : i + 4]
    assert crosses(RULES, release.position, gap.position, [space.rects["obstacle_5"]])
    assert (up.action, over.action, gap.action) == ("transit", "transit", "gap")
    assert (up.position, over.position) == (release.position, gap.position)
    assert up.height == over.height == pytest.approx(transit_height(RULES, scene))


def test_a_push_that_would_leave_the_obstacle_in_the_way_goes_another_way():
    from hlp_drake.transfer.push import chosen_push, crosses, robot_push

    WAY_CLEARANCE = RULES.way_clearance

    # gen1 seed 19: the person moves FailOnTouchObstacleLong-1 forwards, over the table; pushed
    # forwards it would end up across the way to the target (and shove the target off the table).
    scene = generate_scene("gen1", 19)
    space = TaskSpace(scene)
    human = human_plan(scene, GEN1_19)
    i = next(i for i, k in enumerate(human.keypoints) if k.action == "move")
    move, rest = human.keypoints[i], human.keypoints[i + 1 :]
    assert (move.element, move.direction) == ("FailOnTouchObstacleLong-1", "FF")
    ways = [k.position for k in rest if k.action in ("gap", "target")]

    def in_the_way(push):
        points = [push.end, *ways]
        return any(
            crosses(RULES, a, b, [push.footprint], clearance=WAY_CLEARANCE) for a, b in pairwise(points)
        )

    forwards = robot_push(RULES, space, scene, move.element, "FF", space.rects)
    assert forwards.travel > 0.0 and in_the_way(forwards)
    push = chosen_push(RULES, space, scene, move, rest, space.rects)
    assert push.direction in ("LL", "RR") and not in_the_way(push) and push.travel >= 0.01
    # Of the sideways pushes that clear the way, the one that moves the obstacle furthest.
    sideways = [robot_push(RULES, space, scene, move.element, d, space.rects) for d in ("LL", "RR")]
    assert push.travel == max(p.travel for p in sideways if not in_the_way(p) and p.travel >= 0.01)
    robot = robot_plan(human, scene, RULES)
    assert [(k.action, k.direction) for k in robot.keypoints if k.action in ("move", "release")] == [
        ("move", push.direction),
        ("release", push.direction),
    ]
    # Pushes already clear of the way keep the person's direction (gen1 seed 3: right, then left).
    scene = generate_scene("gen1", 3)
    human = plan(scene, default_models())
    robot = robot_plan(human, scene, RULES)
    assert (
        [k.direction for k in robot.keypoints if k.action == "move"]
        == [k.direction for k in human.keypoints if k.action == "move"]
        == ["RR", "LL"]
    )


def test_the_gripper_slides_onto_the_target_along_its_approach_axis():
    from hlp_drake.taskspace import Rect
    from hlp_drake.transfer.push import approach

    APPROACH_GAP, GRIPPER_AHEAD = RULES.approach_gap, RULES.gripper_ahead

    target = Rect(0.70, -0.03, 0.76, 0.03)
    # Coming in 35 degrees off +x: a waypoint APPROACH_GAP behind the target's back face, in line.
    (point,) = approach(RULES, (0.50, -0.14), target, {"t": target}, "t")
    assert point.action == "approach" and point.element == "t"
    assert point.position == pytest.approx((0.70 - APPROACH_GAP, 0.0))
    assert point.position[0] + GRIPPER_AHEAD < target.x_min  # the fingertips stop short of it
    # Already in line (within 15 degrees): none; an object where the gripper would be: none.
    assert approach(RULES, (0.40, 0.05), target, {"t": target}, "t") == []
    blocker = Rect(0.60, 0.04, 0.66, 0.10)
    assert approach(RULES, (0.50, -0.14), target, {"t": target, "b": blocker}, "t") == []
    # In a plan: gen1 seed 18 comes to the target from a gap 9 cm to its side.
    scene = generate_scene("gen1", 18)
    keypoints = robot_plan(plan(scene, default_models()), scene, RULES).keypoints
    before, last = keypoints[-2:]
    space = TaskSpace(scene)
    assert (before.action, last.action) == ("approach", "target")
    assert before.position == pytest.approx(
        (space.rects[scene.target.name].x_min - APPROACH_GAP, scene.target.y)
    )


def test_a_failed_closed_loop_execution_still_reports_what_the_controller_did(tmp_path):
    out, config = tmp_path / "run.json", tmp_path / "one_rollout.yaml"
    config.write_text(  # the straight line, never improved: it fails on this scene (as it did optimised)
        "optimiser: {samples: 1, max_iterations: 1, max_rollouts: 1, verify: false}\n"
        "closed_loop: {replan_period: 2.0, iterations: 1, rollouts: 1}\n"
    )
    args = ["--kind", "gen1", "--seed", "46", "--planner", "sto", "--workers", "1", "--config", str(config)]
    result = run_module("hlp_drake.run_scene", *args, "--execution", "closed", "--json", str(out))
    assert result.returncode == 1 and "Traceback" not in result.stderr, result.stderr
    report = json.loads(out.read_text())
    assert not report["success"] and report["failure_reason"].startswith("in execution")
    loop = report["closed_loop"]
    # one rollout per re-optimisation, and one more for the remainder where it re-planned the scene
    assert (
        loop["replans"] >= 1 and loop["replans"] <= loop["rollouts"] == loop["replans"] + loop["initialised"]
    )
    assert "closed loop:" in result.stdout
