"""The grasp after a reach: slide onto the target's centre, close, lift (``grasp_knots``), and in
a simulated world the short-fingered Panda holds a target its reach ended 2 cm off."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
from conftest import run_module

from hlp_drake.commands.run_scene import DEFAULT_SCENE
from hlp_drake.scene.io import load_scene
from hlp_drake.systems.conditions import scene_for_robot
from hlp_drake.systems.execution.command import GraspConfig, grasp_knots, moved_configuration
from hlp_drake.systems.planning.config import IkConfig
from hlp_drake.systems.world.robot_description import load_robot
from hlp_drake.systems.world.start_pose import kinematic_robot, start_configuration


def _tcp(q: np.ndarray, robot) -> np.ndarray:
    plant, instance = kinematic_robot(robot)
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, instance, q)
    return plant.GetFrameByName(robot.tcp_frame, instance).CalcPoseInWorld(context).translation()


@pytest.fixture(scope="module", params=["mobile_ur5", "panda"])
def start(request):
    robot = load_robot(request.param)
    plant, instance = kinematic_robot(robot)
    return robot, start_configuration(
        scene_for_robot(load_scene(DEFAULT_SCENE), robot), IkConfig(), plant, instance, robot
    )


def test_the_grasp_slides_level_onto_the_centre_then_closes_and_lifts(start):
    robot, q = start
    tcp = _tcp(q, robot)
    centre = (tcp[0] + 0.02, tcp[1] - 0.015)
    grasp = GraspConfig()
    times, knots = grasp_knots(q, grasp, robot, centre=centre)
    np.testing.assert_allclose(
        np.diff(times, prepend=0.0), [grasp.align_s, grasp.close_s, grasp.lift_s, grasp.hold_s]
    )
    aligned, closed, lifted, held = knots
    np.testing.assert_allclose(_tcp(aligned, robot), [*centre, tcp[2]], atol=2e-3)
    fingers = list(robot.finger_columns)
    np.testing.assert_allclose(aligned[fingers], q[fingers])  # open while it slides
    np.testing.assert_allclose(closed[fingers], robot.gripper_closed)
    np.testing.assert_allclose(_tcp(closed, robot), _tcp(aligned, robot), atol=1e-9)
    np.testing.assert_allclose(
        _tcp(lifted, robot), _tcp(aligned, robot) + [0, 0, grasp.lift_height], atol=2e-3
    )
    np.testing.assert_array_equal(held, lifted)


def test_without_alignment_or_a_centre_the_fingers_close_where_the_reach_ended(start):
    robot, q = start
    centre = tuple(_tcp(q, robot)[:2] + 0.02)
    for grasp, given in ((replace(GraspConfig(), align=False), centre), (GraspConfig(), None)):
        times, knots = grasp_knots(q, grasp, robot, centre=given)
        assert len(knots) == 3
        np.testing.assert_allclose(_tcp(knots[0], robot), _tcp(q, robot), atol=1e-9)
        assert grasp.duration == pytest.approx(times[-1] + (grasp.align_s if grasp.align else 0.0))


def test_a_centre_out_of_reach_leaves_the_hand_where_it_is(start):
    robot, q = start
    assert moved_configuration(q, robot, level_to=(25.0, 0.0)) is None
    _, knots = grasp_knots(q, GraspConfig(), robot, centre=(25.0, 0.0))
    assert len(knots) == 3
    np.testing.assert_allclose(_tcp(knots[0], robot), _tcp(q, robot), atol=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("align, held", [(True, True), (False, False)])
def test_the_panda_holds_a_target_its_reach_ended_two_centimetres_off_only_by_sliding_on(
    tmp_path, align, held
):
    # Gen I seed 29 on the Panda: the reach passes with the tcp 2.2 cm short of the target's centre and
    # 2.3 cm beside it; its fingertips reach 1 cm past the tcp and close on the target's near side.
    out, config = tmp_path / "run.json", tmp_path / "grasp.yaml"
    config.write_text(f"grasp: {{align: {str(align).lower()}}}\n")
    args = ["--robot", "panda", "--kind", "gen1", "--seed", "29", "--config", str(config), "--json", str(out)]
    result = run_module("hlp_drake.run_scene", *args, "--quiet")
    assert result.returncode == 0, result.stdout + result.stderr
    assert json.loads(out.read_text())["grasp_held"] is held
