"""``RobotDescription``: a robot as data, the scenario's ``robot`` section, and the shipped robots.

A description names a model file (URDF or SDF) and, in it, what the blocks need (see the class);
``hlp_drake.systems.world.robot`` loads the model and checks the names against it. Three robots
are shipped in the model package's ``robot`` folder (``SHIPPED_ROBOTS``; ``load_robot(NAME)``).
Imports no Drake.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Literal

import hlp_drake.models
from hlp_drake.config.ranges import NonNegativeFloat
from hlp_drake.errors import HlpError
from hlp_drake.models import SHIPPED_ROBOTS
from hlp_drake.scene.workspace import Workspace

# The project's own Drake model package (``package://hlp_drake_models/...``); no remote packages.
MODELS_PACKAGE = "hlp_drake_models"


def models_directory() -> Path:
    """The folder that holds ``package.xml`` and the robot and scene model files."""
    return Path(hlp_drake.models.__file__).resolve().parent


ROBOTS_FOLDER = "robot"
"""The folder of the model package holding the shipped robots: ``NAME.urdf`` and its description
``NAME.yaml`` each."""


@dataclass(frozen=True)
class BaseConfig:
    """Where the robot stands.

    Attributes:
        kind: "mobile": a planar base driven by ``joints`` (x, y, yaw, in that order, from the world;
            their limits come from the model), placed behind the scene's start at each run
            (``ik.start_reach``); "fixed": the model's ``frame`` welded to the world at ``pose``.
        joints: the mobile base's x, y and yaw joints ("mobile" only).
        footprint: length (x) and width (y) of a mobile base, m: it keeps ``ik.start_base_clearance``
            from the table's front edge.
        frame: the model's frame welded to the world ("fixed" only).
        pose: (x, y, yaw) of ``frame`` on the floor, m and rad, in the scene's frame: x into the
            table from the middle of its front edge, y to the left ("fixed" only).
    """

    kind: Literal["mobile", "fixed"] = "mobile"
    joints: tuple[str, ...] = ("base_x_joint", "base_y_joint", "base_yaw_joint")
    footprint: tuple[float, float] = (0.96, 0.79)
    frame: str = ""
    pose: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class RobotDescription:
    """A robot as data: its model file and what the planning and execution blocks need of it.

    Nothing outside a description names a joint or a link; joint limits come from the model. The
    defaults describe the shipped ``mobile_ur5``; ``--robot NAME`` reads ``hlp_drake/models/robot/NAME.yaml``.

    Attributes:
        name: the robot's name, also its model instance's.
        model: a ``package://`` URL, a ``file://`` URL or a path (a scenario file's relative path
            is read from its folder) of a URDF or SDF file.
        base: where it stands (``BaseConfig``).
        arm_joints: the arm's revolute joints, base to wrist; the last three are the wrist (their
            gains are ``controller.wrist``, the others' ``controller.arm``).
        gripper_joint: the actuated finger joint (prismatic: each finger's travel from the centre).
        mimic_joints: unactuated finger joints copying ``gripper_joint`` (a URDF ``<mimic>``, which
            needs the SAP solver).
        tcp_frame: the frame between the fingertip pads: +z the approach direction, +y the fingers'
            opening direction.
        flange_frame: the arm's tool flange (the push transfer's gripper length is measured from it).
        wrist_link: the arm's last link (its radius is one of the transfer's clearances).
        gripper_links: the palm and finger links (the gripper's friction; the fingers' extent).
        finger_links: the two finger links (their box is the transfer's finger geometry).
        home: the arm's ready configuration, rad: the seed of the start pose's IK.
        gripper_open: ``gripper_joint``'s position with the fingers open, m (> ``gripper_closed``).
        gripper_closed: its position with the fingers closed, m.
        reach: how far from the base's ``pose`` the tcp reaches over the table, held horizontal at
            ``ik.height`` (a fixed base; the scene generators keep their tables within it), m; 0 for a
            mobile base.
        approach_weight: the keypoint IK's pull of the approach axis towards world +x, the way the
            push transfer assumes the gripper points: a cost of this times (1 - cos) of their angle,
            beside the keyframe's step (1 per rad^2 or m^2). 0: none, the axis anywhere within
            ``ik.approach_tolerance`` (a mobile base squares the hand by turning itself; a fixed arm's
            step cost lets its hand turn to the cone's edge, where a wide hand sweeps its neighbours).
    """

    name: str = "mobile_ur5"
    model: str = f"package://{MODELS_PACKAGE}/{ROBOTS_FOLDER}/mobile_ur5.urdf"
    base: BaseConfig = field(default_factory=BaseConfig)
    arm_joints: tuple[str, ...] = (
        "shoulder_pan_joint",
        "shoulder_lift_joint",
        "elbow_joint",
        "wrist_1_joint",
        "wrist_2_joint",
        "wrist_3_joint",
    )
    gripper_joint: str = "left_finger_joint"
    mimic_joints: tuple[str, ...] = ("right_finger_joint",)
    tcp_frame: str = "tcp"
    flange_frame: str = "ur5_flange"
    wrist_link: str = "wrist_3_link"
    gripper_links: tuple[str, ...] = ("gripper_base_link", "left_finger_link", "right_finger_link")
    finger_links: tuple[str, str] = ("left_finger_link", "right_finger_link")
    home: tuple[float, ...] = (-0.2257, -0.9273, 1.9016, -0.9743, 1.3451, -math.pi / 2)
    gripper_open: float = 0.0425
    gripper_closed: float = 0.0
    reach: NonNegativeFloat = 0.0
    approach_weight: NonNegativeFloat = 0.0

    @property
    def mobile(self) -> bool:
        return self.base.kind == "mobile"

    @property
    def base_joints(self) -> tuple[str, ...]:
        """The mobile base's x, y and yaw joints; none for a fixed base."""
        return self.base.joints if self.mobile else ()

    @property
    def gripper_joints(self) -> tuple[str, ...]:
        """The finger joints: the actuated one, then the mimics."""
        return (self.gripper_joint, *self.mimic_joints)

    @property
    def actuated_joints(self) -> tuple[str, ...]:
        """The actuated joints in the plant's actuator order: base, arm, gripper."""
        return (*self.base_joints, *self.arm_joints, self.gripper_joint)

    @property
    def position_names(self) -> tuple[str, ...]:
        """The joints of the robot's positions, in model-instance order: the actuated, then the mimics."""
        return (*self.actuated_joints, *self.mimic_joints)

    @property
    def workspace(self) -> Workspace | None:
        """Where a fixed robot reaches (the scene generators keep their tables within it); None if mobile."""
        if self.mobile:
            return None
        return Workspace(x=self.base.pose[0], y=self.base.pose[1], reach=self.reach)

    @property
    def base_columns(self) -> tuple[int, ...]:
        """Columns of the base's x, y and yaw in the robot's positions (none for a fixed base)."""
        return tuple(range(len(self.base_joints)))

    @property
    def finger_columns(self) -> tuple[int, ...]:
        """Columns of the finger joints in the robot's positions."""
        names = self.position_names
        return tuple(names.index(name) for name in self.gripper_joints)

    def problems(self, where: str = "robot") -> list[str]:
        """What is wrong with the description on its own (the model is checked when loaded)."""
        problems = []
        if self.mobile and len(self.base.joints) != 3:
            problems.append(
                f"{where}.base.joints: a mobile base needs its x, y and yaw joints, got {len(self.base.joints)}"
            )
        if not self.mobile and not self.base.frame:
            problems.append(f"{where}.base.frame: a fixed base names the model frame welded to the world")
        if not self.mobile and self.reach <= 0:
            problems.append(f"{where}.reach: a fixed base needs the arm's reach over the table (> 0 m)")
        if len(self.arm_joints) < 4:
            problems.append(f"{where}.arm_joints: an arm needs at least 4 joints, got {len(self.arm_joints)}")
        if len(self.home) != len(self.arm_joints):
            problems.append(f"{where}.home: {len(self.home)} angles for {len(self.arm_joints)} arm joints")
        if not self.gripper_open > self.gripper_closed:
            problems.append(
                f"{where}.gripper_open: the gripper has no opening ({self.gripper_open} <= "
                f"gripper_closed {self.gripper_closed})"
            )
        names = self.position_names
        if len(set(names)) != len(names):
            problems.append(f"{where}: a joint is named twice among base, arm and gripper joints")
        if not self.mobile:
            x, y, _ = self.base.pose
            distance = math.hypot(x, y)
            if self.reach > 0 and distance >= self.reach:
                problems.append(
                    f"{where}.base.pose: ({x}, {y}) is {distance:.2f} m from the middle of the table's "
                    f"front edge, beyond the arm's reach {self.reach} m"
                )
            if x > 0:
                problems.append(
                    f"{where}.base.pose: x {x} m stands under the table (x > 0); put it at x <= 0"
                )
        return problems


MOBILE_UR5 = RobotDescription()
"""The default robot: a UR5 with a two-finger gripper on an omnidirectional base."""


def robot_file(name: str) -> Path:
    """The description file of the shipped robot ``name``."""
    return models_directory() / ROBOTS_FOLDER / f"{name}.yaml"


def load_robot(name_or_file: str | Path) -> RobotDescription:
    """A shipped robot by name (``SHIPPED_ROBOTS``) or a description file's robot (a YAML mapping of
    ``RobotDescription``'s fields; a relative ``model`` path is read from the file's folder).

    Raises:
        HlpError: an unknown name, a missing or malformed file; one line naming the field.
    """
    from hlp_drake.config.typed_yaml import load_typed
    from hlp_drake.files.documents import parse_yaml, read_document

    text = str(name_or_file)
    path = robot_file(text) if text in SHIPPED_ROBOTS else Path(text)
    if text not in SHIPPED_ROBOTS and path.suffix not in (".yaml", ".yml"):
        raise HlpError(
            f"robot {text!r}: not a shipped robot ({', '.join(SHIPPED_ROBOTS)}) nor a .yaml description file"
        )
    document = parse_yaml(read_document(path, missing="robot description not found"), str(path))
    if document is None:  # else the defaults: the mobile UR5 under another name
        raise HlpError(f"{path}: the file is empty; a robot description names its model, joints and frames")
    robot = load_typed(RobotDescription, document, defaults=RobotDescription(), where=str(path), top="robot")
    robot = with_model_beside(robot, path.parent)
    problems = robot.problems(str(path))
    model = missing_model(robot)
    if model is not None:
        problems.insert(0, f"{path}: model: {model} does not exist")
    if problems:
        raise HlpError(*problems)
    return robot


def missing_model(robot: RobotDescription) -> Path | None:
    """The model file a description names when it is a path or ``file://`` URL and the file does not
    exist, else None (a ``package://`` URL is resolved when the model is loaded)."""
    if robot.model.startswith("package://"):
        return None
    path = Path(robot.model.removeprefix("file://"))
    return None if path.exists() else path


def with_model_beside(robot: RobotDescription, folder: Path) -> RobotDescription:
    """``robot`` with a relative ``model`` path read from ``folder`` (where its file is)."""
    if "://" in robot.model or Path(robot.model).is_absolute():
        return robot
    return replace(robot, model=str((folder / robot.model).resolve()))


__all__ = [
    "MOBILE_UR5",
    "MODELS_PACKAGE",
    "SHIPPED_ROBOTS",
    "BaseConfig",
    "RobotDescription",
    "load_robot",
    "missing_model",
    "models_directory",
    "robot_file",
    "with_model_beside",
]
