"""What a run shows in MeshCat: the camera framed on the table, the plans as thick coloured paths with
keypoint markers, and what the cameras perceived (the point cloud and the fitted objects).

``frame_table`` looks at the table from the person's side (the start's, where the person stood in
the demonstrations), 45 degrees up and from a little to the right, close enough that the table fills
most of the view, with MeshCat's grid and axes hidden and a plain light background. ``draw_plan``
draws a plan as a tube of cylinders (WebGL draws MeshCat's lines one pixel wide whatever their
width); ``with_legend`` adds the legend naming the colours to a recording's HTML.
"""

from __future__ import annotations

import html
import math

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
PATH_COLOURS = {"plan": Rgba(0.9, 0.2, 0.6, 1), "robot_plan": Rgba(0.1, 0.4, 0.95, 1)}
"""The person's plan (magenta, on the table top) and the robot's path (blue, at the tcp's height)."""
PATH_RADIUS = {"plan": 0.006, "robot_plan": 0.008}
"""The paths' tubes, m: a centimetre or two across, clear at a glance from the framed view."""
PLAN_LIFT = 0.004
"""The person's plan is drawn this far above the table top, m (the robot's at the tcp's height)."""
PERCEIVED_COLOURS = {"target": Rgba(1.0, 0.55, 0.0, 0.45), "obstacle": Rgba(0.95, 0.85, 0.1, 0.45)}
"""The fitted objects, translucent over the true ones."""
CLOUD_VOXEL = 0.005
"""The drawn point cloud is Drake's voxel down-sampling of the frame's at this size, m."""
VIEW_ELEVATION = math.radians(55.0)
"""The camera looks down at the table from this far above the horizontal."""
VIEW_AZIMUTH = math.radians(-45.0)
"""... and from this far to the right of the start-target line (x), seen from the start (negative: to
the left, where the arm, reaching from the right, hides neither plan; checked in screenshots)."""
VIEW_DISTANCE = 1.0
"""... from this many times the table's larger side from the point it looks at."""
BACKGROUND = ([0.97, 0.97, 0.98], [0.85, 0.86, 0.88])
"""The background's top and bottom colours: plain and light, the scene in front of it."""


def camera_pose(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """(where the camera is, the point it looks at) in the world, for ``scene``'s table: from the
    person's side (x < 0), ``VIEW_ELEVATION`` up and ``VIEW_AZIMUTH`` to the side, looking just in
    front of the table top's centre so that its near edge stays in view."""
    table = scene.table
    target = np.array([0.35 * table.length, 0.0, table.height - 0.05])
    distance = VIEW_DISTANCE * max(table.length, table.width)
    direction = np.array(
        [
            -math.cos(VIEW_ELEVATION) * math.cos(VIEW_AZIMUTH),
            -math.cos(VIEW_ELEVATION) * math.sin(VIEW_AZIMUTH),
            math.sin(VIEW_ELEVATION),
        ]
    )
    return target + distance * direction, target


def frame_table(meshcat: Meshcat, scene: Scene) -> None:
    """Frame ``scene``'s table (``camera_pose``) on a plain background, the grid and axes hidden."""
    camera, target = camera_pose(scene)
    meshcat.SetCameraPose(camera, target)
    meshcat.SetProperty("/Grid", "visible", False)
    meshcat.SetProperty("/Axes", "visible", False)
    meshcat.SetProperty("/Background", "top_color", BACKGROUND[0])
    meshcat.SetProperty("/Background", "bottom_color", BACKGROUND[1])


def _segment(meshcat: Meshcat, name: str, a: np.ndarray, b: np.ndarray, radius: float, rgba: Rgba) -> None:
    """A cylinder of ``radius`` from ``a`` to ``b`` (nothing for a zero-length segment)."""
    axis = b - a
    length = float(np.linalg.norm(axis))
    if length < 1e-6:
        return
    meshcat.SetObject(name, Cylinder(radius, length), rgba)
    z = axis / length
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    rotation = RotationMatrix(np.column_stack([x, np.cross(z, x), z]))
    meshcat.SetTransform(name, RigidTransform(rotation, (a + b) / 2.0))


def draw_plan(
    meshcat: Meshcat,
    plan: HighLevelPlan,
    *,
    table_height: float,
    keypoint_height: float,
    path: str = "plan",
    markers: bool = True,
) -> None:
    """``plan`` under ``path``: a tube (``path/path/NN``, a cylinder per leg and a sphere per bend, in
    ``PATH_COLOURS[path]``) through its keypoints at ``keypoint_height`` (a lifted keypoint at its
    own height above the table top) and, with ``markers``, a sphere per keypoint coloured by its
    action."""
    meshcat.Delete(path)
    points = np.array(
        [
            (k.position[0], k.position[1], keypoint_height if k.height is None else table_height + k.height)
            for k in plan.keypoints
        ],
        dtype=float,
    ).reshape(-1, 3)
    rgba = PATH_COLOURS.get(path, PATH_COLOURS["plan"])
    radius = PATH_RADIUS.get(path, PATH_RADIUS["plan"])
    for i in range(len(points) - 1):
        _segment(meshcat, f"{path}/path/{i:02d}", points[i], points[i + 1], radius, rgba)
    for i, point in enumerate(points[1:-1], 1):  # round the bends
        meshcat.SetObject(f"{path}/path/bend_{i:02d}", Sphere(radius), rgba)
        meshcat.SetTransform(f"{path}/path/bend_{i:02d}", RigidTransform(point))
    if not markers:
        return
    for i, (keypoint, point) in enumerate(zip(plan.keypoints, points)):
        name = f"{path}/{i:02d}_{keypoint.action}"
        meshcat.SetObject(
            name, Sphere(MARKER_RADIUS), ACTION_COLOURS.get(keypoint.action, Rgba(0.5, 0.5, 0.5, 1))
        )
        meshcat.SetTransform(name, RigidTransform(point))


def _swatch(rgba: Rgba, shape: str = "line") -> str:
    colour = f"rgb({round(255 * rgba.r())},{round(255 * rgba.g())},{round(255 * rgba.b())})"
    if shape == "line":
        return f'<span style="display:inline-block;width:28px;height:6px;border-radius:3px;background:{colour}"></span>'
    return f'<span style="display:inline-block;width:12px;height:12px;border-radius:6px;background:{colour}"></span>'


def legend_html(*, perceived: bool = False) -> str:
    """The legend of ``draw_plan``'s (and ``draw_perception``'s) colours, as an HTML box."""
    rows = [
        (_swatch(PATH_COLOURS["plan"]), "the person's plan (the human-like planner), on the table top"),
        (_swatch(PATH_COLOURS["robot_plan"]), "the robot's path (its plan, at the gripper's height)"),
        (
            " ".join(
                _swatch(ACTION_COLOURS[a], "dot") for a in ("start", "move", "release", "gap", "target")
            ),
            "the robot's keypoints: start, push, release, gap, target",
        ),
    ]
    if perceived:
        rows.append(
            (
                _swatch(PERCEIVED_COLOURS["obstacle"], "dot")
                + " "
                + _swatch(PERCEIVED_COLOURS["target"], "dot"),
                "what the cameras saw: the fitted objects (translucent) and the point cloud",
            )
        )
    body = "".join(f"<div>{swatch} {html.escape(text)}</div>" for swatch, text in rows)
    return (
        '<div id="hlp-legend" style="position:fixed;left:12px;bottom:12px;z-index:10;padding:8px 10px;'
        "background:rgba(255,255,255,0.88);border-radius:6px;font:13px/1.6 sans-serif;color:#222;"
        f'pointer-events:none">{body}</div>'
    )


def with_legend(page: str, *, perceived: bool = False) -> str:
    """A MeshCat recording's HTML (``Meshcat.StaticHtml``) with ``legend_html`` over the view."""
    legend = legend_html(perceived=perceived)
    at = page.rfind("</body>")
    return page + legend if at < 0 else page[:at] + legend + page[at:]


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
