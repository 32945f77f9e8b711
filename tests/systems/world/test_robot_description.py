"""Robots as data: ``RobotDescription``, the shipped robots, a user's own robot, and bad descriptions."""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import REPO

from hlp_drake.commands.parsing import SHIPPED_ROBOTS
from hlp_drake.errors import HlpError
from hlp_drake.scene.generators import GEN1, generate_scene
from hlp_drake.scene.io import default_scene
from hlp_drake.scene.scaled import scaled_to_reach
from hlp_drake.scene.workspace import Workspace, within_reach
from hlp_drake.systems import Scenario, load_scenario
from hlp_drake.systems.conditions import Conditions
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.sto.planar_noise import planar_maps, planar_shift
from hlp_drake.systems.world.robot_description import MOBILE_UR5, BaseConfig, RobotDescription, load_robot
from hlp_drake.systems.world.start_pose import kinematic_robot

EXAMPLE = REPO / "examples" / "own_robot.py"


@pytest.fixture(scope="module")
def own_robot(tmp_path_factory) -> Path:
    """The README's worked example: a 6-DOF arm's URDF and description written into a folder."""
    folder = tmp_path_factory.mktemp("my_robot")
    subprocess.run([sys.executable, str(EXAMPLE), "--out", str(folder)], check=True, capture_output=True)
    return folder / "arm6.yaml"


def test_the_default_robot_is_the_shipped_mobile_ur5():
    assert load_robot("mobile_ur5") == MOBILE_UR5 == Scenario().robot
    assert MOBILE_UR5.position_names[:3] == MOBILE_UR5.base_joints and MOBILE_UR5.workspace is None


@pytest.mark.parametrize("name", SHIPPED_ROBOTS)
def test_every_shipped_robot_loads_and_matches_its_model(name):
    robot = load_robot(name)
    assert robot.name == name and robot.problems() == []
    plant, instance = kinematic_robot(robot)
    assert plant.num_positions(instance) == len(robot.position_names)
    assert [
        plant.get_joint_actuator(i).joint().name() for i in plant.GetJointActuatorIndices(instance)
    ] == list(robot.actuated_joints)


def test_a_scenario_file_names_its_robot_and_its_relative_model(own_robot):
    scenario_file = own_robot.parent / "scenario.yaml"
    scenario_file.write_text(yaml.safe_dump({"robot": _as_mapping(own_robot)}))
    scenario = load_scenario(scenario_file)
    assert scenario.robot.name == "arm6"
    assert Path(scenario.robot.model) == (own_robot.parent / "arm6.urdf").resolve()
    assert scenario.robot == load_robot(own_robot)


def _broken(own_robot: Path, tmp_path: Path, old: str, new: str) -> Path:
    text = own_robot.read_text()
    assert old in text
    path = tmp_path / "broken.yaml"
    path.write_text(
        text.replace(old, new).replace("model: arm6.urdf", f"model: {own_robot.parent / 'arm6.urdf'}")
    )
    return path


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("joint_6]", "joint_66]", "robot.arm_joints: the model has no joint 'joint_66'"),
        ("tcp_frame: tcp", "tcp_frame: tool", "robot.tcp_frame: the model has no frame 'tool'"),
        ("gripper_open: 0.04", "gripper_open: 0.0", "gripper_open: the gripper has no opening"),
        (
            "gripper_open: 0.04",
            "gripper_open: 0.2",
            "robot.gripper_open: 0.2 m is outside joint 'left_finger_joint'",
        ),
        ("pose: [-0.25, 0.0, 0.0]", "pose: [-3.0, 0.0, 0.0]", "base.pose: (-3.0, 0.0) is 3.00 m from"),
        ("frame: pedestal", "frame: plinth", "robot.base.frame: the model has no frame 'plinth'"),
        (
            "gripper_joint: left_finger_joint",
            "gripper_joint: palm_joint",
            "robot.gripper_joint: joint 'palm_joint' is weld, expected prismatic",
        ),
    ],
)
def test_a_bad_description_is_one_line_naming_the_field(own_robot, tmp_path, old, new, message):
    path = _broken(own_robot, tmp_path, old, new)
    with pytest.raises(HlpError) as error:
        load_scenario(data=f"robot: {json.dumps(_as_mapping(path))}")
    assert any(message in problem for problem in error.value.problems), error.value.problems


def _as_mapping(path: Path) -> dict:
    return yaml.safe_load(path.read_text())


def test_a_model_that_does_not_parse_is_one_line(tmp_path):
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'></robot>")
    robot = replace(MOBILE_UR5, name="bad", model=str(bad))
    with pytest.raises(HlpError, match=r"^robot.model: .*bad.urdf cannot be parsed"):
        Scenario(robot=robot)


def test_a_missing_model_file_is_named_by_its_description_file(own_robot, tmp_path):
    description = tmp_path / "arm.yaml"
    description.write_text(own_robot.read_text().replace("model: arm6.urdf", "model: gone.urdf"))
    assert "model: gone.urdf" in description.read_text()
    with pytest.raises(HlpError) as error:
        load_robot(description)
    assert error.value.problems == (f"{description}: model: {tmp_path / 'gone.urdf'} does not exist",)
    robot = replace(MOBILE_UR5, name="gone", model=str(tmp_path / "gone.urdf"))  # in a scenario
    with pytest.raises(HlpError) as error:
        Scenario(robot=robot)
    assert error.value.problems == (f"robot.model: {tmp_path / 'gone.urdf'} does not exist",)
    (empty := tmp_path / "empty.yaml").write_text("")  # not the mobile UR5 under another name
    with pytest.raises(HlpError, match="empty.yaml: the file is empty"):
        load_robot(empty)


def test_the_command_line_names_an_unknown_robot_and_a_bad_description(own_robot, tmp_path):
    def run(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run(
            [sys.executable, "-m", "hlp_drake.run_scene", *args],
            capture_output=True,
            text=True,
            timeout=300,
            check=False,
        )

    unknown = run("--robot", "r2d2")
    assert unknown.returncode == 2 and "Traceback" not in unknown.stderr
    assert "robot 'r2d2': not a shipped robot (mobile_ur5, iiwa14, panda)" in unknown.stderr
    broken = run("--robot", str(_broken(own_robot, tmp_path, "joint_6]", "joint_7]")))
    assert broken.returncode == 2 and broken.stderr.strip().splitlines() == [
        "error: robot.arm_joints: the model has no joint 'joint_7'"
    ]


def test_generated_tables_stay_within_a_fixed_robots_reach():
    workspace = Workspace(x=-0.15, y=0.0, reach=0.9)
    ranges = within_reach(GEN1, workspace)
    assert 0.5 < ranges.table_length[1] / GEN1.table_length[1] < 1.0
    for seed in range(20):
        for scene in (
            generate_scene("gen1", seed, workspace=workspace),
            generate_scene("gen2", seed, 7, workspace),
        ):
            for x, y in (scene.start, (scene.target.x, scene.target.y)):
                assert np.hypot(x - workspace.x, y - workspace.y) <= workspace.reach + 1e-9
    assert within_reach(GEN1, None) == GEN1 == within_reach(GEN1, Workspace(-0.1, 0.0, 5.0))
    with pytest.raises(HlpError, match="reaches too little"):
        within_reach(GEN1, Workspace(x=-0.15, y=0.0, reach=0.3))


def test_a_fixed_robots_gen2_tables_hold_as_much_clutter_for_their_size_as_the_mobile_robots():
    def coverage(workspace: Workspace | None) -> float:  # obstacle footprint / table area, mean of 30
        shares = []
        for seed in range(30):
            scene = generate_scene("gen2", seed, 7, workspace)
            area = sum(
                o.size[0] * o.size[1] * (np.pi / 4 if o.shape == "cylinder" else 1.0) for o in scene.obstacles
            )
            shares.append(area / (scene.table.length * scene.table.width))
        return float(np.mean(shares))

    workspace = Workspace(x=-0.3, y=0.0, reach=0.88)
    assert within_reach(GEN1, workspace).table_length[1] < 0.7 * GEN1.table_length[1]
    assert coverage(workspace) == pytest.approx(coverage(None), rel=0.15)
    heights = [o.size[2] for seed in range(30) for o in generate_scene("gen2", seed, 7, workspace).obstacles]
    assert max(heights) > 0.18  # heights are not scaled


def test_a_fixed_arms_planar_noise_moves_its_tcp_in_the_plane(own_robot):
    robot = load_robot(own_robot)
    plant, instance = kinematic_robot(robot)
    context = plant.CreateDefaultContext()
    home = np.concatenate([robot.home, [robot.gripper_open] * 2])
    sequence = ControlSequence(np.array([0.0, 1.0, 2.0]), np.vstack([home, home, home]))
    maps = planar_maps(robot, sequence.knots)
    assert maps.shape == (3, len(home), 3) and np.all(maps[:, list(robot.finger_columns)] == 0)
    moved = planar_shift(robot, sequence)(np.array([[0.01, 0.0, 0.0], [0.0, 0.01, 0.0]]))
    tcp = plant.GetFrameByName(robot.tcp_frame, instance)

    def position(q):
        plant.SetPositions(context, instance, q)
        return tcp.CalcPoseInWorld(context).translation()

    np.testing.assert_allclose(position(moved.knots[0]), position(home))  # the start stays
    np.testing.assert_allclose(position(moved.knots[1]) - position(home), [0.01, 0.0, 0.0], atol=5e-4)
    np.testing.assert_allclose(position(moved.knots[2]) - position(home), [0.01, 0.01, 0.0], atol=5e-4)
    mobile = ControlSequence(np.array([0.0, 1.0]), np.zeros((2, 11)))
    velocity = np.array([[0.1, 0.2, 0.3]])
    np.testing.assert_array_equal(  # a mobile base takes the noise on its own joints, as before
        planar_shift(MOBILE_UR5, mobile)(velocity).knots, mobile.with_base_velocity(velocity).knots
    )


def test_a_description_needs_a_frame_and_reach_for_a_fixed_base():
    fixed = replace(MOBILE_UR5, base=BaseConfig(kind="fixed"))
    problems = fixed.problems()
    assert any(p.startswith("robot.base.frame:") for p in problems)
    assert any(p.startswith("robot.reach:") for p in problems)
    assert RobotDescription(home=(0.0,)).problems() == ["robot.home: 1 angles for 6 arm joints"]


def test_a_users_own_arm_runs_a_scene_end_to_end(own_robot, tmp_path):
    out = tmp_path / "run.json"
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "hlp_drake.run_scene",
            "--robot",
            str(own_robot),
            "--kind",
            "gen1",
            "--seed",
            "4",
            "--quiet",
            "--json",
            str(out),
        ],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert "Traceback" not in result.stderr, result.stderr
    assert "run: robot arm6, initialiser hlp, low-level planner sto" in result.stdout
    record = json.loads(out.read_text())
    assert record["robot"] == "arm6" and record["robot_actuated_dofs"] == 7  # 6 joints and a gripper
    assert result.returncode == 0, result.stdout + result.stderr


@pytest.mark.parametrize("name", ["panda", "iiwa14", "own"])
def test_the_default_scene_is_scaled_as_the_generators_scale_gen1_seed_3(name, own_robot):
    robot = load_robot(own_robot if name == "own" else name)
    scene = Conditions(robot=str(own_robot if name == "own" else name)).applied(Scenario()).scene
    generated = generate_scene("gen1", 3, workspace=robot.workspace)  # the default is gen1 seed 3
    assert scene.name.startswith(f"default (gen1 seed 3), scaled to the {robot.name}'s reach x0.")
    assert (scene.table, scene.start) == (generated.table, generated.start)
    for mine, theirs in zip((scene.target, *scene.obstacles), (generated.target, *generated.obstacles)):
        assert mine.name == theirs.name
        np.testing.assert_allclose(
            [mine.x, mine.y, *mine.size], [theirs.x, theirs.y, *theirs.size], atol=2e-4
        )
    for x, y in (scene.start, (scene.target.x, scene.target.y)):
        assert np.hypot(x - robot.workspace.x, y - robot.workspace.y) <= robot.workspace.reach
    assert Conditions().applied(Scenario(robot=robot)).scene == scene  # the scenario's own robot: the same


def test_only_the_default_scene_is_scaled_and_only_for_a_fixed_robot():
    panda = load_robot("panda")
    assert Conditions().applied(Scenario()).scene is default_scene()  # the mobile UR5's own
    mine = replace(default_scene(), name="mine")  # a user's scene is never changed
    assert Conditions(robot="panda").applied(Scenario(), scene=mine).scene is mine
    assert scaled_to_reach(mine, None, "mobile_ur5") is mine
    assert scaled_to_reach(mine, panda.workspace, "panda").table.length < 0.6 * mine.table.length


@pytest.mark.parametrize("name", ["panda", "iiwa14", "own"])
def test_every_fixed_robot_reaches_the_target_on_the_default_scene(name, own_robot, tmp_path):
    """``run_scene --robot R`` with no scene: the bundled default, scaled to R's reach, succeeds in the
    reference world (the paper's success)."""
    out = tmp_path / "run.json"
    robot = str(own_robot) if name == "own" else name
    result = subprocess.run(
        [sys.executable, "-m", "hlp_drake.run_scene", "--robot", robot, "--workers", "1", "--quiet"]
        + ["--json", str(out)],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert "Traceback" not in result.stderr, result.stderr
    label = "arm6" if name == "own" else name
    assert result.stdout.startswith(f"scene default (gen1 seed 3), scaled to the {label}'s reach x0.")
    record = json.loads(out.read_text())
    assert record["robot"] == label and record["world"] == "reference"
    assert record["success"] is True and result.returncode == 0, result.stdout + result.stderr


def test_a_fixed_arms_recording_looks_past_the_arm():
    from hlp_drake.systems.execution.meshcat_view import camera_pose

    scene = generate_scene("gen1", 5, workspace=load_robot("panda").workspace)
    person_side, target = camera_pose(scene)
    beside, same_target = camera_pose(scene, fixed_base=True)
    np.testing.assert_array_equal(target, same_target)
    assert person_side[0] < 0 < person_side[1]  # behind the front edge, to the left
    assert beside[0] > 0 and beside[1] > 0 and beside[2] > person_side[2]  # over the table, from the left


def test_a_start_out_of_a_fixed_arms_reach_is_that_jobs_failure():
    from job_support import one_job

    from hlp_drake.systems.execution.job import run_job

    panda = load_robot("panda")  # a reach claimed beyond the arm's: the start 1.2 m to the side is out of it
    robot = replace(panda, reach=1.5, base=replace(panda.base, pose=(-0.1, 1.2, 0.0)))
    job = one_job(Scenario(robot=robot).yaml, "gen2", 20, 7, workspace=Workspace(-0.3, 0.0, 0.88))
    row = run_job(job)
    assert row["success"] is False and "the arm cannot put the tcp above the start" in row["failure_reason"]
    assert "out of its reach" in row["failure_reason"] and not row["failure_reason"].startswith("crashed")


def test_the_iiwas_push_beside_the_pedestal_starts_where_its_closed_fingers_need_and_is_reached():
    """The iiwa's Gen II seed 38 (7 objects): spaced for open fingers (0.07 m half-width) the push of
    obstacle_7 started at (0.060, -0.241), too close before the pedestal for the IK, and the plan gave
    way to its second alternative. Spaced for the closed fingers it pushes with (0.015 m), it starts
    nearer the obstacle and the plan itself runs (the fallback is tested on its block,
    ``test_keypoint_ik``)."""
    from hlp_drake.systems.planning.diagram import make_planning_diagram
    from hlp_drake.systems.world.scene_source import SCENE_PORT

    iiwa = load_robot("iiwa14")
    scene = generate_scene("gen2", 38, 7, iiwa.workspace)
    diagram = make_planning_diagram(Scenario(robot=iiwa, scene=scene))
    context = diagram.CreateDefaultContext()
    diagram.GetInputPort(SCENE_PORT).FixValue(context, scene)
    robot_plan = diagram.GetOutputPort("robot_plan").Eval(context)
    (push,) = [k for k in robot_plan.keypoints if k.action == "move"]
    assert push.element == "obstacle_7"
    assert np.hypot(push.position[0] - 0.06, push.position[1] + 0.241) > 0.03
    keyframes = diagram.GetOutputPort("keyframes").Eval(context)
    assert keyframes.ok and keyframes.candidate == 0 and keyframes.replaced == ()
    assert keyframes.keypoints == robot_plan.keypoints


def test_a_start_close_before_the_pedestal_tilts_within_the_keypoints_tolerance():
    from hlp_drake.systems.world.start_pose import _start_arm, start_configuration, tcp_keypoint_height

    iiwa = load_robot("iiwa14")
    scene = generate_scene("gen2", 16, 7, iiwa.workspace)  # the start 0.2 m before the pedestal, a low table
    ik = Scenario(robot=iiwa).ik
    goal = (*scene.start, tcp_keypoint_height(scene, ik))
    assert _start_arm(iiwa, tuple(round(v, 9) for v in goal), ik.max_iterations) is None  # not horizontal
    plant, instance = kinematic_robot(iiwa)
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, instance, start_configuration(scene, ik, plant, instance, iiwa))
    pose = plant.GetFrameByName(iiwa.tcp_frame, instance).CalcPoseInWorld(context)
    np.testing.assert_allclose(pose.translation(), goal, atol=2e-4)
    approach, fingers = pose.rotation().matrix()[:, 2], pose.rotation().matrix()[:, 1]
    assert 1e-3 < np.arccos(approach[0]) <= ik.approach_tolerance + 1e-6  # tilted, within the keypoints' cone
    assert abs(fingers[2]) <= np.sin(ik.roll_tolerance) + 1e-6  # the fingers still open sideways
