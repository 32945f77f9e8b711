"""The simulated world: config loading, scene models, the world diagram, resting and pushed objects."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from pydrake.geometry import SceneGraph
from pydrake.math import RigidTransform
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.trajectories import PiecewisePolynomial

from hlp_drake.errors import HlpError
from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.model import Scene, SceneObject, Table
from hlp_drake.systems.robot import ACTUATED_JOINTS, BASE_FOOTPRINT, TCP_FRAME
from hlp_drake.systems.scene_models import (
    add_scene,
    fallen_objects,
    object_body,
    object_mass,
    object_planar_poses,
    object_poses,
    scene_from_plant,
    set_object_poses,
    tilted_objects,
)
from hlp_drake.systems.world import (
    DESIRED_STATE_PORT,
    PlanningModel,
    add_position_trajectory,
    desired_state_from_robot_state,
    make_world_diagram,
    robot_base_pose,
    robot_position_names,
    start_configuration,
    world_plant,
)
from hlp_drake.systems.world_config import WorldConfig, dump_world_config, load_world_config

KINDS = ("vr", "gen1", "gen2")
OUTPUTS = {"robot.state", "state", "body_poses", "contact_results", "query_object"}


@pytest.fixture(scope="module")
def scenes() -> dict[str, Scene]:
    return {
        "vr": generate_scene("vr", 0),
        "gen1": generate_scene("gen1", 1),
        "gen2": generate_scene("gen2", 2),
    }


@pytest.fixture(scope="module")
def worlds(scenes):
    return {kind: make_world_diagram(scene) for kind, scene in scenes.items()}


def resting_z(scene: Scene) -> dict[str, float]:
    return {obj.name: scene.table.height + obj.height / 2.0 for obj in scene.objects}


# --- Config -------------------------------------------------------------------------------------


def test_default_config_uses_sap_point_contact_and_stiff_materials():
    config = load_world_config()
    assert config.plant.time_step == pytest.approx(0.002)
    assert config.plant.discrete_contact_approximation == "sap"
    assert config.plant.contact_model == "point"
    assert config.contact.stiffness >= 1e6 and config.contact.corner_sphere_radius > 0
    assert config.control.gravity_compensation
    assert 0.1 <= config.scene.object_min_mass < config.scene.object_max_mass <= 0.5


def test_config_loads_from_yaml_and_overrides(tmp_path):
    path = tmp_path / "world.yaml"
    path.write_text(
        "plant:\n  time_step: 0.005\ncontrol:\n  arm: {kp: 3000.0, kd: 200.0}\nmotion:\n  tcp_speed: 0.2\n"
    )
    config = load_world_config(path, overrides="motion: {tcp_speed: 0.15}\nmeshcat: true\n")
    assert config.plant.time_step == 0.005
    assert config.plant.discrete_contact_approximation == "sap"  # untouched defaults stay
    assert (config.control.arm.kp, config.control.arm.kd) == (3000.0, 200.0)
    assert config.control.wrist == WorldConfig().control.wrist
    assert config.motion.tcp_speed == 0.15 and config.meshcat
    assert dump_world_config(load_world_config(overrides=dump_world_config(config))) == dump_world_config(
        config
    )
    (tmp_path / "empty.yaml").write_text("# nothing to change\n")
    assert dump_world_config(load_world_config(tmp_path / "empty.yaml")) == dump_world_config(WorldConfig())


@pytest.mark.parametrize(
    "text, problem",
    [
        ("plant: [0.002,\n", "invalid YAML"),
        ("plant: {time_stp: 0.002}\n", "time_stp"),
        ("control: {arm: {kp: fast}}\n", "fast"),
        ("ik: 3\n", "structure"),
        ("plant: {discrete_contact_approximation: tamsi}\n", "SAP"),
        ("plant: {time_step: 0.0}\n", "time_step"),
        ("scene: {object_min_mass: 1.0, object_max_mass: 0.5}\n", "object_max_mass"),
        ("sto: {update: annealing}\n", "sto.update"),
        ("sto: {samples: 0}\n", "sto.samples"),
        ("sto: {noise: {end_fraction: 1.5}}\n", "sto.noise.end_fraction"),
        ("sto: {weld_clearance: 0.0}\n", "sto.weld_clearance"),
        ("sto: {weld_margin: 0.5}\n", "sto.weld_margin"),
        ("grasp: {lift_s: 0.0}\n", "grasp.lift_s"),
    ],
)
def test_bad_config_file_raises_a_one_line_hlp_error_naming_the_file(tmp_path, text, problem):
    path = tmp_path / "bad_world.yaml"
    path.write_text(text)
    with pytest.raises(HlpError) as info:
        load_world_config(path)
    message = str(info.value)
    assert "bad_world.yaml" in message and problem in message
    assert "\n" not in message
    with pytest.raises(HlpError, match=r"missing\.yaml"):
        load_world_config(tmp_path / "missing.yaml")


# --- Scene models -------------------------------------------------------------------------------


def test_scene_objects_are_free_bodies_named_after_the_scene(scenes):
    scene = scenes["gen2"]
    plant = MultibodyPlant(time_step=0.002)
    scene_graph = SceneGraph()
    plant.RegisterAsSourceForSceneGraph(scene_graph)
    models = add_scene(plant, scene)
    plant.Finalize()
    assert models.names == tuple(obj.name for obj in scene.objects)
    assert plant.num_positions() == 7 * len(scene.objects)  # free bodies only; the table is welded
    config = WorldConfig()
    for obj in scene.objects:
        body = object_body(plant, obj.name)
        assert body.is_floating_base_body() if hasattr(body, "is_floating_base_body") else body.is_floating()
        assert body.default_mass() == pytest.approx(object_mass(obj, config.scene))
        assert config.scene.object_min_mass <= body.default_mass() <= config.scene.object_max_mass
    context = plant.CreateDefaultContext()
    poses = object_planar_poses(plant, context, scene)
    for obj in scene.objects:
        np.testing.assert_allclose(poses[obj.name], (obj.x, obj.y, obj.yaw), atol=1e-12)
    assert fallen_objects(plant, context, scene) == [] and tilted_objects(plant, context, scene) == []
    with pytest.raises(ValueError, match="finalized"):
        add_scene(plant, scene)


def test_object_names_must_be_unique_in_the_plant(scenes):
    plant = MultibodyPlant(time_step=0.0)
    plant.AddModelInstance(scenes["vr"].target.name)
    with pytest.raises(ValueError, match=scenes["vr"].target.name):
        add_scene(plant, scenes["vr"])


def test_fallen_objects_and_scene_readback(worlds, scenes):
    scene = scenes["vr"]
    plant, _ = world_plant(worlds["vr"])
    context = plant.CreateDefaultContext()
    first, second, third = (obj.name for obj in scene.obstacles[:3])
    plant.SetFreeBodyPose(
        context, object_body(plant, first), RigidTransform([-0.2, 0.0, 0.9])
    )  # off the front
    plant.SetFreeBodyPose(
        context, object_body(plant, second), RigidTransform([0.3, 0.0, 0.5])
    )  # below the top
    plant.SetFreeBodyPose(
        context, object_body(plant, third), RigidTransform([0.31, 0.05, 0.8])
    )  # moved, on top
    assert fallen_objects(plant, context, scene) == [first, second]
    moved = scene_from_plant(plant, context, scene)
    assert moved.obstacle(third).position == pytest.approx((0.31, 0.05))
    assert moved.target == scene.target
    set_object_poses(plant, context, scene)
    assert fallen_objects(plant, context, scene) == []


def test_chosen_objects_can_be_welded(scenes):
    scene = scenes["gen2"]
    welded = {scene.obstacles[0].name, scene.obstacles[2].name}
    plant = MultibodyPlant(time_step=0.002)
    scene_graph = SceneGraph()
    plant.RegisterAsSourceForSceneGraph(scene_graph)
    models = add_scene(plant, scene, welded_objects=welded)
    plant.Finalize()
    assert models.welded_objects == welded and not models.welded
    assert plant.num_positions() == 7 * (len(scene.objects) - len(welded))
    context = plant.CreateDefaultContext()
    for obj in scene.objects:
        body = object_body(plant, obj.name)
        assert body.is_floating_base_body() != (obj.name in welded)
        spheres = len(plant.GetCollisionGeometriesForBody(body)) - 1
        assert (spheres == 0) == (obj.name in welded)  # welded objects need no support spheres
    poses = object_planar_poses(plant, context, scene)
    for obj in scene.objects:
        np.testing.assert_allclose(poses[obj.name], (obj.x, obj.y, obj.yaw), atol=1e-12)
    world = make_world_diagram(scene, welded_objects=welded)
    assert world_plant(world)[0].num_positions() == 11 + 7 * (len(scene.objects) - len(welded))
    with pytest.raises(ValueError, match="Nowhere"):
        add_scene(MultibodyPlant(time_step=0.0), scene, welded_objects=["Nowhere"])


def test_planning_model_welds_the_objects(scenes):
    model = PlanningModel(scenes["gen1"])
    assert model.plant.num_positions() == 11
    assert len(model.object_geometries()) > len(scenes["gen1"].objects)  # boxes + corner spheres
    assert model.plant.time_step() == 0.0


# --- World diagram ------------------------------------------------------------------------------


@pytest.mark.parametrize("kind", KINDS)
def test_world_diagram_builds_with_named_ports(worlds, scenes, kind):
    world, scene = worlds[kind], scenes[kind]
    assert world.get_name() == "world"
    plant, robot = world_plant(world)
    assert world.GetSubsystemByName("plant") is plant
    assert plant.num_actuators() == 10 == len(ACTUATED_JOINTS)
    assert plant.num_positions(robot) == 11
    starts = [plant.GetJointByName(name, robot).position_start() for name in robot_position_names()]
    assert starts == list(range(starts[0], starts[0] + 11))  # the documented order of the 11 positions
    assert [world.get_input_port(i).get_name() for i in range(world.num_input_ports())] == [
        DESIRED_STATE_PORT
    ]
    assert world.GetInputPort(DESIRED_STATE_PORT).size() == 20
    assert {world.get_output_port(i).get_name() for i in range(world.num_output_ports())} == OUTPUTS
    assert world.GetOutputPort("robot.state").size() == 22
    context = world.CreateDefaultContext()
    plant_context = plant.GetMyContextFromRoot(context)
    np.testing.assert_allclose(
        plant.GetPositions(plant_context, robot), start_configuration(scene, plant, robot), atol=1e-12
    )
    poses = object_planar_poses(plant, plant_context, scene)
    for obj in scene.objects:
        np.testing.assert_allclose(poses[obj.name], (obj.x, obj.y, obj.yaw), atol=1e-12)
    assert len(world.GetOutputPort("body_poses").Eval(context)) == plant.num_bodies()
    world.GetOutputPort("query_object").Eval(context)
    world.GetOutputPort("contact_results").Eval(context)


@pytest.mark.parametrize("kind", KINDS)
def test_robot_starts_in_front_of_the_table_with_the_tcp_above_the_start(worlds, scenes, kind):
    world, scene = worlds[kind], scenes[kind]
    config = WorldConfig()
    x, y, yaw = robot_base_pose(scene)
    assert x + BASE_FOOTPRINT[0] / 2.0 <= -config.ik.start_base_clearance + 1e-12  # front edge off the table
    assert yaw == 0.0 and y == scene.start[1]
    plant, robot = world_plant(world)
    context = plant.CreateDefaultContext()
    X_tcp = plant.GetFrameByName(TCP_FRAME, robot).CalcPoseInWorld(context)
    np.testing.assert_allclose(X_tcp.translation()[:2], scene.start, atol=2e-3)
    assert X_tcp.translation()[2] == pytest.approx(scene.table.height + config.ik.height, abs=2e-3)
    R = X_tcp.rotation().matrix()
    np.testing.assert_allclose(R[:, 2], [1.0, 0.0, 0.0], atol=1e-2)  # approach along +x
    assert abs(R[2, 1]) < 1e-2  # fingers open horizontally


def _simulate_holding_start(world, duration: float):
    plant, robot = world_plant(world)
    simulator = Simulator(world)
    context = simulator.get_mutable_context()
    plant_context = plant.GetMyContextFromRoot(context)
    q0 = plant.GetPositions(plant_context, robot)
    world.GetInputPort(DESIRED_STATE_PORT).FixValue(context, desired_state_from_robot_state(plant, robot, q0))
    simulator.AdvanceTo(duration)
    return plant, robot, plant_context, q0


@pytest.mark.parametrize("kind", KINDS)
def test_holding_the_start_leaves_every_object_resting(worlds, scenes, kind):
    world, scene = worlds[kind], scenes[kind]
    plant, robot, plant_context, q0 = _simulate_holding_start(world, 1.0)
    z = {name: X.translation()[2] for name, X in object_poses(plant, plant_context, resting_z(scene)).items()}
    for name, z0 in resting_z(scene).items():
        assert z0 - z[name] < 2e-3, f"{name} sank {1000 * (z0 - z[name]):.2f} mm"
    poses = object_planar_poses(plant, plant_context, scene)
    for obj in scene.objects:
        assert math.hypot(poses[obj.name][0] - obj.x, poses[obj.name][1] - obj.y) < 1e-3, obj.name
        assert abs(poses[obj.name][2] - obj.yaw) < 1e-2, obj.name
    assert fallen_objects(plant, plant_context, scene) == []
    assert np.max(np.abs(plant.GetPositions(plant_context, robot) - q0)) < 2e-3  # the PD + gravity hold


def push_scene() -> Scene:
    return Scene(
        table=Table(length=0.8, width=1.0, height=0.75),
        start=(0.1, 0.0),
        target=SceneObject("target", "cylinder", 0.65, 0.30, (0.06, 0.06, 0.12)),
        obstacles=(
            SceneObject("wide_box", "box", 0.30, 0.0, (0.06, 0.15, 0.12)),
            SceneObject("side_box", "box", 0.30, -0.35, (0.06, 0.10, 0.12), 0.3),
        ),
        name="push",
    )


def test_a_box_pushed_by_the_gripper_slides_and_stays_on_the_table():
    scene = push_scene()
    world = make_world_diagram(scene)
    builder = DiagramBuilder()
    builder.AddSystem(world)
    plant, robot = world_plant(world)
    q0 = plant.GetPositions(plant.CreateDefaultContext(), robot)
    q1 = q0.copy()
    q1[0] += 0.30  # the base drives 0.3 m forward, carrying the tcp through the box's place
    trajectory = PiecewisePolynomial.FirstOrderHold([0.0, 0.25, 3.25, 3.5], np.column_stack([q0, q0, q1, q1]))
    add_position_trajectory(builder, world, trajectory)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    simulator.AdvanceTo(3.5)
    plant_context = plant.GetMyContextFromRoot(simulator.get_context())
    tcp = plant.GetFrameByName(TCP_FRAME, robot).CalcPoseInWorld(plant_context).translation()
    assert tcp[0] == pytest.approx(scene.start[0] + 0.30, abs=5e-3)
    poses = object_planar_poses(plant, plant_context, scene)
    box = scene.obstacle("wide_box")
    dx, dy = poses["wide_box"][0] - box.x, poses["wide_box"][1] - box.y
    assert 0.10 < dx < 0.30 and abs(dy) < 0.02  # pushed ahead of the gripper
    assert poses["wide_box"][0] - box.size[0] / 2.0 >= tcp[0] - 0.005  # stayed in front: no tunnelling
    box_z = object_poses(plant, plant_context, ["wide_box"])["wide_box"].translation()[2]
    assert abs(box_z - resting_z(scene)["wide_box"]) < 2e-3
    assert (
        fallen_objects(plant, plant_context, scene) == []
        and tilted_objects(plant, plant_context, scene) == []
    )
    for name in ("target", "side_box"):
        obj = scene.target if name == "target" else scene.obstacle(name)
        assert math.hypot(poses[name][0] - obj.x, poses[name][1] - obj.y) < 1e-3


def test_world_with_a_yaml_config_and_without_gravity_compensation(tmp_path):
    path = tmp_path / "coarse.yaml"
    path.write_text("plant: {time_step: 0.005}\ncontrol: {gravity_compensation: false}\n")
    config = load_world_config(path)
    scene = replace(push_scene(), obstacles=())
    world = make_world_diagram(scene, config)
    plant, _ = world_plant(world)
    assert plant.time_step() == 0.005
    names = {system.get_name() for system in world.GetSystems()}
    assert "gravity_compensation" not in names
    assert "gravity_compensation" in {s.get_name() for s in make_world_diagram(scene).GetSystems()}


def test_meshcat_visualisation_is_optional(monkeypatch):
    from pydrake.geometry import Meshcat, MeshcatParams

    monkeypatch.setenv("DRAKE_ALLOW_NETWORK", "meshcat")  # a local server only; still no remote packages
    try:
        meshcat = Meshcat(MeshcatParams(host="localhost"))
    except RuntimeError as error:  # no free port in a sandbox
        pytest.skip(f"MeshCat cannot start here: {error}")
    scene = replace(push_scene(), obstacles=())
    world = make_world_diagram(scene, meshcat=meshcat)
    simulator = Simulator(world)
    simulator.AdvanceTo(0.05)
    assert meshcat.HasPath("/drake/visualizer")
