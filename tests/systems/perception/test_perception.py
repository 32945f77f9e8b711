"""ScenePerception on a known scene's frame rendered once and on synthetic frames for the bad inputs."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from perception_support import CAMERA, SCENARIO, SCENE, perceive_fixed, perceive_rendered
from pydrake.systems.sensors import ImageDepth32F, ImageLabel16I

from hlp_drake.systems.perception.accuracy import perception_record
from hlp_drake.systems.perception.cameras import ROBOT_LABEL, TABLE_LABEL, TARGET_LABEL
from hlp_drake.systems.perception.depth_points import view_points
from hlp_drake.systems.perception.system import ScenePerception
from hlp_drake.systems.world.world import make_world_diagram


@pytest.fixture(scope="module")
def frame() -> dict[str, object]:
    """The world's camera ports evaluated once at time 0: depth, label image and camera pose."""
    world = make_world_diagram(SCENARIO)
    context = world.CreateDefaultContext()
    return {
        port: world.GetOutputPort(f"{CAMERA.name}.{port}").Eval(context)
        for port in ("depth_image", "label_image", "camera_pose")
    }


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
