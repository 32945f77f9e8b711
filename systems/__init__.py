"""Drake blocks of hlp_drake (imported as ``hlp_drake.systems``) and the model package they load."""

from hlp_drake.systems.model_package import MODELS_PACKAGE, configure_parser, models_directory
from hlp_drake.systems.robot import (
    ACTUATED_JOINTS,
    ARM_JOINTS,
    BASE_JOINTS,
    GRIPPER_JOINTS,
    HOME_ARM_POSITIONS,
    ROBOT_URL,
    TCP_FRAME,
    add_robot,
    robot_joint_limits,
    set_robot_positions,
)

__all__ = [
    "ACTUATED_JOINTS",
    "ARM_JOINTS",
    "BASE_JOINTS",
    "GRIPPER_JOINTS",
    "HOME_ARM_POSITIONS",
    "MODELS_PACKAGE",
    "ROBOT_URL",
    "TCP_FRAME",
    "add_robot",
    "configure_parser",
    "models_directory",
    "robot_joint_limits",
    "set_robot_positions",
]
