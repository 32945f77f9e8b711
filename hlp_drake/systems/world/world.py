"""The simulated world: the scenario's robot, a scene's table and free objects, and the robot's PD control.

``world_diagram(scene, model)`` (a scene in a ``WorldModel``) returns a Diagram named ``world`` with
these exported ports (``make_world_diagram(scenario)``: the scenario's scene and world model):

Input:
    ``robot.desired_state``: desired positions then velocities of the robot's actuated joints in
        actuator order (``RobotDescription.actuated_joints``: a mobile base's x, y, yaw, the arm, the
        actuated finger; 20 for the mobile UR5), fed to the plant's PD-controlled actuators. Left
        unconnected, the controllers are disarmed (only gravity compensation acts).
        ``desired_state_from_robot_state`` / ``add_position_trajectory`` map the robot's positions
        (with the mimic fingers) onto it.

Outputs:
    ``robot.state``: the robot's positions then velocities (``RobotDescription.position_names``; 22
        for the mobile UR5).
    ``state``: the whole plant's state (robot and free objects).
    ``body_poses``: ``list[RigidTransform]`` of every body's world pose, by body index.
    ``contact_results``: the plant's ``ContactResults``.
    ``query_object``: SceneGraph's ``QueryObject`` (distance and collision queries).

The plant is the subsystem ``plant`` (``world.GetSubsystemByName("plant")``) and the SceneGraph
``scene_graph``; the robot is the model instance ``model.robot.name``. The default context has the
robot in ``start_configuration`` (``hlp_drake.systems.world.start_pose``) and every object at rest on the
table at its scene pose.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING

import numpy as np
from pydrake.geometry import (
    CollisionFilterDeclaration,
    GeometrySet,
    Meshcat,
    MeshcatVisualizer,
    MeshcatVisualizerParams,
    ProximityProperties,
    Role,
    RoleAssign,
    SceneGraph,
)
from pydrake.multibody.meshcat import ContactVisualizer, ContactVisualizerParams
from pydrake.multibody.plant import AddMultibodyPlant, CoulombFriction, MultibodyPlant
from pydrake.multibody.tree import JointActuatorIndex, ModelInstanceIndex, PdControllerGains
from pydrake.systems.controllers import InverseDynamics
from pydrake.systems.framework import Diagram, DiagramBuilder, OutputPort
from pydrake.systems.primitives import MatrixGain, TrajectorySource
from pydrake.trajectories import Trajectory

from hlp_drake.systems.perception.cameras import add_cameras, label_classes
from hlp_drake.systems.world.model import WorldModel
from hlp_drake.systems.world.robot import add_robot
from hlp_drake.systems.world.robot_description import RobotDescription
from hlp_drake.systems.world.scene_models import ContactConfig, add_scene
from hlp_drake.systems.world.start_pose import robot_position_names, start_configuration
from hlp_drake.systems.world.world_config import DESIRED_STATE_PORT, WRIST_JOINTS, ControlConfig

if TYPE_CHECKING:
    from hlp_drake.scene.model import Scene
    from hlp_drake.systems.perception.cameras import CameraConfig
    from hlp_drake.systems.scenario import Scenario
    from hlp_drake.systems.world.uncertainty import WorldPerturbation


def _set_robot_contact(
    plant: MultibodyPlant,
    scene_graph: SceneGraph,
    instance: ModelInstanceIndex,
    contact: ContactConfig,
    robot: RobotDescription,
) -> None:
    """Give every robot collision geometry the configured stiffness and dissipation, and the gripper
    its friction (the other links keep the model's friction)."""
    inspector = scene_graph.model_inspector()
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
            if body.name() in robot.gripper_links:
                material["coulomb_friction"] = CoulombFriction(
                    contact.gripper_friction, contact.gripper_friction
                )
            for name, value in material.items():
                if properties.HasProperty("material", name):
                    properties.UpdateProperty("material", name, value)
                else:
                    properties.AddProperty("material", name, value)
            scene_graph.AssignRole(plant.get_source_id(), geometry, properties, RoleAssign.kReplace)


def _filter_robot_self_contact(
    plant: MultibodyPlant, scene_graph: SceneGraph, instance: ModelInstanceIndex
) -> None:
    """Exclude every contact pair between two of the robot's links (``ContactConfig.robot_self_contact`` off)."""
    geometries = [
        g
        for i in plant.GetBodyIndices(instance)
        for g in plant.GetCollisionGeometriesForBody(plant.get_body(i))
    ]
    scene_graph.collision_filter_manager().Apply(
        CollisionFilterDeclaration().ExcludeWithin(GeometrySet(geometries))
    )


def _set_pd_gains(
    plant: MultibodyPlant, instance: ModelInstanceIndex, control: ControlConfig, robot: RobotDescription
) -> None:
    """Make every actuator of ``instance`` PD-controlled (before ``Finalize``)."""
    base, arm = robot.base_joints, robot.arm_joints
    groups = {name: control.base for name in base[:2]}
    groups.update({name: control.base_yaw for name in base[2:]})
    groups.update({name: control.arm for name in arm[:-WRIST_JOINTS]})
    groups.update({name: control.wrist for name in arm[-WRIST_JOINTS:]})
    groups[robot.gripper_joint] = control.gripper
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
    """The ``robot.desired_state`` vector holding the robot at positions ``q`` with velocities ``v``."""
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
    scenario: Scenario,
    *,
    meshcat: Meshcat | None = None,
    contact_forces: bool = False,
    welded_objects: Iterable[str] = (),
    cameras: bool | None = None,
    model_error: WorldPerturbation | None = None,
) -> Diagram:
    """The world of ``scenario``: ``world_diagram`` of its scene in what the robot acts in
    (``executed_model``: the ``world`` section's physics over the planner's model).

    Args:
        cameras: add the scenario's cameras (``perception.cameras``; their ports: see
            ``hlp_drake.systems.perception.cameras``); None (the default): when the scenario
            perceives the scene through them (``perception.source: camera``).
        meshcat, contact_forces, welded_objects, model_error: as ``world_diagram``'s.
    """
    watching = cameras or (cameras is None and scenario.perception.source == "camera")
    return world_diagram(
        scenario.scene,
        scenario.executed_model,
        cameras=scenario.perception.cameras if watching else (),
        meshcat=meshcat,
        contact_forces=contact_forces,
        welded_objects=welded_objects,
        model_error=model_error,
    )


def world_diagram(
    scene: Scene,
    model: WorldModel | None = None,
    *,
    cameras: tuple[CameraConfig, ...] = (),
    meshcat: Meshcat | None = None,
    contact_forces: bool = False,
    welded_objects: Iterable[str] = (),
    model_error: WorldPerturbation | None = None,
) -> Diagram:
    """Build the world of ``scene`` in ``model`` (its robot, plant, contact, bodies, controller and
    start pose; default ``WorldModel()``): see the module's docstring for the ports.

    Args:
        cameras: RGB-D cameras fixed in the world (their ports: see
            ``hlp_drake.systems.perception.cameras``), rendered only when their images are
            evaluated. Even unrendered, a camera costs ~10 % of the simulation's time (the render
            engine follows every pose).
        meshcat: if given, the illustration geometry is drawn there ...
        contact_forces: ... and, if this is set, the contact forces (1 cm per 5 N).
        welded_objects: names of scene objects welded to the world at their scene poses instead of
            free (a reduced model: they neither move nor join the contact problem with the table);
            ``state`` then holds only the free objects' states.
        model_error: the world differs from ``scene`` so (``sample_perturbation``): its objects
            stand where ``model_error.true_scene`` has them, with its mass and friction factors.
    """
    model = model or WorldModel()
    scene = scene if model_error is None else model_error.true_scene(scene)
    scales = None if model_error is None else model_error.scales()
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlant(model.plant, builder)
    instance = add_robot(plant, model.robot)
    _set_robot_contact(plant, scene_graph, instance, model.contact, model.robot)
    _set_pd_gains(plant, instance, model.controller, model.robot)
    models = add_scene(
        plant, scene, contact=model.contact, bodies=model.bodies, welded_objects=welded_objects, scales=scales
    )
    plant.Finalize()
    if not model.contact.robot_self_contact:
        _filter_robot_self_contact(plant, scene_graph, instance)
    if cameras:
        label_classes(plant, scene_graph, instance, models, scene)
        add_cameras(builder, scene_graph, cameras, scene)
    plant.SetDefaultPositions(instance, start_configuration(scene, model.ik, plant, instance, model.robot))
    if model.controller.gravity_compensation:
        _add_gravity_compensation(builder, plant, instance)
    _export_ports(builder, plant, scene_graph, instance)
    if meshcat is not None:
        MeshcatVisualizer.AddToBuilder(
            builder, scene_graph, meshcat, MeshcatVisualizerParams(role=Role.kIllustration)
        )
        if contact_forces:
            ContactVisualizer.AddToBuilder(
                builder, plant, meshcat, ContactVisualizerParams(newtons_per_meter=500.0, radius=0.002)
            )
    diagram = builder.Build()
    diagram.set_name("world")
    return diagram


def _export_ports(
    builder: DiagramBuilder, plant: MultibodyPlant, scene_graph: SceneGraph, instance: ModelInstanceIndex
) -> None:
    """Export the world's ports (see the module's docstring)."""
    builder.ExportInput(plant.get_desired_state_input_port(instance), DESIRED_STATE_PORT)
    builder.ExportOutput(plant.get_state_output_port(instance), "robot.state")
    builder.ExportOutput(plant.get_state_output_port(), "state")
    builder.ExportOutput(plant.get_body_poses_output_port(), "body_poses")
    builder.ExportOutput(plant.get_contact_results_output_port(), "contact_results")
    builder.ExportOutput(scene_graph.get_query_output_port(), "query_object")


def world_plant(diagram: Diagram) -> tuple[MultibodyPlant, ModelInstanceIndex]:
    """The world diagram's plant and the robot's model instance (the first with actuators)."""
    plant = diagram.GetSubsystemByName("plant")
    return plant, robot_instance(plant)


def robot_instance(plant: MultibodyPlant) -> ModelInstanceIndex:
    """The robot's model instance in a world's plant: the one model with actuators."""
    return plant.get_joint_actuator(JointActuatorIndex(0)).model_instance()


def connect_robot_command(builder: DiagramBuilder, world: Diagram, port: OutputPort, *, name: str) -> None:
    """Drive ``world``'s ``robot.desired_state`` from ``port``: the robot's positions then their
    velocities (e.g. a ``TrajectorySource``'s with its derivative), through a selection gain
    named ``{name}_to_desired_state``. ``world`` must already be in ``builder``."""
    plant, instance = world_plant(world)
    select = builder.AddNamedSystem(
        f"{name}_to_desired_state", MatrixGain(actuated_state_selector(plant, instance))
    )
    builder.Connect(port, select.get_input_port())
    builder.Connect(select.get_output_port(), world.GetInputPort(DESIRED_STATE_PORT))


def add_position_trajectory(
    builder: DiagramBuilder, world: Diagram, trajectory: Trajectory, *, name: str = "robot_trajectory"
) -> TrajectorySource:
    """Drive ``world``'s ``robot.desired_state`` from a trajectory of the robot's positions.

    ``world`` must already be in ``builder``. Adds a C++ ``TrajectorySource`` (positions and their
    derivative; ``connect_robot_command``); swap trajectories per rollout with ``UpdateTrajectory``.
    Returns the source.
    """
    source = builder.AddNamedSystem(name, TrajectorySource(trajectory, output_derivative_order=1))
    connect_robot_command(builder, world, source.get_output_port(), name=name)
    return source


__all__ = [
    "DESIRED_STATE_PORT",
    "actuated_state_selector",
    "add_position_trajectory",
    "connect_robot_command",
    "desired_state_from_robot_state",
    "make_world_diagram",
    "robot_instance",
    "robot_position_names",
    "world_diagram",
    "world_plant",
]
