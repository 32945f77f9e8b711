"""Drake blocks of hlp_drake (imported as ``hlp_drake.systems``) and the model package they load.

Every builder and block takes one typed ``Scenario`` (``load_scenario``); the planning blocks take
the scene from their ``scene`` input port (``SceneFromPlant`` reads it from a plant,
``ScenePerception`` from the world's depth cameras). Resources
(``RolloutPool``) belong to the caller, who closes them. Subpackages: ``world``, ``planning``,
``optimiser``, ``perception`` and ``execution``; the names below are the public API.
"""

from hlp_drake.systems.execution.command import GraspConfig
from hlp_drake.systems.execution.diagram import ExecutionDiagram, make_execution_diagram
from hlp_drake.systems.execution.job import run_job, scenario_yamls
from hlp_drake.systems.execution.meshcat_view import draw_perception, draw_plan, frame_table
from hlp_drake.systems.execution.receding_horizon import RecedingHorizonController
from hlp_drake.systems.execution.run import ExecutionResult, RunListener, plan_and_execute, run_execution
from hlp_drake.systems.optimiser.config import StoConfig
from hlp_drake.systems.optimiser.control_sequence import ControlSequence
from hlp_drake.systems.optimiser.cost import RolloutOutcome
from hlp_drake.systems.optimiser.optimiser import StoResult, optimise
from hlp_drake.systems.optimiser.pool import RolloutPool, SceneRollouts
from hlp_drake.systems.optimiser.rollout_world import RolloutWorld
from hlp_drake.systems.optimiser.system import StochasticTrajectoryOptimiser
from hlp_drake.systems.perception.accuracy import perception_record
from hlp_drake.systems.perception.cameras import CameraConfig, PerceptionConfig
from hlp_drake.systems.perception.perception import PerceivedObject, Perception, perceive
from hlp_drake.systems.perception.system import ScenePerception, add_scene_perception, perceive_world
from hlp_drake.systems.planning.diagram import (
    HlpPlannerSystem,
    StraightLinePlanSystem,
    first_rollout,
    initial_sequence,
    make_planning_diagram,
    straight_line_plan,
)
from hlp_drake.systems.planning.ik import KeypointIk
from hlp_drake.systems.planning.keyframes import Keyframes, PlanningModel
from hlp_drake.systems.planning.transfer import RobotPlanTransfer, gripper_geometry
from hlp_drake.systems.scenario import PlannerChoiceConfig, Scenario, load_scenario
from hlp_drake.systems.world.robot import (
    ACTUATED_JOINTS,
    ARM_JOINTS,
    BASE_JOINTS,
    GRIPPER_JOINTS,
    HOME_ARM_POSITIONS,
    MODELS_PACKAGE,
    ROBOT_URL,
    TCP_FRAME,
    add_robot,
    configure_parser,
    models_directory,
    robot_joint_limits,
    set_robot_positions,
)
from hlp_drake.systems.world.scene_models import (
    SceneModels,
    add_scene,
    fallen_objects,
    object_planar_poses,
    scene_from_plant,
    set_object_poses,
)
from hlp_drake.systems.world.scene_source import SceneFromPlant
from hlp_drake.systems.world.start_pose import robot_base_pose, robot_position_names, start_configuration
from hlp_drake.systems.world.world import (
    DESIRED_STATE_PORT,
    add_position_trajectory,
    desired_state_from_robot_state,
    make_world_diagram,
    world_plant,
)
from hlp_drake.transfer.push import ROBOT_ACTIONS, robot_alternatives, robot_plan
from hlp_drake.transfer.rules import (
    GripperGeometry,
    PushRules,
    TransferConfig,
    push_rules,
)

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
    "CameraConfig",
    "ControlSequence",
    "ExecutionDiagram",
    "ExecutionResult",
    "GraspConfig",
    "GripperGeometry",
    "HlpPlannerSystem",
    "Keyframes",
    "KeypointIk",
    "PerceivedObject",
    "Perception",
    "PerceptionConfig",
    "PlannerChoiceConfig",
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
    "make_execution_diagram",
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
    "run_execution",
    "run_job",
    "scenario_yamls",
    "scene_from_plant",
    "set_object_poses",
    "set_robot_positions",
    "start_configuration",
    "straight_line_plan",
    "world_plant",
]
