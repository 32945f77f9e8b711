"""The fixed-base arms on pedestals as published (``PANDA``, ``IIWA``: joints, limits, masses, the
kinematics written out independently of the generating script ``tools/robot_models/make_arms.py``,
whose mount heights and ready poses they take) and ``build``: an arm loaded as ``add_robot`` loads the
mobile UR5."""

from __future__ import annotations

import importlib.util
import math
from dataclasses import dataclass

import numpy as np
from conftest import REPO
from pydrake.geometry import SceneGraph
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.plant import (
    AddMultibodyPlantSceneGraph,
    DiscreteContactApproximation,
    MultibodyPlant,
)
from pydrake.multibody.tree import ModelInstanceIndex
from pydrake.systems.framework import Diagram, DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from hlp_drake.systems.world.robot import new_parser
from hlp_drake.systems.world.robot_description import MODELS_PACKAGE, models_directory

ROBOT_DIR = models_directory() / "robot"
TOOLS = REPO / "tools" / "robot_models"
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
class BuiltRobot:
    """A robot's diagram: its plant, scene graph and model instance."""

    diagram: Diagram
    plant: MultibodyPlant
    scene_graph: SceneGraph
    instance: ModelInstanceIndex

    def contexts(self):
        """(the diagram's, the plant's and the scene graph's) default contexts."""
        context = self.diagram.CreateDefaultContext()
        return (
            context,
            self.plant.GetMyContextFromRoot(context),
            self.scene_graph.GetMyContextFromRoot(context),
        )


@dataclass
class Robot(BuiltRobot):
    spec: ArmSpec | None = None

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
    return Robot(builder.Build(), plant, scene_graph, instance, spec=spec)
