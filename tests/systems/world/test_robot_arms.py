"""The fixed-base arms on pedestals (hlp_drake/models/robot/panda.urdf, iiwa14.urdf): parsing, joints, limits,
actuators, the mimic finger, published kinematics, the pedestal, the gripper, the ready poses."""

from __future__ import annotations

import importlib.util
import math
import subprocess
import sys
from dataclasses import dataclass

import numpy as np
import pytest
from conftest import REPO
from pydrake.geometry import Box, Capsule, Cylinder, Role, SceneGraph, Sphere
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.plant import (
    AddMultibodyPlantSceneGraph,
    DiscreteContactApproximation,
    MultibodyPlant,
)
from pydrake.multibody.tree import ModelInstanceIndex
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import Diagram, DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from hlp_drake.systems.world.robot import new_parser
from hlp_drake.systems.world.robot_description import MODELS_PACKAGE, models_directory

ROBOT_DIR = models_directory() / "robot"
TOOLS = REPO / "tools" / "robot_models"
PRIMITIVES = (Box, Cylinder, Capsule, Sphere)
DEG = math.pi / 180.0


def _make_arms():
    """The generating script's constants (mount heights, ready poses), loaded by path."""
    spec = importlib.util.spec_from_file_location("make_arms", TOOLS / "make_arms.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


MAKE_ARMS = _make_arms()


# --- Published kinematics, written out here independently of the generating script --------------
def rot_x(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def rot_z(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def trans(x: float, y: float, z: float) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, 3] = (x, y, z)
    return pose


# Franka's Craig (modified) DH parameters (a_{i-1}, d_i, alpha_{i-1}) of joints 1..7 and the flange.
PANDA_MDH = [
    (0.0, 0.333, 0.0),
    (0.0, 0.0, -math.pi / 2),
    (0.0, 0.316, math.pi / 2),
    (0.0825, 0.0, math.pi / 2),
    (-0.0825, 0.384, -math.pi / 2),
    (0.0, 0.0, math.pi / 2),
    (0.088, 0.0, math.pi / 2),
]
PANDA_FLANGE_D = 0.107


def panda_flange(q) -> np.ndarray:
    """Flange (franka's panda_link8) in panda_link0: prod RotX(alpha) TransX(a) RotZ(q) TransZ(d)."""
    pose = np.eye(4)
    for theta, (a, d, alpha) in zip(q, PANDA_MDH):
        pose = pose @ rot_x(alpha) @ trans(a, 0, 0) @ rot_z(theta) @ trans(0, 0, d)
    return pose @ trans(0, 0, PANDA_FLANGE_D)


# KUKA LBR iiwa 14 R820, standard DH (d_i, alpha_i), all a_i = 0; d7 to the flange.
IIWA_DH = [
    (0.36, -math.pi / 2),
    (0.0, math.pi / 2),
    (0.42, math.pi / 2),
    (0.0, -math.pi / 2),
    (0.40, -math.pi / 2),
    (0.0, math.pi / 2),
    (0.126, 0.0),
]


def iiwa_flange(q) -> np.ndarray:
    """Flange in iiwa_link_0: prod RotZ(q) TransZ(d) RotX(alpha)."""
    pose = np.eye(4)
    for theta, (d, alpha) in zip(q, IIWA_DH):
        pose = pose @ rot_z(theta) @ trans(0, 0, d) @ rot_x(alpha)
    return pose


@dataclass(frozen=True)
class ArmSpec:
    name: str
    joints: tuple[str, ...]
    lower: tuple[float, ...]
    upper: tuple[float, ...]
    velocity: tuple[float, ...]
    effort: tuple[float, ...]
    links: tuple[str, ...]  # link 0 (the DH base) .. link 7
    masses: tuple[float, ...]  # links 1..7
    flange: str
    palm: str
    fingers: tuple[str, str]
    finger_joints: tuple[str, str]
    stroke: float
    finger_force: float
    finger_base: float  # finger joints' origin along the palm's z
    tcp: float
    hand_yaw: float  # the palm (and tcp) about the flange's z
    hand_bracket: (
        float  # > 0: an angle bracket, the palm this far out along the flange's z, turned to face its x
    )
    forward_kinematics: object
    mount: float
    home: tuple[float, ...]
    home_tcp: tuple[float, float, float]
    home_pitch: float  # at most, rad

    def hand_mount(self) -> RigidTransform:
        """The palm's pose in the flange's frame."""
        if self.hand_bracket == 0.0:
            return RigidTransform(RotationMatrix.MakeZRotation(self.hand_yaw))
        # approach (z) along the flange's x, the palm's x along the flange's z (the flange points down)
        turned = RotationMatrix(np.array([[0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]]))
        return RigidTransform(turned, [0.0, 0.0, self.hand_bracket])

    @property
    def pedestal(self) -> str:
        return f"{self.name}_pedestal"


PANDA = ArmSpec(
    name="panda",
    joints=tuple(f"panda_joint{i}" for i in range(1, 8)),
    lower=(-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973),
    upper=(2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973),
    velocity=(2.175,) * 4 + (2.61,) * 3,
    effort=(87.0,) * 4 + (12.0,) * 3,
    links=tuple(f"panda_link{i}" for i in range(8)),
    masses=(4.970684, 0.646926, 3.228604, 3.587895, 1.225946, 1.666555, 0.735522),  # Gaz et al. 2019
    flange="panda_flange",
    palm="panda_hand",
    fingers=("panda_leftfinger", "panda_rightfinger"),
    finger_joints=("panda_finger_joint1", "panda_finger_joint2"),
    stroke=0.04,
    finger_force=70.0,
    finger_base=0.0584,
    tcp=0.1034,
    hand_yaw=-math.pi / 4,
    hand_bracket=0.0,
    forward_kinematics=panda_flange,
    mount=MAKE_ARMS.PANDA_MOUNT,
    home=MAKE_ARMS.PANDA_HOME,
    home_tcp=(0.40, 0.0, 0.81),
    home_pitch=2e-3,
)
IIWA = ArmSpec(
    name="iiwa14",
    joints=tuple(f"iiwa_joint_{i}" for i in range(1, 8)),
    lower=tuple(-a * DEG for a in (170, 120, 170, 120, 170, 120, 175)),
    upper=tuple(a * DEG for a in (170, 120, 170, 120, 170, 120, 175)),
    velocity=tuple(v * DEG for v in (85, 85, 100, 75, 130, 135, 135)),
    effort=(320.0, 320.0, 176.0, 176.0, 110.0, 40.0, 40.0),
    links=tuple(f"iiwa_link_{i}" for i in range(8)),
    masses=(4.0, 4.0, 3.0, 2.7, 1.7, 1.8, 0.3),
    flange="iiwa_flange",
    palm="wsg_body",
    fingers=("wsg_left_finger", "wsg_right_finger"),
    finger_joints=("wsg_left_finger_joint", "wsg_right_finger_joint"),
    stroke=0.055,
    finger_force=80.0,
    finger_base=0.087,
    tcp=0.13,
    hand_yaw=0.0,
    hand_bracket=MAKE_ARMS.WSG_BRACKET,
    forward_kinematics=iiwa_flange,
    mount=MAKE_ARMS.IIWA_MOUNT,
    home=MAKE_ARMS.IIWA_HOME,
    home_tcp=(0.45, 0.0, 0.81),
    home_pitch=0.08,
)
ARMS = (PANDA, IIWA)


@dataclass
class Robot:
    spec: ArmSpec
    diagram: Diagram
    plant: MultibodyPlant
    scene_graph: SceneGraph
    instance: ModelInstanceIndex

    def contexts(self):
        context = self.diagram.CreateDefaultContext()
        return (
            context,
            self.plant.GetMyContextFromRoot(context),
            self.scene_graph.GetMyContextFromRoot(context),
        )

    def frame(self, name: str):
        return self.plant.GetFrameByName(name, self.instance)

    def set(self, context, arm=None, finger: float = 0.0) -> None:
        """Arm joint angles (the ready pose by default) and both fingers' travel."""
        arm = self.spec.home if arm is None else arm
        for name, value in zip(self.spec.joints, arm):
            self.plant.GetJointByName(name, self.instance).set_angle(context, float(value))
        for name in self.spec.finger_joints:
            self.plant.GetJointByName(name, self.instance).set_translation(context, finger)


def build(spec: ArmSpec, *, gravity: bool = True, actuation: np.ndarray | None = None) -> Robot:
    """The arm as ``add_robot`` loads the mobile UR5: a discrete SAP plant, the project's parser and
    package URL; its pedestal welded to the world at the origin."""
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.001)
    plant.set_discrete_contact_approximation(DiscreteContactApproximation.kSap)
    (instance,) = new_parser(plant).AddModels(url=f"package://{MODELS_PACKAGE}/robot/{spec.name}.urdf")
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName(spec.pedestal, instance))
    if not gravity:
        plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, 0.0])
    plant.Finalize()
    if actuation is not None:
        source = builder.AddSystem(ConstantVectorSource(actuation))
        builder.Connect(source.get_output_port(), plant.get_actuation_input_port())
    return Robot(spec, builder.Build(), plant, scene_graph, instance)


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
