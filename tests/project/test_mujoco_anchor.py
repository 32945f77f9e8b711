"""The MuJoCo anchor benchmark's converter (``benchmarks/mujoco_anchor.py``): the default scenario's
plant as MJCF, its structure, and 0.1 s of stepping with the robot holding its start pose."""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

import numpy as np
import pytest
from pydrake.geometry import Role

from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.scenario import Scenario
from hlp_drake.systems.world.robot_description import MOBILE_UR5
from hlp_drake.systems.world.start_pose import robot_position_names

mujoco = pytest.importorskip("mujoco", reason="mujoco is an optional extra (pip install -e '.[bench]')")
BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"


@pytest.fixture(scope="module")
def anchor():
    """The benchmark module (it imports ``sto`` from its own folder)."""
    sys.path.insert(0, str(BENCHMARKS))
    try:
        return importlib.import_module("mujoco_anchor")
    finally:
        sys.path.remove(str(BENCHMARKS))


@pytest.fixture(scope="module")
def scenario() -> Scenario:
    return Scenario()


@pytest.fixture(scope="module")
def world(anchor, scenario: Scenario):
    return anchor.MujocoWorld(scenario)


def test_structure(world, scenario: Scenario) -> None:
    model = world.model
    free = [model.joint(j) for j in range(model.njnt) if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE]
    assert sorted(model.body(j.bodyid[0]).name for j in free) == sorted(
        o.name for o in scenario.scene.objects
    )
    robot = [
        model.joint(j).name for j in range(model.njnt) if model.jnt_type[j] != mujoco.mjtJoint.mjJNT_FREE
    ]
    assert sorted(robot) == sorted(robot_position_names())
    assert len(robot) == 11
    assert model.ngeom == world.inspector.NumGeometriesWithRole(Role.kProximity)
    assert [model.joint(model.actuator_trnid[a, 0]).name for a in range(model.nu)] == list(
        MOBILE_UR5.actuated_joints
    )
    control = scenario.controller
    assert model.actuator("base_x_motor").gainprm[0] == control.base.kp
    assert -model.actuator("wrist_3_motor").biasprm[2] == control.wrist.kd
    assert model.neq == 1 and model.eq_type[0] == mujoco.mjtEq.mjEQ_JOINT


def test_holds_still(world) -> None:
    start = world.qpos0[world.robot_qpos]
    run = world.rollout(ControlSequence(np.array([0.0, 0.1]), np.vstack([start, start])), time_step=0.005)
    assert not run.failed and run.simulated_s == pytest.approx(0.1)
    assert np.all(np.isfinite(world.data.qpos))
    assert np.max(np.abs(run.robot_end - start)) < 1e-3
    assert np.max(run.drift) < 1e-3  # the objects rest on the table
    plant = world.plant
    robot = {world.model.body(plant.get_body(b).name()).id for b in plant.GetBodyIndices(world.robot)}
    touching = set(world.model.geom_bodyid[world.data.contact.geom[: world.data.ncon].ravel()])
    assert world.data.ncon > 0 and not touching & robot  # only the objects and the table touch
