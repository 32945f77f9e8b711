"""The mobile UR5 model: parsing, actuators, limits, UR5 kinematics, the mimic finger, geometry, masses."""

from __future__ import annotations

import importlib.util
import math
import subprocess
import sys

import numpy as np
import pytest
from arm_support import BuiltRobot as Robot
from conftest import REPO
from pydrake.geometry import Box, Capsule, Cylinder, Role, Sphere
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import (
    AddMultibodyPlantSceneGraph,
    DiscreteContactApproximation,
    MultibodyPlant,
)
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from hlp_drake.systems.world.robot import add_robot, robot_joint_limits, set_robot_positions
from hlp_drake.systems.world.robot_description import MOBILE_UR5, models_directory


def _script(name: str):
    """A model-writing script of ``hlp_drake/models/robot`` (the source of the model's dimensions)."""
    spec = importlib.util.spec_from_file_location(name, REPO / "tools" / "robot_models" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


UR5_SCRIPT = _script("make_mobile_ur5")
ACTUATED_JOINTS = MOBILE_UR5.actuated_joints
ARM_JOINTS = MOBILE_UR5.arm_joints
BASE_JOINTS = MOBILE_UR5.base_joints
GRIPPER_JOINTS = (MOBILE_UR5.gripper_joint,)
GRIPPER_MIMIC_JOINTS = MOBILE_UR5.mimic_joints
GRIPPER_OPEN = MOBILE_UR5.gripper_open
HOME_ARM_POSITIONS = MOBILE_UR5.home
ROBOT_MODEL_NAME = MOBILE_UR5.name
TCP_FRAME = MOBILE_UR5.tcp_frame
FLANGE_FRAME = MOBILE_UR5.flange_frame
BASE_FOOTPRINT = MOBILE_UR5.base.footprint
ARM_BASE_FRAME = "ur5_base"
BASE_BODY = "base_link"
DECK_HEIGHT = UR5_SCRIPT.DECK_HEIGHT
MOUNT_HEIGHT = UR5_SCRIPT.MOUNT_HEIGHT
RISER_RADIUS = UR5_SCRIPT.RISER_RADIUS
ARM_MOUNT = UR5_SCRIPT.ARM_MOUNT_XYZ
TCP_OFFSET = UR5_SCRIPT.TCP_DEPTH

# UR5 official DH parameters (d, a, alpha) and link masses (base, shoulder, ..., wrist 3).
UR5_DH = [
    (0.089159, 0.0, math.pi / 2),
    (0.0, -0.425, 0.0),
    (0.0, -0.39225, 0.0),
    (0.10915, 0.0, math.pi / 2),
    (0.09465, 0.0, -math.pi / 2),
    (0.0823, 0.0, 0.0),
]
UR5_MASSES = [4.0, 3.7, 8.393, 2.275, 1.219, 1.219, 0.1879]
UR5_LINKS = [
    "ur5_base_link",
    "shoulder_link",
    "upper_arm_link",
    "forearm_link",
    "wrist_1_link",
    "wrist_2_link",
    "wrist_3_link",
]
PRIMITIVES = (Box, Cylinder, Capsule, Sphere)


def dh_forward_kinematics(q) -> np.ndarray:
    """4x4 pose of the UR5 flange in its DH base frame: product of Rz(q) Tz(d) Tx(a) Rx(alpha)."""
    pose = np.eye(4)
    for theta, (d, a, alpha) in zip(q, UR5_DH):
        ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
        pose = pose @ np.array(
            [
                [ct, -st * ca, st * sa, a * ct],
                [st, ct * ca, -ct * sa, a * st],
                [0.0, sa, ca, d],
                [0.0, 0.0, 0.0, 1.0],
            ]
        )
    return pose


def build_robot(*, gravity: bool = True, actuation: np.ndarray | None = None) -> Robot:
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.001)
    plant.set_discrete_contact_approximation(DiscreteContactApproximation.kSap)
    instance = add_robot(plant)
    if not gravity:
        plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, 0.0])
    plant.Finalize()
    if actuation is not None:
        source = builder.AddSystem(ConstantVectorSource(actuation))
        builder.Connect(source.get_output_port(), plant.get_actuation_input_port())
    return Robot(builder.Build(), plant, scene_graph, instance)


@pytest.fixture(scope="module")
def robot() -> Robot:
    return build_robot()


def test_generated_urdf_is_up_to_date_and_self_contained():
    script = REPO / "tools" / "robot_models" / "make_mobile_ur5.py"
    result = subprocess.run(
        [sys.executable, str(script), "--check"], check=False, capture_output=True, text=True
    )
    assert result.returncode == 0, result.stderr
    text = (models_directory() / "robot" / "mobile_ur5.urdf").read_text()
    assert "package://" not in text and "<mesh" not in text
    assert text.count("<mimic ") == 1


def test_parses_with_ten_actuators_in_order(robot: Robot):
    plant = robot.plant
    assert plant.GetModelInstanceName(robot.instance) == ROBOT_MODEL_NAME
    assert plant.num_actuated_dofs() == 10 == len(ACTUATED_JOINTS)
    actuated = [
        plant.get_joint_actuator(i).joint().name() for i in plant.GetJointActuatorIndices(robot.instance)
    ]
    assert actuated == list(BASE_JOINTS + ARM_JOINTS + GRIPPER_JOINTS)
    assert plant.num_positions() == plant.num_velocities() == 11  # + the mimic finger
    assert len(plant.GetConstraintIds()) == 1  # the finger coupler
    for name in GRIPPER_MIMIC_JOINTS:
        assert plant.GetJointByName(name, robot.instance).num_velocities() == 1
    assert plant.HasFrameNamed(TCP_FRAME, robot.instance)
    tcp_joint = plant.GetJointByName("tcp_joint", robot.instance)  # a fixed-joint link: a welded body
    assert (tcp_joint.type_name(), tcp_joint.parent_body().name()) == ("weld", "gripper_base_link")


def test_joint_limits(robot: Robot):
    plant = robot.plant
    limits = robot_joint_limits(plant, robot.instance)
    assert all(a.shape == (10,) for a in limits)
    arm = slice(3, 9)
    np.testing.assert_allclose(limits.velocity[arm], math.pi, rtol=1e-12)
    np.testing.assert_allclose(limits.velocity[:3], [1.0, 1.0, 2.0])
    np.testing.assert_allclose(limits.upper[arm], [2 * math.pi, 2 * math.pi, math.pi] + [2 * math.pi] * 3)
    np.testing.assert_allclose(limits.lower[arm], -limits.upper[arm])
    assert (limits.lower[9], limits.upper[9]) == (0.0, pytest.approx(0.0425))
    efforts = [
        plant.get_joint_actuator(i).effort_limit() for i in plant.GetJointActuatorIndices(robot.instance)
    ]
    assert efforts[3:9] == [150.0, 150.0, 150.0, 28.0, 28.0, 28.0]
    assert efforts[9] == 100.0
    mimic = plant.GetJointByName(GRIPPER_MIMIC_JOINTS[0], robot.instance)
    assert (mimic.position_lower_limits()[0], mimic.position_upper_limits()[0]) == (
        0.0,
        pytest.approx(0.0425),
    )


@pytest.mark.parametrize(
    "q",
    [
        (0.0,) * 6,
        HOME_ARM_POSITIONS,
        (0.3, -1.2, 1.0, -0.5, 0.8, 2.0),
        (-2.5, 0.7, -2.8, 3.5, -1.9, -4.0),
    ],
)
def test_ur5_forward_kinematics_matches_dh(robot: Robot, q):
    plant = robot.plant
    _, context, _ = robot.contexts()
    set_robot_positions(plant, context, robot.instance, base=(0.4, -0.3, 0.7), arm=q)

    def frame(name: str):
        return plant.GetFrameByName(name, robot.instance)

    X_base_flange = plant.CalcRelativeTransform(context, frame(ARM_BASE_FRAME), frame(FLANGE_FRAME))
    np.testing.assert_allclose(X_base_flange.GetAsMatrix4(), dh_forward_kinematics(q), atol=1e-9)
    # The tcp sits TCP_OFFSET along the flange's z axis, with the flange's orientation.
    X_flange_tcp = plant.CalcRelativeTransform(context, frame(FLANGE_FRAME), frame(TCP_FRAME))
    np.testing.assert_allclose(
        X_flange_tcp.GetAsMatrix4(), RigidTransform([0, 0, TCP_OFFSET]).GetAsMatrix4(), atol=1e-12
    )


def test_arm_mounted_at_the_front_facing_forward(robot: Robot):
    plant = robot.plant
    _, context, _ = robot.contexts()
    set_robot_positions(plant, context, robot.instance, arm=(0.0,) * 6)
    base = plant.GetFrameByName(BASE_BODY, robot.instance)
    mount = plant.GetFrameByName("ur5_base_link", robot.instance)
    X_base_mount = plant.CalcRelativeTransform(context, base, mount)
    np.testing.assert_allclose(X_base_mount.translation(), ARM_MOUNT)
    assert X_base_mount.rotation().IsExactlyIdentity()
    assert 0.0 < BASE_FOOTPRINT[0] / 2 - ARM_MOUNT[0] < 0.2  # near the front edge, on the riser
    assert ARM_MOUNT[2] == MOUNT_HEIGHT
    # The UR5's DH base is the mount turned by pi; at zero angles the arm stretches along +x.
    X_mount_dh = plant.CalcRelativeTransform(
        context, mount, plant.GetFrameByName(ARM_BASE_FRAME, robot.instance)
    )
    assert X_mount_dh.IsNearlyEqualTo(RigidTransform(RotationMatrix.MakeZRotation(math.pi), [0, 0, 0]), 1e-12)
    p_flange = plant.CalcRelativeTransform(context, mount, plant.GetFrameByName(FLANGE_FRAME, robot.instance))
    assert p_flange.translation()[0] == pytest.approx(0.425 + 0.39225)


def test_riser_lifts_the_mount_to_about_table_height(robot: Robot):
    """A round column on the deck, part of the base body, up to the mount: 0.7-0.8 m tables' height."""
    plant, inspector = robot.plant, robot.scene_graph.model_inspector()
    assert 0.7 <= MOUNT_HEIGHT <= 0.85
    body = plant.GetBodyByName(BASE_BODY, robot.instance)
    columns = []
    for role in (Role.kProximity, Role.kIllustration):
        for geometry in inspector.GetGeometries(plant.GetBodyFrameIdOrThrow(body.index()), role):
            shape = inspector.GetShape(geometry)
            if isinstance(shape, Cylinder) and shape.length() > 0.3:
                columns.append((role, shape, inspector.GetPoseInFrame(geometry)))
    assert {role for role, _, _ in columns} == {Role.kProximity, Role.kIllustration}
    for _, shape, X_base_column in columns:
        p = X_base_column.translation()
        assert X_base_column.rotation().IsNearlyIdentity(1e-12)  # upright
        np.testing.assert_allclose(p[:2], ARM_MOUNT[:2], atol=1e-12)  # right under the mount
        assert p[2] - shape.length() / 2 == pytest.approx(DECK_HEIGHT)  # stands on the deck
        assert p[2] + shape.length() / 2 == pytest.approx(MOUNT_HEIGHT)  # carries the arm's base
        assert shape.radius() == pytest.approx(RISER_RADIUS)
        front = ARM_MOUNT[0] + shape.radius()
        assert 0.0 < BASE_FOOTPRINT[0] / 2 - front < 0.03  # nearly flush with the base's front
    # The riser's mass raises the base's centre of mass and moves it forward.
    com = body.default_com()
    assert 0.0 < com[0] < ARM_MOUNT[0] and com[1] == pytest.approx(0.0) and 0.17 < com[2] < MOUNT_HEIGHT


def test_planar_base_joints_move_the_base(robot: Robot):
    plant = robot.plant
    _, context, _ = robot.contexts()
    set_robot_positions(plant, context, robot.instance, base=(1.5, -0.5, math.pi / 2))
    X_world_base = plant.GetFrameByName(BASE_BODY, robot.instance).CalcPoseInWorld(context)
    np.testing.assert_allclose(X_world_base.translation(), [1.5, -0.5, 0.0], atol=1e-12)
    np.testing.assert_allclose(X_world_base.rotation().matrix()[:, 0], [0.0, 1.0, 0.0], atol=1e-12)
    kinds = [plant.GetJointByName(n, robot.instance).type_name() for n in BASE_JOINTS]
    assert kinds == ["prismatic", "prismatic", "revolute"]


def test_home_pose_is_in_front_above_the_table_pointing_forward(robot: Robot):
    plant = robot.plant
    _, context, sg_context = robot.contexts()
    set_robot_positions(plant, context, robot.instance)
    X_world_tcp = plant.GetFrameByName(TCP_FRAME, robot.instance).CalcPoseInWorld(context)
    x, y, z = X_world_tcp.translation()
    assert x > BASE_FOOTPRINT[0] / 2 + 0.2 and abs(y) < 1e-3 and 0.75 < z < 0.9  # at table height
    assert x - ARM_MOUNT[0] > 0.5  # well in front of the arm's base, the arm half stretched out
    np.testing.assert_allclose(X_world_tcp.rotation().matrix()[:, 2], [1.0, 0.0, 0.0], atol=1e-3)  # approach
    np.testing.assert_allclose(
        abs(X_world_tcp.rotation().matrix()[1, 1]), 1.0, atol=1e-3
    )  # fingers open along y
    limits = robot_joint_limits(plant, robot.instance)
    assert np.all(limits.lower[3:9] < HOME_ARM_POSITIONS) and np.all(HOME_ARM_POSITIONS < limits.upper[3:9])
    for gripper in (GRIPPER_OPEN, 0.0):
        set_robot_positions(plant, context, robot.instance, gripper=gripper)
        query = robot.scene_graph.get_query_output_port().Eval(sg_context)
        assert query.ComputePointPairPenetration() == []


def test_tcp_lies_between_the_fingers(robot: Robot):
    plant = robot.plant
    _, context, _ = robot.contexts()
    set_robot_positions(plant, context, robot.instance, gripper=0.03)
    tcp = plant.GetFrameByName(TCP_FRAME, robot.instance)
    for name, side in (("left_finger_link", 1.0), ("right_finger_link", -1.0)):
        finger = plant.GetFrameByName(name, robot.instance)
        p = plant.CalcRelativeTransform(context, tcp, finger).translation()
        np.testing.assert_allclose(p, [0.0, side * 0.03, -TCP_OFFSET], atol=1e-12)


def test_mimic_finger_follows_the_actuated_finger():
    actuation = np.zeros(10)
    actuation[9] = 1.0  # N on the left finger: opens slowly against the joint damping
    robot = build_robot(gravity=False, actuation=actuation)
    plant = robot.plant
    simulator = Simulator(robot.diagram)
    context = plant.GetMyContextFromRoot(simulator.get_mutable_context())
    left = plant.GetJointByName(GRIPPER_JOINTS[0], robot.instance)
    right = plant.GetJointByName(GRIPPER_MIMIC_JOINTS[0], robot.instance)
    simulator.AdvanceTo(0.2)
    q_left, q_right = left.get_translation(context), right.get_translation(context)
    assert 0.005 < q_left < GRIPPER_OPEN
    assert q_right == pytest.approx(q_left, abs=1e-6)


@pytest.mark.skipif(
    not hasattr(DiscreteContactApproximation, "kTamsi"), reason="this Drake has no TAMSI solver"
)
def test_add_robot_rejects_a_plant_without_sap():
    plant = MultibodyPlant(time_step=0.001)
    plant.set_discrete_contact_approximation(DiscreteContactApproximation.kTamsi)
    with pytest.raises(ValueError, match="SAP"):
        add_robot(plant)


def test_continuous_plant_loads_for_kinematics():
    plant = MultibodyPlant(time_step=0.0)
    instance = add_robot(plant)
    plant.Finalize()
    assert plant.num_actuated_dofs() == 10
    assert robot_joint_limits(plant, instance).velocity[3] == pytest.approx(math.pi)


def test_two_robots_need_different_names():
    plant = MultibodyPlant(time_step=0.001)
    parser = Parser(plant)
    first = add_robot(plant, parser=parser)
    second = add_robot(plant, parser=parser, name="robot_2")
    with pytest.raises(ValueError, match="robot_2"):
        add_robot(plant, name="robot_2")
    other = MultibodyPlant(time_step=0.001)
    with pytest.raises(ValueError, match="different plant"):
        add_robot(other, parser=parser)
    plant.Finalize()
    assert plant.GetModelInstanceName(second) == "robot_2" and first != second
    assert plant.num_actuated_dofs() == 20


def test_geometry_is_primitive_only(robot: Robot):
    plant, inspector = robot.plant, robot.scene_graph.model_inspector()
    counts = {}
    for role in (Role.kProximity, Role.kIllustration):
        geometries = [
            geometry
            for body in plant.GetBodyIndices(robot.instance)
            for geometry in inspector.GetGeometries(plant.GetBodyFrameIdOrThrow(body), role)
        ]
        counts[role] = len(geometries)
        shapes = [type(inspector.GetShape(g)).__name__ for g in geometries]
        assert all(isinstance(inspector.GetShape(g), PRIMITIVES) for g in geometries), shapes
    assert counts[Role.kProximity] >= 15 and counts[Role.kIllustration] > counts[Role.kProximity]
    for link in UR5_LINKS[1:] + ["gripper_base_link", "left_finger_link", "right_finger_link", BASE_BODY]:
        body = plant.GetBodyByName(link, robot.instance)
        assert inspector.GetGeometries(plant.GetBodyFrameIdOrThrow(body.index()), Role.kProximity), link


def test_collision_filters(robot: Robot):
    plant, inspector = robot.plant, robot.scene_graph.model_inspector()

    def geometry(link: str):
        body = plant.GetBodyByName(link, robot.instance)
        return inspector.GetGeometries(plant.GetBodyFrameIdOrThrow(body.index()), Role.kProximity)[0]

    # The closed fingers touch each other and the wrist links nest: those pairs never count.
    assert inspector.CollisionFiltered(geometry("left_finger_link"), geometry("right_finger_link"))
    assert inspector.CollisionFiltered(geometry("wrist_1_link"), geometry("wrist_3_link"))
    # The gripper can still hit the arm and the base.
    assert not inspector.CollisionFiltered(geometry("left_finger_link"), geometry("forearm_link"))
    assert not inspector.CollisionFiltered(geometry("gripper_base_link"), geometry(BASE_BODY))
    assert not inspector.CollisionFiltered(geometry("upper_arm_link"), geometry(BASE_BODY))


def test_masses_and_inertias(robot: Robot):
    plant = robot.plant
    arm_mass = sum(plant.GetBodyByName(link, robot.instance).default_mass() for link in UR5_LINKS)
    assert arm_mass == pytest.approx(sum(UR5_MASSES), abs=1e-9)
    for link, mass in zip(UR5_LINKS, UR5_MASSES):
        assert plant.GetBodyByName(link, robot.instance).default_mass() == pytest.approx(mass)
    base_mass = plant.GetBodyByName(BASE_BODY, robot.instance).default_mass()
    assert base_mass == pytest.approx(135.0 + 15.0)  # the base and its riser
    gripper = sum(
        plant.GetBodyByName(link, robot.instance).default_mass()
        for link in ("gripper_base_link", "left_finger_link", "right_finger_link")
    )
    assert 0.85 <= gripper <= 1.0
    for index in plant.GetBodyIndices(robot.instance):
        body = plant.get_body(index)
        inertia = body.default_spatial_inertia()
        assert inertia.IsPhysicallyValid(), body.name()
        if body.default_mass() > 0:
            about_com = inertia.Shift(inertia.get_com()).CalcRotationalInertia()
            moments = sorted(about_com.CalcPrincipalMomentsOfInertia())
            assert moments[0] > 0 and moments[0] + moments[1] >= moments[2], body.name()
