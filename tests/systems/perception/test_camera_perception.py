"""The world's cameras and ScenePerception on the frames they render: noise, poses, wiring and accuracy."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from perception_support import CAMERA, SCENARIO, SCENE, perceive_rendered
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.sensors import ImageDepth32F

from hlp_drake.scene.model import SceneObject
from hlp_drake.systems.perception.accuracy import perception_record
from hlp_drake.systems.perception.cameras import CameraConfig, DepthNoise, PerceptionConfig, camera_pose
from hlp_drake.systems.perception.system import ScenePerception, add_scene_perception, perceive_world
from hlp_drake.systems.scenario import Scenario, load_scenario
from hlp_drake.systems.world.uncertainty import ObjectPerturbation, WorldPerturbation
from hlp_drake.systems.world.world import make_world_diagram, world_plant


def test_depth_noise_is_seeded_by_the_time_and_drops_the_asked_share():
    camera = CameraConfig(width=160, height=120, depth_noise=0.002, dropout=0.1, seed=7)
    block = DepthNoise(camera)
    context = block.CreateDefaultContext()
    clean = ImageDepth32F(160, 120)
    clean.mutable_data[:] = 1.0
    block.get_input_port().FixValue(context, clean)

    def draw(time: float) -> np.ndarray:
        context.SetTime(time)
        return np.array(block.get_output_port().Eval(context).data[:, :, 0], copy=True)

    first, again, later = draw(0.0), draw(0.0), draw(0.5)
    np.testing.assert_array_equal(first, again)
    assert not np.array_equal(np.isnan(first), np.isnan(later))
    assert np.isnan(first).mean() == pytest.approx(0.1, abs=0.01)
    assert np.nanstd(first) == pytest.approx(0.002, rel=0.05) and np.nanmean(first) == pytest.approx(
        1.0, abs=1e-3
    )


def test_camera_pose_looks_at_the_table_and_rejects_a_parallel_up():
    pose = camera_pose(CameraConfig(up=(1.0, 0.0, 0.0)), SCENE)
    np.testing.assert_allclose(pose.translation(), [0.4, 0.0, 0.75 + 1.6])
    np.testing.assert_allclose(pose.rotation().matrix()[:, 2], [0, 0, -1], atol=1e-12)  # looking down
    np.testing.assert_allclose(pose.rotation().matrix()[:, 1], [-1, 0, 0], atol=1e-12)  # +x up the image
    turned = camera_pose(CameraConfig(), SCENE).rotation().matrix()  # the default: 3 degrees off the grid
    np.testing.assert_allclose(turned[:, 2], [0, 0, -1], atol=1e-12)
    assert math.degrees(math.atan2(-turned[1, 1], -turned[0, 1])) == pytest.approx(3.0, abs=0.01)
    with pytest.raises(ValueError, match="parallel to its view"):
        camera_pose(CameraConfig(up=(0.0, 0.0, 1.0)), SCENE)


def test_the_scenario_file_sets_the_cameras_and_the_perception_block_follows_it():
    scenario = load_scenario(
        data="perception: {source: camera, cameras: [{name: top, width: 160, height: 120}, {name: side}]}"
    )
    assert scenario.perception.source == "camera" and [c.name for c in scenario.perception.cameras] == [
        "top",
        "side",
    ]
    assert scenario.perception.cameras[0].depth_noise == CameraConfig().depth_noise
    block = ScenePerception(template=scenario.scene, config=scenario.perception)
    ports = {block.get_input_port(i).get_name() for i in range(block.num_input_ports())}
    assert ports == {
        f"{c}.{p}" for c in ("top", "side") for p in ("depth_image", "label_image", "camera_pose")
    }
    assert {block.get_output_port(i).get_name() for i in range(block.num_output_ports())} == {
        "scene",
        "perception",
        "point_cloud",
    }


def test_add_scene_perception_wires_the_worlds_cameras():
    builder = DiagramBuilder()
    scenario = replace(
        SCENARIO, perception=replace(SCENARIO.perception, cameras=(replace(CAMERA, width=160, height=120),))
    )
    world = builder.AddSystem(make_world_diagram(scenario))
    block = add_scene_perception(builder, world, template=scenario.scene, config=scenario.perception)
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    mine = block.GetMyContextFromRoot(context)
    perception = block.get_perception_output_port().Eval(mine)
    assert perception.ok, perception.reason
    cloud = block.get_point_cloud_output_port().Eval(mine)  # every pixel with a depth, coloured
    assert cloud.size() == perception.pixels - perception.no_depth_pixels > 0.2 * 160 * 120
    assert cloud.has_rgbs() and np.all(np.isfinite(cloud.xyzs()))


def test_an_object_partly_hidden_by_a_taller_one_is_found_with_the_outline_that_shows():
    """Off the camera's axis a tall box hides the near side of a short one behind it: the short box
    is found, a third of its outline reported occluded, its seen extents right and its hidden one
    a lower bound (what shows of it)."""
    short = SceneObject("short", "box", 0.4, -0.40, (0.08, 0.06, 0.05))
    tall = SceneObject("tall", "box", 0.4, -0.32, (0.08, 0.06, 0.2))
    scene = replace(SCENE, obstacles=(short, tall))
    perception, _ = perceive_rendered(replace(SCENARIO, scene=scene))
    assert perception.ok, perception.reason
    record = perception_record(scene, perception)
    assert record["missed"] == [] and record["invented"] == []
    errors = {o["name"]: o for o in record["objects"]}
    seen = {o.name: o for o in perception.objects}
    hidden = seen[errors["short"]["perceived_as"]]
    assert hidden.occluded > 0.2 and seen[errors["tall"]["perceived_as"]].occluded == 0.0
    along_x, _, height = errors["short"]["size_errors_m"]  # absolute errors
    assert along_x < 0.005 and height < 0.002
    assert -0.03 < hidden.size[1] - short.size[1] < 0.001  # the hidden side: what shows
    assert errors["tall"]["position_error_m"] < 0.002 and errors["tall"]["size_error_m"] < 0.004


def test_two_tilted_cameras_frames_are_perceived_together():
    cameras = (
        CameraConfig(name="left", width=320, height=240, position=(0.0, 0.5, 1.5), look_at=(0.0, 0.1, 0.0)),
        CameraConfig(
            name="right", width=320, height=240, position=(0.0, -0.5, 1.5), look_at=(0.0, -0.1, 0.0), seed=1
        ),
    )
    scenario = replace(SCENARIO, perception=replace(SCENARIO.perception, cameras=cameras))
    builder = DiagramBuilder()
    world = builder.AddSystem(make_world_diagram(scenario))
    block = add_scene_perception(builder, world, template=scenario.scene, config=scenario.perception)
    diagram = builder.Build()
    perception = block.get_perception_output_port().Eval(
        block.GetMyContextFromRoot(diagram.CreateDefaultContext())
    )
    assert perception.ok, perception.reason
    assert perception.pixels == 2 * 320 * 240
    record = perception_record(SCENE, perception)
    assert record["missed"] == [] and record["invented"] == []
    for error in record["objects"]:
        assert error["perceived_shape"] == error["shape"], error
        assert error["position_error_m"] < 0.003 and error["size_error_m"] < 0.005, error


def test_the_perceived_scene_follows_an_object_moved_in_the_plant():
    """What a re-planning controller needs: the same diagram perceives again when an object moves."""
    builder = DiagramBuilder()
    world = builder.AddSystem(make_world_diagram(SCENARIO))
    block = add_scene_perception(builder, world, template=SCENARIO.scene, config=SCENARIO.perception)
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    mine = block.GetMyContextFromRoot(context)
    can = next(o for o in block.get_scene_output_port().Eval(mine).obstacles if o.shape == "cylinder")
    plant = world_plant(world)[0]
    plant_context = plant.GetMyMutableContextFromRoot(context)
    body = plant.GetBodyByName("can")
    pose = plant.GetFreeBodyPose(plant_context, body)
    pose.set_translation(pose.translation() + [0.05, 0.0, 0.0])
    plant.SetFreeBodyPose(plant_context, body, pose)
    moved = next(o for o in block.get_scene_output_port().Eval(mine).obstacles if o.shape == "cylinder")
    assert moved.x - can.x == pytest.approx(0.05, abs=0.002) and moved.y == pytest.approx(can.y, abs=0.002)


def test_perceive_world_sees_the_true_world_not_the_believed_scene():
    """The one frame an open-loop run plans on: the world's cameras at the start, with its model error."""
    error = WorldPerturbation(
        {"can": ObjectPerturbation(dx=0.04, dy=-0.03, dyaw=0.0, mass_scale=1.0, friction_scale=1.0)}
    )
    believed, _ = perceive_world(SCENARIO)
    true, seconds = perceive_world(SCENARIO, model_error=error)
    assert believed.ok and true.ok and seconds > 0.0
    can = [next(o for o in p.scene.obstacles if o.shape == "cylinder") for p in (believed, true)]
    assert (can[1].x - can[0].x, can[1].y - can[0].y) == pytest.approx((0.04, -0.03), abs=0.002)
    assert can[0].x == pytest.approx(0.3, abs=0.003) and can[0].y == pytest.approx(0.2, abs=0.003)
    assert perceive_rendered(SCENARIO)[1] == believed.scene  # the same frame as the world's own ports


def test_off_axis_objects_are_located_without_the_pixel_grids_bias():
    """A cylinder and a yawed box 0.3 m off the camera's axis at 640 x 480 (a pixel ~2.3 mm on
    them): found within 0.2 mm, their sizes within 0.3 mm. Pixel centres on a top's edge lie inside
    the footprint by half a pixel on average; fitted to them, the cylinder was 0.8 mm nearer the
    camera's axis and the box 1.5 mm too large."""
    camera = replace(CAMERA, width=640, height=480)
    scene = replace(
        SCENE,
        target=replace(SCENE.target, x=0.62, y=0.23),
        obstacles=(SceneObject("yawed", "box", 0.22, -0.21, (0.06, 0.12, 0.10), yaw=0.3),),
    )
    scenario = Scenario(scene=scene, perception=PerceptionConfig(source="camera", cameras=(camera,)))
    perception, _ = perceive_rendered(scenario)
    assert perception.ok, perception.reason
    errors = {o["name"]: o for o in perception_record(scene, perception)["objects"]}
    assert set(errors) == {"Target", "yawed"}
    for error in errors.values():
        assert error["perceived_shape"] == error["shape"], error
        assert error["position_error_m"] < 0.0002 and error["size_error_m"] < 0.0003, error


def test_a_rolled_cameras_table_edges_are_found_without_the_pixel_grids_bias():
    """The camera turned about 3 degrees about its axis: the table's edges cross the pixel grid
    at a slant, so their steps' middles average onto them: its length and width within 0.5 mm (a
    pixel here is ~5 mm; grown by half a pixel from its extremes they were 2.3 and 4.8 mm long)."""
    camera = replace(CAMERA, up=(1.0, 0.05, 0.0))
    scenario = replace(SCENARIO, perception=replace(SCENARIO.perception, cameras=(camera,)))
    perception, scene = perceive_rendered(scenario)
    assert perception.ok, perception.reason
    assert scene.table.length == pytest.approx(SCENE.table.length, abs=0.0005)
    assert scene.table.width == pytest.approx(SCENE.table.width, abs=0.0005)
