"""The cameras and ``ScenePerception`` on their own: a known scene rendered once (small images), its
depth and label images fixed on the block's inputs, and synthetic frames for the bad-input cases."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.sensors import ImageDepth32F, ImageLabel16I

from hlp_drake.scene.model import Scene, SceneObject, Table
from hlp_drake.systems.perception.accuracy import perception_record
from hlp_drake.systems.perception.cameras import (
    ROBOT_LABEL,
    TABLE_LABEL,
    TARGET_LABEL,
    CameraConfig,
    DepthNoise,
    PerceptionConfig,
    camera_pose,
)
from hlp_drake.systems.perception.depth_points import view_points
from hlp_drake.systems.perception.system import ScenePerception, add_scene_perception, perceive_world
from hlp_drake.systems.scenario import Scenario, load_scenario
from hlp_drake.systems.world.uncertainty import ObjectPerturbation, WorldPerturbation
from hlp_drake.systems.world.world import make_world_diagram, world_plant

CAMERA = CameraConfig(width=320, height=240, depth_noise=0.001, dropout=0.01, seed=4)
SCENE = Scene(
    name="perceived",
    table=Table(length=0.8, width=0.9, height=0.75),
    start=(0.1, 0.0),
    target=SceneObject("Target", "cylinder", 0.6, 0.1, (0.066, 0.066, 0.12)),
    obstacles=(
        SceneObject("tilted_box", "box", 0.35, -0.2, (0.06, 0.15, 0.10), yaw=0.4),
        SceneObject("box", "box", 0.55, -0.15, (0.08, 0.05, 0.14)),
        SceneObject("can", "cylinder", 0.3, 0.2, (0.07, 0.07, 0.09)),
    ),
)
SCENARIO = Scenario(scene=SCENE, perception=PerceptionConfig(source="camera", cameras=(CAMERA,)))


@pytest.fixture(scope="module")
def frame() -> dict[str, object]:
    """The world's camera ports evaluated once at time 0: depth, label image and camera pose."""
    world = make_world_diagram(SCENARIO)
    context = world.CreateDefaultContext()
    return {
        port: world.GetOutputPort(f"{CAMERA.name}.{port}").Eval(context)
        for port in ("depth_image", "label_image", "camera_pose")
    }


def perceive_fixed(depth, labels, pose, scenario: Scenario = SCENARIO):
    """``ScenePerception``'s ``perception`` and ``scene`` outputs with its inputs fixed."""
    block = ScenePerception(template=scenario.scene, config=scenario.perception)
    context = block.CreateDefaultContext()
    name = scenario.perception.cameras[0].name
    block.GetInputPort(f"{name}.depth_image").FixValue(context, depth)
    block.GetInputPort(f"{name}.label_image").FixValue(context, labels)
    block.GetInputPort(f"{name}.camera_pose").FixValue(context, pose)
    return block.get_perception_output_port().Eval(context), block.get_scene_output_port().Eval(context)


def perceive_rendered(scenario: Scenario):
    """``perceive_fixed`` on the frame the world of ``scenario`` renders with its first camera."""
    context = (world := make_world_diagram(scenario)).CreateDefaultContext()
    name = scenario.perception.cameras[0].name
    ports = [
        world.GetOutputPort(f"{name}.{p}").Eval(context)
        for p in ("depth_image", "label_image", "camera_pose")
    ]
    return perceive_fixed(*ports, scenario)


def images(depth: np.ndarray, labels: np.ndarray) -> tuple[ImageDepth32F, ImageLabel16I]:
    h, w = depth.shape
    depth_image, label_image = ImageDepth32F(w, h), ImageLabel16I(w, h)
    depth_image.mutable_data[:, :, 0] = depth
    label_image.mutable_data[:, :, 0] = labels
    return depth_image, label_image


def synthetic_table(rows: slice, cols: slice, depth: float = 1.6) -> tuple[np.ndarray, np.ndarray]:
    """A level table straight below the camera (constant depth) over ``rows`` x ``cols``, nothing
    elsewhere (+inf: out of range)."""
    d = np.full((CAMERA.height, CAMERA.width), np.inf, np.float32)
    labels = np.zeros(d.shape, np.int16)
    d[rows, cols], labels[rows, cols] = depth, TABLE_LABEL
    return d, labels


def test_scene_perception_finds_every_object_with_its_pose_size_and_shape(frame):
    perception, scene = perceive_fixed(frame["depth_image"], frame["label_image"], frame["camera_pose"])
    assert perception.ok, perception.reason
    record = perception_record(SCENE, perception)
    assert record["missed"] == [] and record["invented"] == []
    assert scene.target.name == "Target" and len(scene.obstacles) == 3
    errors = {o["name"]: o for o in record["objects"]}
    for true in SCENE.objects:
        error = errors[true.name]
        assert error["perceived_shape"] == true.shape, true.name
        assert error["position_error_m"] < 0.004, true.name  # a pixel is ~5 mm wide at 320 x 240
        assert error["size_error_m"] < 0.006, true.name
    assert errors["tilted_box"]["yaw_error_rad"] < math.radians(3)
    assert abs(scene.table.height - SCENE.table.height) < 0.002
    assert abs(scene.table.length - SCENE.table.length) < 0.01
    assert scene.start == SCENE.start
    assert perception.perception_s > 0 and perception.pixels == CAMERA.width * CAMERA.height


def test_the_tables_height_images_are_the_heights_of_the_pixels_points_and_classify_the_cloud(frame):
    perception, _ = perceive_fixed(frame["depth_image"], frame["label_image"], frame["camera_pose"])
    table, (view,) = perception.table, perception.views
    points, _ = view_points([view])
    heights = table.heights[0][points.row, points.col]
    assert np.allclose(heights, table.height_above(points.xyz), atol=1e-9)
    assert len(perception.cloud) == len(points) and perception.cloud_class.shape == (len(points),)
    on_table = np.abs(heights) <= SCENARIO.perception.table_tolerance
    assert np.all(perception.cloud_class[on_table & (points.label != ROBOT_LABEL)] == 0)
    assert np.all(perception.cloud_class[heights >= SCENARIO.perception.min_height] != 0)
    assert (perception.cloud_class == 1).sum() == sum(o.points for o in perception.objects)


def test_scene_perception_reads_through_missing_depth_and_tells_of_nan_pixels(frame):
    depth = np.array(frame["depth_image"].data[:, :, 0], copy=True)
    rng = np.random.default_rng(0)
    depth[rng.random(depth.shape) < 0.2] = np.nan
    perception, _ = perceive_fixed(
        images(depth, frame["label_image"].data[:, :, 0])[0], frame["label_image"], frame["camera_pose"]
    )
    assert perception.ok, perception.reason
    assert perception.nan_pixels == int(np.isnan(depth).sum()) > 0.15 * depth.size
    record = perception_record(SCENE, perception)
    assert record["missed"] == [] and max(o["position_error_m"] for o in record["objects"]) < 0.006


def test_a_frame_without_a_table_gives_the_reason(frame):
    pose = frame["camera_pose"]
    nothing = np.full((CAMERA.height, CAMERA.width), np.inf, np.float32)
    perception, scene = perceive_fixed(*images(nothing, np.zeros(nothing.shape, np.int16)), pose)
    assert not perception.ok and perception.reason.startswith("no table plane found")
    assert scene.target is None and scene.obstacles == () and scene.start == SCENE.start
    all_nan = np.full(nothing.shape, np.nan, np.float32)
    perception, _ = perceive_fixed(*images(all_nan, np.zeros(nothing.shape, np.int16)), pose)
    assert perception.reason.startswith("no table plane found")
    assert perception.nan_pixels == all_nan.size
    # A wall: the depth grows down the image (a plane tilted 60 degrees), no horizontal plane.
    rows = np.arange(CAMERA.height, dtype=np.float32)[:, None]
    wall = np.broadcast_to(1.0 + 0.01 * rows, nothing.shape).astype(np.float32)
    perception, _ = perceive_fixed(*images(wall, np.zeros(nothing.shape, np.int16)), pose)
    assert perception.reason == "no table plane found (the largest plane is not horizontal)"


def test_an_empty_table_and_an_object_at_the_border_give_their_reasons(frame):
    pose = frame["camera_pose"]
    depth, labels = synthetic_table(slice(30, 210), slice(40, 280))
    perception, scene = perceive_fixed(*images(depth, labels), pose)
    assert perception.reason == "no target found (nothing stands on the table)"
    assert perception.table is not None and scene.target is None
    # The table reaches the image's left border with a box standing on it there.
    depth, labels = synthetic_table(slice(30, 210), slice(0, 280))
    depth[100:130, 0:20], labels[100:130, 0:20] = 1.5, TARGET_LABEL
    perception, _ = perceive_fixed(*images(depth, labels), pose)
    assert perception.reason.startswith("object at the image border (")
    # The table goes on out of view.
    depth, labels = synthetic_table(slice(30, 210), slice(40, CAMERA.width))
    depth[100:130, 100:130], labels[100:130, 100:130] = 1.5, TARGET_LABEL
    perception, _ = perceive_fixed(*images(depth, labels), pose)
    assert perception.reason.startswith("the table reaches out of the cameras' view")


def test_unlabelled_objects_and_a_wrong_image_size_give_their_reasons(frame):
    pose = frame["camera_pose"]
    depth, labels = synthetic_table(slice(30, 210), slice(40, 280))
    depth[100:130, 100:130] = 1.5  # labelled as the table, not the target
    perception, _ = perceive_fixed(*images(depth, labels), pose)
    assert perception.reason == "no target found (no object is labelled the target)"
    small = ImageDepth32F(160, 120)
    perception, _ = perceive_fixed(small, frame["label_image"], pose)
    assert (
        perception.reason == "camera table_camera: its depth image is 160 x 120, its settings say 320 x 240"
    )


def test_an_unconnected_input_is_a_wiring_error():
    block = ScenePerception(template=SCENARIO.scene, config=SCENARIO.perception)
    with pytest.raises(RuntimeError, match="connect or fix table_camera.depth_image"):
        block.get_scene_output_port().Eval(block.CreateDefaultContext())


def test_perception_record_reports_missed_and_invented_objects(frame):
    perception, scene = perceive_fixed(frame["depth_image"], frame["label_image"], frame["camera_pose"])
    moved = replace(
        SCENE, obstacles=(SCENE.obstacles[0], SCENE.obstacles[1].moved(0.2, -0.35), SCENE.obstacles[2])
    )
    record = perception_record(moved, perception)
    assert record["missed"] == ["box"] and record["invented"] == [
        o.name for o in scene.obstacles if abs(o.x - 0.55) < 0.01
    ]


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


def _spy_on_clustering(monkeypatch) -> list[tuple]:
    """Each call of the perception's clustering: (linked, its clusters, every point linked's clusters)."""
    from hlp_drake.systems.perception import perception as module

    calls, real = [], module.cluster_points

    def spy(points, *, radius, min_points, linked=None):
        groups = real(points, radius=radius, min_points=min_points, linked=linked)
        calls.append((linked, groups, real(points, radius=radius, min_points=min_points)))
        return groups

    monkeypatch.setattr(module, "cluster_points", spy)
    return calls


def test_a_fine_cameras_points_are_linked_on_a_strided_sample_into_the_same_objects(frame, monkeypatch):
    calls = _spy_on_clustering(monkeypatch)
    perceive_fixed(frame["depth_image"], frame["label_image"], frame["camera_pose"])
    assert calls[-1][0] is None  # a pixel wider than a third of the radius: every point linked
    fine = replace(CAMERA, width=640, height=480)
    scenario = replace(
        SCENARIO, perception=replace(SCENARIO.perception, cameras=(fine,), cluster_radius=0.02)
    )
    perception, _ = perceive_rendered(scenario)
    assert perception.ok, perception.reason
    assert perception_record(SCENE, perception)["missed"] == []
    linked, groups, full = calls[-1]
    assert linked is not None and 0 < linked.sum() <= linked.size / 3  # every second row and column
    assert len(groups) == len(full) == len(SCENE.objects)
    for group, whole in zip(sorted(groups, key=min), sorted(full, key=min)):
        assert set(group) <= set(whole) and len(group) >= 0.99 * len(whole)
