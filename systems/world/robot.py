"""The mobile manipulator: a UR5 arm with a two-finger gripper on an omnidirectional base.

The model is ``models/robot/mobile_ur5.urdf`` (written by ``models/robot/make_mobile_ur5.py``),
loaded as ``package://hlp_drake_models/robot/mobile_ur5.urdf``. It has 10 actuated degrees of
freedom, in this actuator order: the base's x, y and yaw (prismatic, prismatic, revolute joints
from the world), the UR5's six joints and the gripper's left finger. The right finger follows the
left one through a URDF ``<mimic>``, which Drake turns into a coupler constraint, so the plant has
11 positions and 11 velocities but 10 actuators.

Coupler constraints are simulated only by a discrete ``MultibodyPlant`` whose contact solver is
SAP (the default approximation ``kLagged``, or ``kSap`` or ``kSimilar``). A continuous plant
(``time_step=0``) loads the model for kinematics (IK, collision queries) but cannot be simulated.

Frames (link names): ``base_link`` (on the floor below the middle of the base's footprint, x
forward; it carries the riser), ``ur5_base_link`` (the arm mount on top of the riser),
``ur5_base`` (the UR5's DH base frame, the mount turned by pi about z), ``ur5_flange`` (the DH tool
flange, ROS's ``tool0``), ``gripper_base_link`` (the same pose as the flange) and ``tcp`` (between
the fingertip pads, +z along the approach direction, +y along the left finger's opening direction).
"""

from __future__ import annotations

import math
import os
from contextlib import contextmanager
from pathlib import Path
from typing import NamedTuple

import numpy as np
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import DiscreteContactSolver, MultibodyPlant
from pydrake.multibody.tree import Joint, ModelInstanceIndex
from pydrake.systems.framework import Context

import hlp_drake.models
from hlp_drake.errors import InstallError, short

# The project's own Drake model package (``package://hlp_drake_models/...``); no remote packages.
MODELS_PACKAGE = "hlp_drake_models"


def models_directory() -> Path:
    """The folder that holds ``package.xml`` and the robot and scene model files."""
    return Path(hlp_drake.models.__file__).resolve().parent


REINSTALL = (
    "reinstall hlp_drake (pip install --force-reinstall --no-deps hlp_drake; in a clone: git checkout models)"
)
"""The hint of a damaged or missing model package."""


def drake_reason(error: Exception, named: Path | None = None) -> str:
    """The first line of a Drake error, short (its parse errors run over many lines); the file
    ``named`` already names in the message is called by its name only (a deep install path would
    otherwise push the hint off the one-line message)."""
    lines = [line.strip() for line in str(error).splitlines() if line.strip()]
    first = lines[0] if lines else type(error).__name__
    if named is not None:
        first = first.replace(str(named), named.name)
    return short(first, 160)


def configure_parser(parser: Parser) -> Parser:
    """Register the project's model package with ``parser``'s package map and return the parser.

    Raises:
        InstallError: the package's ``package.xml`` is missing or cannot be read.
    """
    package_map = parser.package_map()
    if not package_map.Contains(MODELS_PACKAGE):
        xml = models_directory() / "package.xml"
        try:
            package_map.AddPackageXml(str(xml))
        except RuntimeError as error:
            raise InstallError(
                f"{xml}: the model package is missing or damaged ({drake_reason(error, xml)}); {REINSTALL}"
            ) from None
    return parser


@contextmanager
def _package_map_network_allowed():
    """Let Drake's default PackageMap *register* its remote ``drake_models`` package.

    Under ``DRAKE_ALLOW_NETWORK`` without ``package_map`` (e.g. ``none`` or ``meshcat``), Drake
    refuses to construct a Parser unless ``drake_models`` is already downloaded, although
    registering it downloads nothing (only resolving a ``package://drake_models/...`` URL would).
    Our models never refer to it, so the restriction is lifted for the construction only.
    """
    policy = os.environ.get("DRAKE_ALLOW_NETWORK")
    if policy is None or "package_map" in policy.split(":"):
        yield
        return
    os.environ["DRAKE_ALLOW_NETWORK"] = "package_map"
    try:
        yield
    finally:
        os.environ["DRAKE_ALLOW_NETWORK"] = policy


def new_parser(plant: MultibodyPlant) -> Parser:
    """A Parser for ``plant`` with the project's package registered, under any network policy."""
    with _package_map_network_allowed():
        parser = Parser(plant)
    return configure_parser(parser)


ROBOT_URL = f"package://{MODELS_PACKAGE}/robot/mobile_ur5.urdf"
ROBOT_MODEL_NAME = "mobile_ur5"

BASE_JOINTS: tuple[str, ...] = ("base_x_joint", "base_y_joint", "base_yaw_joint")
ARM_JOINTS: tuple[str, ...] = (
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "elbow_joint",
    "wrist_1_joint",
    "wrist_2_joint",
    "wrist_3_joint",
)
GRIPPER_JOINTS: tuple[str, ...] = ("left_finger_joint",)
"""The gripper's actuated joint: each finger's travel from the centre, 0 (closed) to 0.0425 m."""
GRIPPER_MIMIC_JOINTS: tuple[str, ...] = ("right_finger_joint",)
"""Unactuated joints that copy ``left_finger_joint`` through a coupler constraint."""
ACTUATED_JOINTS: tuple[str, ...] = BASE_JOINTS + ARM_JOINTS + GRIPPER_JOINTS
"""The 10 actuated joints, in the plant's actuator order."""

BASE_BODY = "base_link"
ARM_BASE_FRAME = "ur5_base"
FLANGE_FRAME = "ur5_flange"
TCP_FRAME = "tcp"

BASE_FOOTPRINT = (0.96, 0.79)
"""Length (x) and width (y) of the base, m; its top deck is ``DECK_HEIGHT`` above the floor."""
DECK_HEIGHT = 0.30
MOUNT_HEIGHT = 0.80
"""Height of the arm's mount above the floor, m: the top of the riser, a round column (part of
``base_link``, radius ``RISER_RADIUS``) standing on the deck. At about table-top height it lets the
arm stretch out flat over a 0.70-0.80 m table: the tcp, horizontal at 0.06 m above the top, reaches
about 0.96 m past the table's front edge (0.85 m and 0.73 m from a 0.60 m mount)."""
RISER_RADIUS = 0.075
ARM_MOUNT = (0.39, 0.0, MOUNT_HEIGHT)
"""Position of the UR5's mount (``ur5_base_link``) in ``base_link``, m: on the riser, 0.09 m behind
the base's front (the riser's front 0.015 m behind it)."""
TCP_OFFSET = 0.14
"""Distance of ``tcp`` from the flange along the approach axis, m."""
GRIPPER_OPEN = 0.0425
GRIPPER_CLOSED = 0.0

HOME_ARM_POSITIONS: tuple[float, ...] = (-0.2257, -0.9273, 1.9016, -0.9743, 1.3451, -math.pi / 2)
"""Ready pose of the arm, elbow up: the tcp 0.81 m above the floor (0.06 m above a 0.75 m table top)
and 1.10 m in front of the base's centre (on its centre line, 0.71 m ahead of the mount), pointing
forward (+x) with the fingers opening sideways (y): the start posture for the default
``Scenario().ik.start_reach``."""


class JointLimits(NamedTuple):
    """Limits of the actuated joints, arrays in actuator order (m, rad, m/s, rad/s)."""

    lower: np.ndarray
    upper: np.ndarray
    velocity: np.ndarray


def add_robot(
    plant: MultibodyPlant, *, parser: Parser | None = None, name: str = ROBOT_MODEL_NAME
) -> ModelInstanceIndex:
    """Parse the mobile UR5 into ``plant`` (not yet finalized) as model instance ``name``.

    Args:
        plant: the plant to add to. A discrete plant must use the SAP solver (any approximation
            but TAMSI), which the gripper's coupler constraint needs.
        parser: a parser of ``plant`` to use (for example one that also carries a builder);
            a new ``Parser(plant)`` by default. Either way it is passed through ``configure_parser``.
        name: the model instance's name; several robots need different names.

    Raises:
        ValueError: ``name`` is taken, ``parser`` belongs to another plant, or the plant is discrete
            without the SAP solver.
        InstallError: the robot's model file or its package is missing or cannot be parsed.
    """
    if plant.time_step() > 0 and plant.get_discrete_contact_solver() != DiscreteContactSolver.kSap:
        raise ValueError(
            "the robot's gripper needs a discrete plant with the SAP contact solver (its right finger "
            "follows the left one through a coupler constraint); call "
            "plant.set_discrete_contact_approximation(DiscreteContactApproximation.kLagged) or kSap first"
        )
    if plant.HasModelInstanceNamed(name):
        raise ValueError(f"the plant already has a model instance named {name!r}")
    if parser is None:
        parser = new_parser(plant)
    elif parser.plant() is not plant:
        raise ValueError("parser belongs to a different plant")
    configure_parser(parser)
    auto_renaming = parser.GetAutoRenaming()
    parser.SetAutoRenaming(True)  # the file's name may be taken by another robot
    try:
        (instance,) = parser.AddModels(url=ROBOT_URL)
    except RuntimeError as error:  # a damaged installation: one line and a hint, exit 2 on the command line
        robot_file = Path(parser.package_map().ResolveUrl(ROBOT_URL))
        raise InstallError(
            f"{ROBOT_URL}: the robot model cannot be parsed ({drake_reason(error, robot_file)}); {REINSTALL}"
        ) from None
    finally:
        parser.SetAutoRenaming(auto_renaming)
    if plant.GetModelInstanceName(instance) != name:
        plant.RenameModelInstance(instance, name)
    return instance


def actuated_joints(plant: MultibodyPlant, instance: ModelInstanceIndex) -> list[Joint]:
    """The joints of ``instance``'s actuators, in actuator order."""
    return [plant.get_joint_actuator(index).joint() for index in plant.GetJointActuatorIndices(instance)]


def robot_joint_limits(plant: MultibodyPlant, instance: ModelInstanceIndex) -> JointLimits:
    """Position and velocity limits of the robot's 10 actuated joints, in actuator order.

    The velocity limit is the symmetric bound ``|v| <= velocity``.
    """
    joints = actuated_joints(plant, instance)
    return JointLimits(
        lower=np.array([j.position_lower_limits()[0] for j in joints]),
        upper=np.array([j.position_upper_limits()[0] for j in joints]),
        velocity=np.array([j.velocity_upper_limits()[0] for j in joints]),
    )


def set_robot_positions(
    plant: MultibodyPlant,
    context: Context,
    instance: ModelInstanceIndex,
    *,
    base: tuple[float, float, float] = (0.0, 0.0, 0.0),
    arm: tuple[float, ...] = HOME_ARM_POSITIONS,
    gripper: float = GRIPPER_OPEN,
) -> None:
    """Set the robot's joint positions in the plant's ``context``.

    Args:
        base: (x, y, yaw) of ``base_link`` in the world, m and rad.
        arm: the six UR5 joint angles, rad (the ready pose by default).
        gripper: each finger's travel from the centre, m (both fingers get it, so the constraint
            holds); 0 closed, ``GRIPPER_OPEN`` open.
    """
    if len(base) != 3 or len(arm) != len(ARM_JOINTS):
        raise ValueError(
            f"expected 3 base and {len(ARM_JOINTS)} arm positions, got {len(base)} and {len(arm)}"
        )
    values = dict(zip(BASE_JOINTS + ARM_JOINTS, (*base, *arm)))
    values.update({name: gripper for name in GRIPPER_JOINTS + GRIPPER_MIMIC_JOINTS})
    q = plant.GetPositions(context)
    for name, value in values.items():
        q[plant.GetJointByName(name, instance).position_start()] = float(value)
    plant.SetPositions(context, q)
