"""What a run shows in MeshCat: the camera framed on the table, the plans as path lines with keypoint
markers, and what the cameras perceived (the point cloud and the fitted objects)."""

from __future__ import annotations

import numpy as np
from pydrake.geometry import Box, Cylinder, Meshcat, Rgba, Sphere
from pydrake.math import RigidTransform, RotationMatrix

from hlp_drake.planner import HighLevelPlan
from hlp_drake.scene.model import Scene
from hlp_drake.systems.perception.perception import Perception
from hlp_drake.systems.perception.system import perception_cloud

ACTION_COLOURS = {
    "start": Rgba(0.1, 0.1, 0.1, 1),
    "gap": Rgba(0.2, 0.7, 0.2, 1),
    "move": Rgba(0.85, 0.2, 0.2, 1),
    "release": Rgba(0.6, 0.3, 0.8, 1),
    "target": Rgba(1.0, 0.55, 0.0, 1),
    "transit": Rgba(0.3, 0.6, 0.9, 1),
    "approach": Rgba(0.95, 0.8, 0.1, 1),
}
MARKER_RADIUS = 0.02
"""Keypoint markers, m: visible from the framed view across a robot-sized table."""
PATH_COLOURS = {"plan": Rgba(0.2, 0.2, 0.2, 1), "robot_plan": Rgba(0.1, 0.45, 0.9, 1)}
PERCEIVED_COLOURS = {"target": Rgba(1.0, 0.55, 0.0, 0.45), "obstacle": Rgba(0.95, 0.85, 0.1, 0.45)}
"""The fitted objects, translucent over the true ones."""
CLOUD_VOXEL = 0.005
"""The drawn point cloud is Drake's voxel down-sampling of the frame's at this size, m."""


def frame_table(meshcat: Meshcat, scene: Scene) -> None:
    """Look at the table from behind and above the robot's start, the whole table in view."""
    table = scene.table
    centre = np.array([table.length / 2.0, 0.0, table.height])
    reach = max(table.length, table.width)
    camera = centre + np.array([-1.6 * reach - 0.6, -0.5 * reach, 1.3 * reach + 0.4])
    meshcat.SetCameraPose(camera, centre)


def draw_plan(
    meshcat: Meshcat,
    plan: HighLevelPlan,
    *,
    table_height: float,
    keypoint_height: float,
    path: str = "plan",
    markers: bool = True,
) -> None:
    """``plan`` under ``path``: a path line through its keypoints at the tcp's height (a lifted
    keypoint at its own height above the table top) and, with ``markers``, a sphere per keypoint
    coloured by its action."""
    meshcat.Delete(path)
    points = np.array(
        [
            (k.position[0], k.position[1], keypoint_height if k.height is None else table_height + k.height)
            for k in plan.keypoints
        ],
        dtype=float,
    ).reshape(-1, 3)
    if len(points) >= 2:
        meshcat.SetLine(
            f"{path}/path", points.T, line_width=3.0, rgba=PATH_COLOURS.get(path, PATH_COLOURS["plan"])
        )
    if not markers:
        return
    for i, (keypoint, point) in enumerate(zip(plan.keypoints, points)):
        name = f"{path}/{i:02d}_{keypoint.action}"
        meshcat.SetObject(
            name, Sphere(MARKER_RADIUS), ACTION_COLOURS.get(keypoint.action, Rgba(0.5, 0.5, 0.5, 1))
        )
        meshcat.SetTransform(name, RigidTransform(point))


def draw_perception(meshcat: Meshcat, perception: Perception, *, path: str = "perception") -> None:
    """``perception`` under ``path``: the frame's point cloud (``points``, coloured by class) and
    each fitted object (``objects/<name>``: a translucent box or cylinder on the fitted table)."""
    meshcat.Delete(path)
    cloud = perception_cloud(perception).VoxelizedDownSample(voxel_size=CLOUD_VOXEL)
    meshcat.SetObject(f"{path}/points", cloud, point_size=0.004)
    if perception.table is None:
        return
    for obj in perception.objects:
        sx, sy, height = obj.size
        shape = Cylinder(sx / 2.0, height) if obj.shape == "cylinder" else Box(sx, sy, height)
        role = "target" if obj is perception.objects[0] and perception.ok else "obstacle"
        name = f"{path}/objects/{obj.name or 'unnamed'}"
        meshcat.SetObject(name, shape, PERCEIVED_COLOURS[role])
        z = perception.table.height_at(obj.x, obj.y) + height / 2.0
        meshcat.SetTransform(name, RigidTransform(RotationMatrix.MakeZRotation(obj.yaw), [obj.x, obj.y, z]))
