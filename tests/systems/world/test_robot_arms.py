"""The fixed-base arms on pedestals (hlp_drake/models/robot/panda.urdf, iiwa14.urdf): parsing, joints, limits,
actuators, the mimic finger, published kinematics, the pedestal, the gripper, the ready poses."""

from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest
from arm_support import ARMS, ROBOT_DIR, TOOLS, Robot, build
from pydrake.geometry import Box, Capsule, Cylinder, Role, Sphere
from pydrake.math import RigidTransform
from pydrake.systems.analysis import Simulator

PRIMITIVES = (Box, Cylinder, Capsule, Sphere)


@pytest.fixture(scope="module", params=ARMS, ids=[a.name for a in ARMS])
def robot(request) -> Robot:
    return build(request.param)


def test_generated_urdfs_are_up_to_date_and_self_contained():
    result = subprocess.run(
        [sys.executable, str(TOOLS / "make_arms.py"), "--check"],
        check=False,
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, result.stderr
    for spec in ARMS:
        text = (ROBOT_DIR / f"{spec.name}.urdf").read_text()
        assert "package://" not in text and "<mesh" not in text
        assert text.count("<mimic ") == 1 and text.count("<transmission ") == 8


def test_parses_with_eight_actuators_and_a_coupled_finger(robot: Robot):
    plant, spec = robot.plant, robot.spec
    assert plant.GetModelInstanceName(robot.instance) == spec.name
    actuated = [
        plant.get_joint_actuator(i).joint().name() for i in plant.GetJointActuatorIndices(robot.instance)
    ]
    assert actuated == [*spec.joints, spec.finger_joints[0]]
    assert plant.num_actuators() == 8
    assert plant.num_positions() == plant.num_velocities() == 9  # 7 arm joints and two fingers
    assert plant.num_constraints() > 0 and len(plant.GetConstraintIds()) == 1  # the finger coupler
    for name in spec.joints:
        assert plant.GetJointByName(name, robot.instance).type_name() == "revolute"
    for name in spec.finger_joints:
        assert plant.GetJointByName(name, robot.instance).type_name() == "prismatic"
    tcp_joint = plant.GetJointByName("tcp_joint", robot.instance)
    assert (tcp_joint.type_name(), tcp_joint.parent_body().name()) == ("weld", spec.palm)
    # The root is the pedestal, welded to the world; the arm's base sits on it.
    mount = plant.GetJointByName(f"{spec.links[0].split('_link')[0]}_mount_joint", robot.instance)
    assert (mount.parent_body().name(), mount.child_body().name()) == (spec.pedestal, spec.links[0])


def test_published_joint_limits_and_efforts(robot: Robot):
    plant, spec = robot.plant, robot.spec
    joints = [plant.GetJointByName(name, robot.instance) for name in spec.joints]
    np.testing.assert_allclose([j.position_lower_limits()[0] for j in joints], spec.lower, rtol=1e-11)
    np.testing.assert_allclose([j.position_upper_limits()[0] for j in joints], spec.upper, rtol=1e-11)
    np.testing.assert_allclose([j.velocity_upper_limits()[0] for j in joints], spec.velocity, rtol=1e-11)
    efforts = [
        plant.get_joint_actuator(i).effort_limit() for i in plant.GetJointActuatorIndices(robot.instance)
    ]
    np.testing.assert_allclose(efforts, [*spec.effort, spec.finger_force])
    for name in spec.finger_joints:
        finger = plant.GetJointByName(name, robot.instance)
        assert finger.position_lower_limits()[0] == 0.0
        assert finger.position_upper_limits()[0] == pytest.approx(spec.stroke)


def test_flange_forward_kinematics_matches_the_published_chain(robot: Robot):
    plant, spec = robot.plant, robot.spec
    _, context, _ = robot.contexts()
    rng = np.random.default_rng(7)
    base, flange = robot.frame(spec.links[0]), robot.frame(spec.flange)
    for q in [np.zeros(7), np.array(spec.home), *rng.uniform(spec.lower, spec.upper, size=(6, 7))]:
        robot.set(context, q)
        X = plant.CalcRelativeTransform(context, base, flange).GetAsMatrix4()
        np.testing.assert_allclose(X, spec.forward_kinematics(q), atol=1e-9)


def test_arm_stands_on_its_pedestal_and_the_tcp_sits_on_the_hand(robot: Robot):
    plant, spec = robot.plant, robot.spec
    _, context, _ = robot.contexts()
    X_world_base = robot.frame(spec.links[0]).CalcPoseInWorld(context)
    assert X_world_base.IsNearlyEqualTo(RigidTransform([0.0, 0.0, spec.mount]), 1e-12)
    X_flange_tcp = plant.CalcRelativeTransform(context, robot.frame(spec.flange), robot.frame("tcp"))
    X_flange_palm = plant.CalcRelativeTransform(context, robot.frame(spec.flange), robot.frame(spec.palm))
    assert X_flange_palm.IsNearlyEqualTo(spec.hand_mount(), 1e-9)
    assert X_flange_tcp.IsNearlyEqualTo(spec.hand_mount() @ RigidTransform([0.0, 0.0, spec.tcp]), 1e-9)


def test_pedestal_column_carries_the_arm(robot: Robot):
    plant, spec = robot.plant, robot.spec
    inspector = robot.scene_graph.model_inspector()
    body = plant.GetBodyByName(spec.pedestal, robot.instance)
    columns = []
    for role in (Role.kProximity, Role.kIllustration):
        for geometry in inspector.GetGeometries(plant.GetBodyFrameIdOrThrow(body.index()), role):
            shape = inspector.GetShape(geometry)
            if isinstance(shape, Cylinder):
                columns.append((role, shape, inspector.GetPoseInFrame(geometry)))
    assert {role for role, _, _ in columns} == {Role.kProximity, Role.kIllustration}
    for _, shape, X in columns:
        p = X.translation()
        assert X.rotation().IsNearlyIdentity(1e-12) and np.allclose(p[:2], 0.0)  # upright, on the axis
        assert p[2] - shape.length() / 2 == pytest.approx(0.015)  # on the foot plate
        assert p[2] + shape.length() / 2 == pytest.approx(spec.mount - 0.015)  # under the top plate
    assert body.default_mass() > 10.0


def test_tcp_lies_between_the_fingertip_pads(robot: Robot):
    plant, spec = robot.plant, robot.spec
    _, context, _ = robot.contexts()
    robot.set(context, finger=0.03)
    inspector = robot.scene_graph.model_inspector()
    for name, side in zip(spec.fingers, (1.0, -1.0)):
        p = plant.CalcRelativeTransform(context, robot.frame("tcp"), robot.frame(name)).translation()
        np.testing.assert_allclose(p, [0.0, side * 0.03, spec.finger_base - spec.tcp], atol=1e-12)
        body = plant.GetBodyByName(name, robot.instance)
        (geometry,) = inspector.GetGeometries(plant.GetBodyFrameIdOrThrow(body.index()), Role.kProximity)
        box, X = inspector.GetShape(geometry), inspector.GetPoseInFrame(geometry)
        inner = X.translation()[1] - side * box.depth() / 2  # the finger's inner face, in its frame
        tip = X.translation()[2] + box.height() / 2
        assert inner == pytest.approx(0.0, abs=1e-12)  # inner faces at y = +-q: closed at q = 0
        assert 0.005 < spec.finger_base + tip - spec.tcp < 0.03  # tcp a little in from the tips


def test_home_pose_points_forward_over_the_table_without_collisions(robot: Robot):
    spec = robot.spec
    _, context, sg_context = robot.contexts()
    assert np.all(np.array(spec.lower) < spec.home) and np.all(np.array(spec.home) < spec.upper)
    robot.set(context)
    X = robot.frame("tcp").CalcPoseInWorld(context)
    np.testing.assert_allclose(X.translation(), spec.home_tcp, atol=2e-3)
    R = X.rotation().matrix()
    assert math.acos(min(1.0, R[0, 2])) <= spec.home_pitch  # the approach along +x
    assert abs(R[2, 1]) < 2e-3  # fingers open horizontally
    for finger in (spec.stroke, 0.0):
        robot.set(context, finger=finger)
        query = robot.scene_graph.get_query_output_port().Eval(sg_context)
        assert query.ComputePointPairPenetration() == []


def test_mimic_finger_follows_the_actuated_finger():
    for spec in ARMS:
        actuation = np.zeros(8)
        actuation[7] = 1.0  # N on the actuated finger: opens slowly against the joint damping
        robot = build(spec, gravity=False, actuation=actuation)
        simulator = Simulator(robot.diagram)
        context = robot.plant.GetMyContextFromRoot(simulator.get_mutable_context())
        robot.set(context)
        simulator.AdvanceTo(0.2)
        left, right = (robot.plant.GetJointByName(n, robot.instance) for n in spec.finger_joints)
        q_left, q_right = left.get_translation(context), right.get_translation(context)
        assert 0.005 < q_left < spec.stroke, spec.name
        assert q_right == pytest.approx(q_left, abs=1e-6), spec.name


def test_geometry_is_primitive_and_every_moving_link_collides(robot: Robot):
    plant, spec = robot.plant, robot.spec
    inspector = robot.scene_graph.model_inspector()
    for role in (Role.kProximity, Role.kIllustration):
        for body in plant.GetBodyIndices(robot.instance):
            for geometry in inspector.GetGeometries(plant.GetBodyFrameIdOrThrow(body), role):
                assert isinstance(inspector.GetShape(geometry), PRIMITIVES)
    for link in (spec.pedestal, *spec.links, spec.palm, *spec.fingers):
        body = plant.GetBodyByName(link, robot.instance)
        assert inspector.GetGeometries(plant.GetBodyFrameIdOrThrow(body.index()), Role.kProximity), link


def test_collision_filters(robot: Robot):
    plant, spec = robot.plant, robot.spec
    inspector = robot.scene_graph.model_inspector()

    def geometry(link: str):
        body = plant.GetBodyByName(link, robot.instance)
        return inspector.GetGeometries(plant.GetBodyFrameIdOrThrow(body.index()), Role.kProximity)[0]

    links = spec.links
    assert inspector.CollisionFiltered(geometry(spec.fingers[0]), geometry(spec.fingers[1]))
    assert inspector.CollisionFiltered(geometry(links[5]), geometry(links[7]))  # the wrist's overlap
    assert inspector.CollisionFiltered(geometry(links[7]), geometry(spec.fingers[0]))
    # The gripper can still hit the forearm, the shoulder and the pedestal.
    for other in (links[4], links[1], spec.pedestal):
        assert not inspector.CollisionFiltered(geometry(spec.palm), geometry(other)), other
        assert not inspector.CollisionFiltered(geometry(spec.fingers[1]), geometry(other)), other
    assert not inspector.CollisionFiltered(geometry(links[3]), geometry(spec.pedestal))


def test_masses_and_inertias(robot: Robot):
    plant, spec = robot.plant, robot.spec
    for link, mass in zip(spec.links[1:], spec.masses):
        assert plant.GetBodyByName(link, robot.instance).default_mass() == pytest.approx(mass)
    gripper = sum(
        plant.GetBodyByName(link, robot.instance).default_mass() for link in (spec.palm, *spec.fingers)
    )
    assert 0.7 <= gripper <= 1.3
    for index in plant.GetBodyIndices(robot.instance):
        body = plant.get_body(index)
        inertia = body.default_spatial_inertia()
        assert inertia.IsPhysicallyValid(), body.name()
        if body.default_mass() > 0:
            moments = sorted(
                inertia.Shift(inertia.get_com()).CalcRotationalInertia().CalcPrincipalMomentsOfInertia()
            )
            assert moments[0] > 0 and moments[0] + moments[1] >= moments[2], body.name()
