"""Drake blocks of hlp_drake (imported as ``hlp_drake.systems``) and the model package they load.

Every builder and block takes one typed ``Scenario`` (``load_scenario``); the planning blocks take
the scene from their ``scene`` input port (``SceneFromPlant`` reads it from a plant,
``ScenePerception`` from the world's depth cameras). Resources
(``RolloutPool``) belong to the caller, who closes them.
"""

from hlp_drake.systems.control_sequence import ControlSequence
from hlp_drake.systems.execution import ExecutionResult, RunListener, plan_and_execute
from hlp_drake.systems.hlp_planner_system import HlpPlannerSystem
from hlp_drake.systems.keyframes import Keyframes
from hlp_drake.systems.keypoint_ik import KeypointIk
from hlp_drake.systems.meshcat_view import draw_perception, draw_plan, frame_table
from hlp_drake.systems.model_package import MODELS_PACKAGE, configure_parser, models_directory
from hlp_drake.systems.optimiser import StoResult, optimise
from hlp_drake.systems.optimiser_config import StoConfig
from hlp_drake.systems.optimiser_system import StochasticTrajectoryOptimiser
from hlp_drake.systems.perception import PerceivedObject, Perception, perceive
from hlp_drake.systems.perception_config import CameraSettings, PerceptionConfig
from hlp_drake.systems.perception_errors import perception_record
from hlp_drake.systems.planning_diagram import first_rollout, initial_sequence, make_planning_diagram
from hlp_drake.systems.planning_model import PlanningModel
from hlp_drake.systems.push_transfer import ROBOT_ACTIONS, robot_alternatives, robot_plan
from hlp_drake.systems.receding_horizon import RecedingHorizonController
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
from hlp_drake.systems.robot_transfer import RobotPlanTransfer
from hlp_drake.systems.rollout_cost import RolloutOutcome
from hlp_drake.systems.rollout_pool import RolloutPool
from hlp_drake.systems.rollout_world import RolloutWorld
from hlp_drake.systems.scenario import PlannerSettings, Scenario, load_scenario
from hlp_drake.systems.scene_models import (
    SceneModels,
    add_scene,
    fallen_objects,
    object_planar_poses,
    scene_from_plant,
    set_object_poses,
)
from hlp_drake.systems.scene_perception import ScenePerception, add_scene_perception, perceive_world
from hlp_drake.systems.scene_rollouts import SceneRollouts
from hlp_drake.systems.scene_source import SceneFromPlant
from hlp_drake.systems.start_pose import robot_base_pose, robot_position_names, start_configuration
from hlp_drake.systems.straight_line import StraightLinePlanSystem, straight_line_plan
from hlp_drake.systems.transfer_geometry import (
    GripperGeometry,
    PushRules,
    TransferConfig,
    gripper_geometry,
    push_rules,
)
from hlp_drake.systems.world import (
    DESIRED_STATE_PORT,
    add_position_trajectory,
    desired_state_from_robot_state,
    make_world_diagram,
    world_plant,
)
from hlp_drake.systems.world_settings import GraspConfig

__all__ = [
    "ACTUATED_JOINTS",
    "ARM_JOINTS",
    "BASE_JOINTS",
    "DESIRED_STATE_PORT",
    "GRIPPER_JOINTS",
    "HOME_ARM_POSITIONS",
    "MODELS_PACKAGE",
    "ROBOT_ACTIONS",
    "ROBOT_URL",
    "TCP_FRAME",
    "CameraSettings",
    "ControlSequence",
    "ExecutionResult",
    "GraspConfig",
    "GripperGeometry",
    "HlpPlannerSystem",
    "Keyframes",
    "KeypointIk",
    "PerceivedObject",
    "Perception",
    "PerceptionConfig",
    "PlannerSettings",
    "PlanningModel",
    "PushRules",
    "RecedingHorizonController",
    "RobotPlanTransfer",
    "RolloutOutcome",
    "RolloutPool",
    "RolloutWorld",
    "RunListener",
    "Scenario",
    "SceneFromPlant",
    "SceneModels",
    "ScenePerception",
    "SceneRollouts",
    "StoConfig",
    "StoResult",
    "StochasticTrajectoryOptimiser",
    "StraightLinePlanSystem",
    "TransferConfig",
    "add_position_trajectory",
    "add_robot",
    "add_scene",
    "add_scene_perception",
    "configure_parser",
    "desired_state_from_robot_state",
    "draw_perception",
    "draw_plan",
    "fallen_objects",
    "first_rollout",
    "frame_table",
    "gripper_geometry",
    "initial_sequence",
    "load_scenario",
    "make_planning_diagram",
    "make_world_diagram",
    "models_directory",
    "object_planar_poses",
    "optimise",
    "perceive",
    "perceive_world",
    "perception_record",
    "plan_and_execute",
    "push_rules",
    "robot_alternatives",
    "robot_base_pose",
    "robot_joint_limits",
    "robot_plan",
    "robot_position_names",
    "scene_from_plant",
    "set_object_poses",
    "set_robot_positions",
    "start_configuration",
    "straight_line_plan",
    "world_plant",
]
