"""Drake blocks of hlp_drake (imported as ``hlp_drake.systems``) and the model package they load."""

from hlp_drake.systems.control_sequence import ControlSequence
from hlp_drake.systems.hlp_planner_system import HlpPlannerSystem
from hlp_drake.systems.keypoint_ik import Keyframes, KeypointIk
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
from hlp_drake.systems.rollout import RolloutOutcome, RolloutWorld, SceneRollouts
from hlp_drake.systems.rollout_pool import RolloutPool
from hlp_drake.systems.scene_models import (
    SceneModels,
    add_scene,
    fallen_objects,
    object_planar_poses,
    scene_from_plant,
    set_object_poses,
)
from hlp_drake.systems.sto import StochasticTrajectoryOptimiser, StoResult, optimise
from hlp_drake.systems.sto_config import GraspConfig, StoConfig
from hlp_drake.systems.world import (
    DESIRED_STATE_PORT,
    PlanningModel,
    add_position_trajectory,
    desired_state_from_robot_state,
    make_world_diagram,
    robot_base_pose,
    start_configuration,
    world_plant,
)
from hlp_drake.systems.world_config import WorldConfig, load_world_config

__all__ = [
    "ACTUATED_JOINTS",
    "ARM_JOINTS",
    "BASE_JOINTS",
    "DESIRED_STATE_PORT",
    "GRIPPER_JOINTS",
    "HOME_ARM_POSITIONS",
    "MODELS_PACKAGE",
    "ROBOT_URL",
    "TCP_FRAME",
    "ControlSequence",
    "GraspConfig",
    "HlpPlannerSystem",
    "Keyframes",
    "KeypointIk",
    "PlanningModel",
    "RolloutOutcome",
    "RolloutPool",
    "RolloutWorld",
    "SceneModels",
    "SceneRollouts",
    "StoConfig",
    "StoResult",
    "StochasticTrajectoryOptimiser",
    "WorldConfig",
    "add_position_trajectory",
    "add_robot",
    "add_scene",
    "configure_parser",
    "desired_state_from_robot_state",
    "fallen_objects",
    "load_world_config",
    "make_world_diagram",
    "models_directory",
    "object_planar_poses",
    "optimise",
    "robot_base_pose",
    "robot_joint_limits",
    "scene_from_plant",
    "set_object_poses",
    "set_robot_positions",
    "start_configuration",
    "world_plant",
]
