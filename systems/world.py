"""The simulated world: the mobile UR5, a scene's table and free objects, and the robot's PD control.

``make_world_diagram(scene, config)`` returns a Diagram named ``world`` with these exported ports:

Input:
    ``robot.desired_state`` (20): desired positions then velocities of the robot's 10 actuated joints
        in actuator order (``ACTUATED_JOINTS``: base x, y, yaw, the six UR5 joints, the left finger),
        fed to the plant's PD-controlled actuators. Left unconnected, the controllers are disarmed
        (only gravity compensation acts). ``desired_state_from_robot_state`` /
        ``add_position_trajectory`` map the robot's 11 positions (with the mimic finger) onto it.

Outputs:
    ``robot.state`` (22): the robot's 11 positions then 11 velocities (``robot_position_names``).
    ``state``: the whole plant's state (robot and free objects).
    ``body_poses``: ``list[RigidTransform]`` of every body's world pose, by body index.
    ``contact_results``: the plant's ``ContactResults``.
    ``query_object``: SceneGraph's ``QueryObject`` (distance and collision queries).

The plant is the subsystem ``plant`` (``world.GetSubsystemByName("plant")``) and the SceneGraph
``scene_graph``; the robot is the model instance ``ROBOT_MODEL_NAME``. The default context has the
robot in ``start_configuration(scene, ...)`` and every object at rest on the table at its scene pose.

Frames and start pose: the world frame is the scene's (z up, x into the table from the middle of its
front edge). The robot's base starts in front of the table facing +x; at the start the gripper
points along +x (horizontal approach), fingers opening along y, its tcp above ``scene.start`` at
``config.ik.height`` above the table top (``scene.start_yaw`` is not used: the gripper faces +x).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable

import numpy as np
from pydrake.geometry import (
    Meshcat,
    MeshcatParams,
    MeshcatVisualizer,
    MeshcatVisualizerParams,
    ProximityProperties,
    Role,
    RoleAssign,
    SceneGraph,
)
from pydrake.math import RotationMatrix
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.multibody.meshcat import ContactVisualizer, ContactVisualizerParams
from pydrake.multibody.plant import (
    AddMultibodyPlant,
    AddMultibodyPlantSceneGraph,
    CoulombFriction,
    MultibodyPlant,
)
from pydrake.multibody.tree import JointActuatorIndex, ModelInstanceIndex, PdControllerGains
from pydrake.solvers import SnoptSolver, Solve, SolverOptions
from pydrake.systems.controllers import InverseDynamics
from pydrake.systems.framework import Diagram, DiagramBuilder
from pydrake.systems.primitives import MatrixGain, TrajectorySource
from pydrake.trajectories import Trajectory

from hlp_drake.errors import HlpError
from hlp_drake.scene.model import Scene
from hlp_drake.systems.robot import (
    ARM_JOINTS,
    BASE_FOOTPRINT,
    BASE_JOINTS,
    GRIPPER_JOINTS,
    GRIPPER_MIMIC_JOINTS,
    GRIPPER_OPEN,
    HOME_ARM_POSITIONS,
    ROBOT_MODEL_NAME,
    TCP_FRAME,
    add_robot,
)
from hlp_drake.systems.scene_models import SceneModels, add_scene
from hlp_drake.systems.world_config import ControlConfig, WorldConfig

GRIPPER_BODIES = ("gripper_base_link", "left_finger_link", "right_finger_link")
WRIST_JOINTS = ARM_JOINTS[3:]
DESIRED_STATE_PORT = "robot.desired_state"


def robot_position_names() -> tuple[str, ...]:
    """The joints of the robot's 11 positions, in model-instance order: the 10 actuated, then the mimic."""
    return BASE_JOINTS + ARM_JOINTS + GRIPPER_JOINTS + GRIPPER_MIMIC_JOINTS


# --- Start pose ---------------------------------------------------------------------------------------


def robot_base_pose(scene: Scene, config: WorldConfig | None = None) -> tuple[float, float, float]:
    """(x, y, yaw) of the base at the start: in front of the table, facing +x, behind ``scene.start``.

    The base's centre stands ``config.ik.start_reach`` behind the start point on its line, but never
    closer to the table than ``config.ik.start_base_clearance`` (its front edge then stays at
    x <= -clearance, outside the table's footprint).
    """
    config = WorldConfig() if config is None else config
    start_x, start_y = scene.start
    x = min(start_x - config.ik.start_reach, -(BASE_FOOTPRINT[0] / 2.0 + config.ik.start_base_clearance))
    return (float(x), float(start_y), 0.0)


def tcp_rotation(approach_yaw: float = 0.0) -> RotationMatrix:
    """The gripper's keypoint orientation: tcp +z horizontal at heading ``approach_yaw`` (0: +x),
    tcp +y horizontal (fingers open sideways), tcp +x pointing down."""
    c, s = math.cos(approach_yaw), math.sin(approach_yaw)
    z = np.array([c, s, 0.0])
    y = np.array([-s, c, 0.0])
    return RotationMatrix(np.column_stack([np.cross(y, z), y, z]))


def tcp_keypoint_height(scene: Scene, config: WorldConfig) -> float:
    """World z of the tcp at the keypoints."""
    return scene.table.height + config.ik.height


@functools.lru_cache(maxsize=1)
def kinematic_robot() -> tuple[MultibodyPlant, ModelInstanceIndex]:
    """A robot-only continuous plant for kinematics (built once, shared; do not modify it)."""
    plant = MultibodyPlant(time_step=0.0)
    instance = add_robot(plant)
    plant.Finalize()
    return plant, instance


def _to_plant_order(
    plant: MultibodyPlant, instance: ModelInstanceIndex, values: dict[str, float]
) -> np.ndarray:
    """The robot's positions in ``plant``'s own order for ``instance``, from joint names."""
    starts = np.arange(plant.num_positions())
    instance_starts = plant.GetPositionsFromArray(instance, starts)
    local = {int(index): i for i, index in enumerate(instance_starts)}
    q = np.zeros(len(instance_starts))
    for name, value in values.items():
        q[local[plant.GetJointByName(name, instance).position_start()]] = value
    return q


def ik_solver_options(max_iterations: int) -> SolverOptions:
    options = SolverOptions()
    snopt = SnoptSolver().solver_id()
    options.SetOption(snopt, "Major iterations limit", int(max_iterations))
    options.SetOption(snopt, "Iterations limit", int(50 * max_iterations))
    return options


def start_configuration(
    scene: Scene,
    plant: MultibodyPlant,
    instance: ModelInstanceIndex,
    *,
    config: WorldConfig | None = None,
) -> np.ndarray:
    """The robot's 11 start positions, in ``plant``'s order for ``instance`` (as ``SetPositions`` takes them).

    The base stands at ``robot_base_pose(scene, config)``; the arm (solved by IK on a robot-only
    kinematic model, seeded and regularised towards the ready pose ``HOME_ARM_POSITIONS``) puts the
    tcp above ``scene.start`` at ``config.ik.height`` above the table top, pointing along +x with
    the fingers opening along y; the gripper is open.

    Raises:
        HlpError: the start point is out of the arm's reach from that base pose.
    """
    config = WorldConfig() if config is None else config
    base = robot_base_pose(scene, config)
    arm = _start_arm(
        round(base[0] - scene.start[0], 9),
        round(tcp_keypoint_height(scene, config), 9),
        config.ik.max_iterations,
    )
    if arm is None:
        raise HlpError(
            f"scene {scene.name or '<unnamed>'}: the arm cannot put the tcp above the start "
            f"{tuple(scene.start)} at height {tcp_keypoint_height(scene, config):.3f} m "
            f"from the base pose {base}"
        )
    values = dict(zip(BASE_JOINTS + ARM_JOINTS, (*base, *arm)))
    values.update({name: GRIPPER_OPEN for name in GRIPPER_JOINTS + GRIPPER_MIMIC_JOINTS})
    return _to_plant_order(plant, instance, values)


@functools.lru_cache(maxsize=64)
def _start_arm(base_offset_x: float, tcp_z: float, max_iterations: int) -> tuple[float, ...] | None:
    """Arm angles putting the tcp ``-base_offset_x`` ahead of the base at height ``tcp_z`` (cached)."""
    plant, instance = kinematic_robot()
    context = plant.CreateDefaultContext()
    ik = InverseKinematics(plant, context, with_joint_limits=True)
    q = ik.q()
    seed = _to_plant_order(
        plant,
        instance,
        {
            **dict(zip(BASE_JOINTS + ARM_JOINTS, (0.0, 0.0, 0.0, *HOME_ARM_POSITIONS))),
            **{name: GRIPPER_OPEN for name in GRIPPER_JOINTS + GRIPPER_MIMIC_JOINTS},
        },
    )
    fixed = np.full(len(seed), True)
    for name in ARM_JOINTS:
        fixed[plant.GetJointByName(name, instance).position_start()] = False
    prog = ik.get_mutable_prog()
    prog.AddBoundingBoxConstraint(seed[fixed], seed[fixed], q[fixed])
    tcp = plant.GetFrameByName(TCP_FRAME, instance)
    target = np.array([-base_offset_x, 0.0, tcp_z])
    ik.AddPositionConstraint(tcp, np.zeros(3), plant.world_frame(), target - 1e-4, target + 1e-4)
    ik.AddOrientationConstraint(plant.world_frame(), tcp_rotation(0.0), tcp, RotationMatrix(), 1e-3)
    prog.AddQuadraticErrorCost(np.eye(int(np.sum(~fixed))), seed[~fixed], q[~fixed])
    result = Solve(prog, seed, ik_solver_options(max_iterations))
    if not result.is_success():
        return None
    solution = result.GetSolution(q)
    return tuple(
        float(solution[plant.GetJointByName(name, instance).position_start()]) for name in ARM_JOINTS
    )


# --- Diagram ------------------------------------------------------------------------------------------


def _set_robot_contact(
    plant: MultibodyPlant, scene_graph: SceneGraph, instance: ModelInstanceIndex, config: WorldConfig
) -> None:
    """Give every robot collision geometry the configured stiffness and dissipation, and the gripper
    its friction (the other links keep the model's friction)."""
    inspector = scene_graph.model_inspector()
    contact = config.contact
    for body_index in plant.GetBodyIndices(instance):
        body = plant.get_body(body_index)
        for geometry in plant.GetCollisionGeometriesForBody(body):
            properties = ProximityProperties(inspector.GetProximityProperties(geometry))
            material = {
                "point_contact_stiffness": contact.stiffness,
                "hunt_crossley_dissipation": contact.hunt_crossley_dissipation,
            }
            if contact.relaxation_time > 0:
                material["relaxation_time"] = contact.relaxation_time
            if body.name() in GRIPPER_BODIES:
                material["coulomb_friction"] = CoulombFriction(
                    contact.gripper_friction, contact.gripper_friction
                )
            for name, value in material.items():
                if properties.HasProperty("material", name):
                    properties.UpdateProperty("material", name, value)
                else:
                    properties.AddProperty("material", name, value)
            scene_graph.AssignRole(plant.get_source_id(), geometry, properties, RoleAssign.kReplace)


def _set_pd_gains(plant: MultibodyPlant, instance: ModelInstanceIndex, control: ControlConfig) -> None:
    """Make every actuator of ``instance`` PD-controlled (before ``Finalize``)."""
    groups = {name: control.base for name in BASE_JOINTS[:2]}
    groups[BASE_JOINTS[2]] = control.base_yaw
    groups.update({name: control.arm for name in ARM_JOINTS[:3]})
    groups.update({name: control.wrist for name in WRIST_JOINTS})
    groups.update({name: control.gripper for name in GRIPPER_JOINTS})
    seen = set()
    for i in range(plant.num_actuators()):
        actuator = plant.get_joint_actuator(JointActuatorIndex(i))
        if actuator.model_instance() != instance:
            continue
        gains = groups[actuator.joint().name()]
        actuator.set_controller_gains(PdControllerGains(p=gains.kp, d=gains.kd))
        seen.add(actuator.joint().name())
    if seen != set(groups):
        raise RuntimeError(f"robot actuators missing: {sorted(set(groups) - seen)}")


def actuated_state_selector(plant: MultibodyPlant, instance: ModelInstanceIndex) -> np.ndarray:
    """The (2 nu) x (nq + nv) matrix taking the robot's state (``robot.state``) to ``robot.desired_state``."""
    nq = plant.num_positions(instance)
    nv = plant.num_velocities(instance)
    q_local = {
        int(g): i
        for i, g in enumerate(plant.GetPositionsFromArray(instance, np.arange(plant.num_positions())))
    }
    v_local = {
        int(g): i
        for i, g in enumerate(plant.GetVelocitiesFromArray(instance, np.arange(plant.num_velocities())))
    }
    actuators = [
        plant.get_joint_actuator(JointActuatorIndex(i))
        for i in range(plant.num_actuators())
        if plant.get_joint_actuator(JointActuatorIndex(i)).model_instance() == instance
    ]
    nu = len(actuators)
    selector = np.zeros((2 * nu, nq + nv))
    for row, actuator in enumerate(actuators):
        joint = actuator.joint()
        selector[row, q_local[joint.position_start()]] = 1.0
        selector[nu + row, nq + v_local[joint.velocity_start()]] = 1.0
    return selector


def desired_state_from_robot_state(
    plant: MultibodyPlant, instance: ModelInstanceIndex, q: np.ndarray, v: np.ndarray | None = None
) -> np.ndarray:
    """The ``robot.desired_state`` vector holding the robot at positions ``q`` (11) with velocities ``v``."""
    q = np.asarray(q, dtype=float)
    v = np.zeros(plant.num_velocities(instance)) if v is None else np.asarray(v, dtype=float)
    return actuated_state_selector(plant, instance) @ np.concatenate([q, v])


def _add_gravity_compensation(
    builder: DiagramBuilder, plant: MultibodyPlant, instance: ModelInstanceIndex
) -> None:
    """Feed the robot's gravity torques forward into its actuation input (``plant`` finalized).

    ``InverseDynamics`` in gravity-compensation mode evaluates the world plant itself (it lives in the
    same diagram, so no second model has to be kept alive); the rows of the robot's actuated joints
    are picked out of the generalized forces by ``B^T``.
    """
    gravity = builder.AddNamedSystem(
        "gravity_compensation",
        InverseDynamics(plant, InverseDynamics.InverseDynamicsMode.kGravityCompensation),
    )
    B = plant.MakeActuationMatrix()  # nv x nu; a selection for simple joint actuators
    columns = [
        i
        for i in range(plant.num_actuators())
        if plant.get_joint_actuator(JointActuatorIndex(i)).model_instance() == instance
    ]
    to_actuators = builder.AddNamedSystem("gravity_to_actuators", MatrixGain(B[:, columns].T))
    builder.Connect(plant.get_state_output_port(), gravity.get_input_port_estimated_state())
    builder.Connect(gravity.get_output_port_generalized_force(), to_actuators.get_input_port())
    builder.Connect(to_actuators.get_output_port(), plant.get_actuation_input_port(instance))


def make_world_diagram(
    scene: Scene,
    config: WorldConfig | None = None,
    *,
    meshcat: Meshcat | None = None,
    welded_objects: Iterable[str] = (),
) -> Diagram:
    """Build the world for ``scene``: see the module's docstring for the ports.

    Args:
        scene: the table, start, target and obstacles.
        config: plant, contact, model and control settings (``WorldConfig()`` by default).
        meshcat: if given, illustration geometry and contact forces are drawn there.
        welded_objects: names of scene objects welded to the world at their scene poses instead of
            free (a reduced model: they neither move nor join the contact problem with the table);
            ``state`` then holds only the free objects' states.
    """
    config = WorldConfig() if config is None else config
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlant(config.plant, builder)
    instance = add_robot(plant)
    _set_robot_contact(plant, scene_graph, instance, config)
    _set_pd_gains(plant, instance, config.control)
    add_scene(plant, scene, config, welded_objects=welded_objects)
    plant.Finalize()
    plant.SetDefaultPositions(instance, start_configuration(scene, plant, instance, config=config))

    if config.control.gravity_compensation:
        _add_gravity_compensation(builder, plant, instance)
    builder.ExportInput(plant.get_desired_state_input_port(instance), DESIRED_STATE_PORT)
    builder.ExportOutput(plant.get_state_output_port(instance), "robot.state")
    builder.ExportOutput(plant.get_state_output_port(), "state")
    builder.ExportOutput(plant.get_body_poses_output_port(), "body_poses")
    builder.ExportOutput(plant.get_contact_results_output_port(), "contact_results")
    builder.ExportOutput(scene_graph.get_query_output_port(), "query_object")
    if meshcat is not None:
        MeshcatVisualizer.AddToBuilder(
            builder, scene_graph, meshcat, MeshcatVisualizerParams(role=Role.kIllustration)
        )
        ContactVisualizer.AddToBuilder(builder, plant, meshcat, ContactVisualizerParams())
    diagram = builder.Build()
    diagram.set_name("world")
    return diagram


def world_plant(diagram: Diagram) -> tuple[MultibodyPlant, ModelInstanceIndex]:
    """The world diagram's plant and the robot's model instance."""
    plant = diagram.GetSubsystemByName("plant")
    return plant, plant.GetModelInstanceByName(ROBOT_MODEL_NAME)


def add_position_trajectory(
    builder: DiagramBuilder, world: Diagram, trajectory: Trajectory, *, name: str = "robot_trajectory"
) -> TrajectorySource:
    """Drive ``world``'s ``robot.desired_state`` from a trajectory of the robot's 11 positions.

    ``world`` must already be in ``builder``. Adds a C++ ``TrajectorySource`` (positions and their
    derivative) and a selection gain; swap trajectories per rollout with ``UpdateTrajectory``.
    Returns the source.
    """
    plant, instance = world_plant(world)
    source = builder.AddNamedSystem(name, TrajectorySource(trajectory, output_derivative_order=1))
    select = builder.AddNamedSystem(
        f"{name}_to_desired_state", MatrixGain(actuated_state_selector(plant, instance))
    )
    builder.Connect(source.get_output_port(), select.get_input_port())
    builder.Connect(select.get_output_port(), world.GetInputPort(DESIRED_STATE_PORT))
    return source


def start_meshcat(config: WorldConfig) -> Meshcat | None:
    """A MeshCat server on localhost when ``config.meshcat`` is on, else None."""
    return Meshcat(MeshcatParams(host="localhost")) if config.meshcat else None


# --- Planning model -----------------------------------------------------------------------------------


class PlanningModel:
    """Robot + table + objects welded at their scene poses, for kinematics (IK, distance queries).

    A continuous plant (no dynamics) with its SceneGraph in a Diagram, and one context, created here.

    Attributes:
        diagram, plant, scene_graph: the model.
        robot: the robot's model instance.
        scene_models: the table's and objects' model instances.
        context, plant_context: the model's own context and the plant's part of it.
    """

    def __init__(self, scene: Scene, config: WorldConfig | None = None) -> None:
        config = WorldConfig() if config is None else config
        builder = DiagramBuilder()
        plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
        self.robot = add_robot(plant)
        self.scene_models: SceneModels = add_scene(plant, scene, config, weld_objects=True)
        plant.Finalize()
        self.diagram = builder.Build()
        self.diagram.set_name("planning_model")
        self.plant: MultibodyPlant = plant
        self.scene_graph: SceneGraph = scene_graph
        self.context = self.diagram.CreateDefaultContext()
        self.plant_context = plant.GetMyMutableContextFromRoot(self.context)

    def robot_geometries(self) -> list:
        return [
            geometry
            for body in self.plant.GetBodyIndices(self.robot)
            for geometry in self.plant.GetCollisionGeometriesForBody(self.plant.get_body(body))
        ]

    def object_geometries(self) -> list:
        return [
            geometry
            for instance in self.scene_models.objects.values()
            for body in self.plant.GetBodyIndices(instance)
            for geometry in self.plant.GetCollisionGeometriesForBody(self.plant.get_body(body))
        ]


__all__ = [
    "DESIRED_STATE_PORT",
    "PlanningModel",
    "actuated_state_selector",
    "add_position_trajectory",
    "desired_state_from_robot_state",
    "make_world_diagram",
    "robot_base_pose",
    "robot_position_names",
    "start_configuration",
    "start_meshcat",
    "tcp_keypoint_height",
    "tcp_rotation",
    "world_plant",
]
