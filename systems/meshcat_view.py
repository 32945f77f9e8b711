"""What a run shows in MeshCat: the camera framed on the table, the plans as path lines with keypoint markers."""

from __future__ import annotations

import numpy as np
from pydrake.geometry import Meshcat, Rgba, Sphere
from pydrake.math import RigidTransform

from hlp_drake.planner import HighLevelPlan
from hlp_drake.scene.model import Scene

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
