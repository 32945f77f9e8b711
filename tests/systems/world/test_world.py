"""The simulated world: scene models, the world diagram (a scene in a ``WorldModel``), resting and
pushed objects."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from pydrake.geometry import SceneGraph
from pydrake.math import RigidTransform
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import BodyIndex
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.trajectories import PiecewisePolynomial

from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.model import Scene, SceneObject, Table, plan_view_order
from hlp_drake.systems.planning.keyframes import PlanningModel
from hlp_drake.systems.scenario import Scenario, load_scenario
from hlp_drake.systems.world.robot_description import MOBILE_UR5
from hlp_drake.systems.world.scene_models import (
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
from hlp_drake.systems.world.start_pose import robot_base_pose, robot_position_names, start_configuration
from hlp_drake.systems.world.world import (
    DESIRED_STATE_PORT,
    add_position_trajectory,
    desired_state_from_robot_state,
    make_world_diagram,
    world_plant,
)

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
    return {kind: make_world_diagram(Scenario(scene=scene)) for kind, scene in scenes.items()}


def resting_z(scene: Scene) -> dict[str, float]:
    return {obj.name: scene.table.height + obj.height / 2.0 for obj in scene.objects}


# --- Scene models -------------------------------------------------------------------------------


def test_scene_objects_are_free_bodies_named_after_the_scene(scenes):
    scene = scenes["gen2"]
    plant = MultibodyPlant(time_step=0.002)
    scene_graph = SceneGraph()
    plant.RegisterAsSourceForSceneGraph(scene_graph)
    models = add_scene(plant, scene)
    plant.Finalize()
    assert models.names == (scene.target.name, *(obj.name for obj in plan_view_order(scene.obstacles)))
    assert plant.num_positions() == 7 * len(scene.objects)  # free bodies only; the table is welded
    bodies = Scenario().bodies
    for obj in scene.objects:
        body = object_body(plant, obj.name)
        assert body.is_floating_base_body() if hasattr(body, "is_floating_base_body") else body.is_floating()
        assert body.default_mass() == pytest.approx(object_mass(obj, bodies))
        assert bodies.object_min_mass <= body.default_mass() <= bodies.object_max_mass
    context = plant.CreateDefaultContext()
    poses = object_planar_poses(plant, context, scene)
    for obj in scene.objects:
        np.testing.assert_allclose(poses[obj.name], (obj.x, obj.y, obj.yaw), atol=1e-12)
    assert fallen_objects(plant, context, scene) == [] and tilted_objects(plant, context, scene) == []
    with pytest.raises(ValueError, match="finalized"):
        add_scene(plant, scene)


def _body_names(scene: Scene) -> list[str]:
    plant = MultibodyPlant(time_step=0.002)
    scene_graph = SceneGraph()  # alive while the plant is built
    plant.RegisterAsSourceForSceneGraph(scene_graph)
    add_scene(plant, scene)
    plant.Finalize()
    return [plant.get_body(BodyIndex(index)).name() for index in range(plant.num_bodies())]


def test_the_plant_is_built_in_plan_view_order_whatever_order_the_scene_lists_its_objects():
    # Drake's contact solver visits bodies in index order; a push's outcome flipped with it
    # (gen2-15-14, straight line: success listed as generated, failure listed as a camera names them).
    scene = generate_scene("gen2", 14, 15)
    listed = [obj.name for obj in scene.obstacles]
    in_plan_view = [obj.name for obj in plan_view_order(scene.obstacles)]
    assert listed != in_plan_view  # the generator's order is not the plan-view order here
    reversed_scene = replace(scene, obstacles=tuple(reversed(scene.obstacles)))
    names = _body_names(scene)
    assert names == _body_names(reversed_scene)
    assert [name for name in names if name in listed] == in_plan_view
    xs = [scene.obstacle(name).x for name in in_plan_view]
    assert xs == sorted(xs)


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
    world = make_world_diagram(Scenario(scene=scene), welded_objects=welded)
    assert world_plant(world)[0].num_positions() == 11 + 7 * (len(scene.objects) - len(welded))
    with pytest.raises(ValueError, match="Nowhere"):
        add_scene(MultibodyPlant(time_step=0.0), scene, welded_objects=["Nowhere"])


def test_planning_model_welds_the_objects_or_leaves_them_out(scenes):
    model = PlanningModel(scenes["gen1"])  # alone: the robot, contact and bodies by default
    assert model.plant.num_positions() == 11 and model.plant.time_step() == 0.0
    assert set(model.scene_models.objects) == {o.name for o in scenes["gen1"].objects}
    bare = PlanningModel(scenes["gen1"], robot=MOBILE_UR5, with_objects=False)
    assert bare.plant.num_positions() == 11 and not bare.scene_models.objects


# --- World diagram ------------------------------------------------------------------------------


@pytest.mark.parametrize("kind", KINDS)
def test_world_diagram_builds_with_named_ports(worlds, scenes, kind):
    world, scene = worlds[kind], scenes[kind]
    assert world.get_name() == "world"
    plant, robot = world_plant(world)
    assert world.GetSubsystemByName("plant") is plant
    assert plant.num_actuators() == 10 == len(MOBILE_UR5.actuated_joints)
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
        plant.GetPositions(plant_context, robot),
        start_configuration(scene, Scenario().ik, plant, robot),
        atol=1e-12,
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
    config = Scenario()
    x, y, yaw = robot_base_pose(scene, config.ik)
    assert (
        x + MOBILE_UR5.base.footprint[0] / 2.0 <= -config.ik.start_base_clearance + 1e-12
    )  # front edge off the table
    assert yaw == 0.0 and y == scene.start[1]
    plant, robot = world_plant(world)
    context = plant.CreateDefaultContext()
    X_tcp = plant.GetFrameByName(MOBILE_UR5.tcp_frame, robot).CalcPoseInWorld(context)
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
    world = make_world_diagram(Scenario(scene=scene))
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
    tcp = plant.GetFrameByName(MOBILE_UR5.tcp_frame, robot).CalcPoseInWorld(plant_context).translation()
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
    path.write_text("plant: {time_step: 0.005}\ncontroller: {gravity_compensation: false}\nworld: model\n")
    scene = replace(push_scene(), obstacles=())
    world = make_world_diagram(replace(load_scenario(path), scene=scene))
    plant, _ = world_plant(world)
    assert plant.time_step() == 0.005
    names = {system.get_name() for system in world.GetSystems()}
    assert "gravity_compensation" not in names
    assert "gravity_compensation" in {
        s.get_name() for s in make_world_diagram(Scenario(scene=scene)).GetSystems()
    }


def test_meshcat_visualisation_is_optional(monkeypatch):
    from pydrake.geometry import Meshcat, MeshcatParams

    monkeypatch.setenv("DRAKE_ALLOW_NETWORK", "meshcat")  # a local server only; still no remote packages
    try:
        meshcat = Meshcat(MeshcatParams(host="localhost"))
    except RuntimeError as error:  # no free port in a sandbox
        pytest.skip(f"MeshCat cannot start here: {error}")
    scene = replace(push_scene(), obstacles=())
    world = make_world_diagram(Scenario(scene=scene), meshcat=meshcat, contact_forces=True)
    simulator = Simulator(world)
    simulator.AdvanceTo(0.05)
    assert meshcat.HasPath("/drake/visualizer") and meshcat.HasPath("/drake/contact_forces")
