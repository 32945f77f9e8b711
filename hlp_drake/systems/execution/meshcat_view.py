"""What a run shows in MeshCat: the camera framed on the table, the plans as thick coloured paths with
keypoint markers, each pushed obstacle highlighted while it is pushed, and what the cameras perceived
(the point cloud and the fitted objects).

``frame_table`` looks at the table from the person's side (the start's, where the person stood in
the demonstrations), ``VIEW_ELEVATION`` up and ``VIEW_AZIMUTH`` to the side, close enough that the
table fills most of the view, with MeshCat's grid and axes hidden and a plain light background.
``draw_plan`` draws a plan as a tube of cylinders (WebGL draws MeshCat's lines one pixel wide whatever
their width); ``push_times`` finds when the executed tcp pushed each obstacle of a robot plan and
``highlight_pushes`` colours the obstacle in the recording for that time; ``with_legend`` adds to a
recording's HTML the legend naming the colours and a heading with the recording's clock.
"""

from __future__ import annotations

import html
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from pydrake.geometry import Box, Cylinder, Meshcat, Rgba, Sphere
from pydrake.math import RigidTransform, RotationMatrix

from hlp_drake.planner import HighLevelPlan
from hlp_drake.scene.model import Scene
from hlp_drake.systems.perception.perception import Perception
from hlp_drake.systems.perception.system import CLASS_COLOURS, perception_cloud
from hlp_drake.systems.world.scene_models import OBSTACLE_COLOR, TARGET_COLOR

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
PUSHED_COLOUR = Rgba(0.15, 0.85, 0.35, 1)
"""An obstacle while the robot pushes it (green: apart from the scene's, the plans' and the perceived
objects' colours)."""
PUSHED_MARGIN = 0.003
"""The pushed obstacle's highlight lies this far outside its faces, m."""
PASSED_WITHIN = 0.1
"""A push is highlighted if the tcp passed this near its start and its end keypoints, m (the optimiser's
noise moves the way by a few centimetres; a plan the execution did not follow is further off)."""
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


FIXED_BASE_VIEW = (math.radians(65.0), math.radians(-110.0), 1.3)
"""(elevation, azimuth, distance) for a robot fixed before the middle of the table's front edge: its
arm stands between the person's side and the table, so the camera looks from the left, a little
from the far side, higher and farther out (checked in screenshots of the panda and the iiwa14)."""


def camera_pose(scene: Scene, *, fixed_base: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """(where the camera is, the point it looks at) in the world, for ``scene``'s table: from the
    person's side (x < 0), ``VIEW_ELEVATION`` up and ``VIEW_AZIMUTH`` to the side, looking just in
    front of the table top's centre so that its near edge stays in view; for a ``fixed_base``
    robot, ``FIXED_BASE_VIEW``."""
    table = scene.table
    target = np.array([0.35 * table.length, 0.0, table.height - 0.05])
    elevation, azimuth, scale = (
        FIXED_BASE_VIEW if fixed_base else (VIEW_ELEVATION, VIEW_AZIMUTH, VIEW_DISTANCE)
    )
    distance = scale * max(table.length, table.width)
    direction = np.array(
        [
            -math.cos(elevation) * math.cos(azimuth),
            -math.cos(elevation) * math.sin(azimuth),
            math.sin(elevation),
        ]
    )
    return target + distance * direction, target


def frame_table(meshcat: Meshcat, scene: Scene, *, fixed_base: bool = False) -> None:
    """Frame ``scene``'s table (``camera_pose``) on a plain background, the grid and axes hidden."""
    camera, target = camera_pose(scene, fixed_base=fixed_base)
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


def keypoint_points(plan: HighLevelPlan, *, table_height: float, keypoint_height: float) -> np.ndarray:
    """(n, 3) world points of ``plan``'s keypoints: at ``keypoint_height``, a lifted keypoint at its own
    height above the table top."""
    return np.array(
        [
            (k.position[0], k.position[1], keypoint_height if k.height is None else table_height + k.height)
            for k in plan.keypoints
        ],
        dtype=float,
    ).reshape(-1, 3)


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
    points = keypoint_points(plan, table_height=table_height, keypoint_height=keypoint_height)
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


@dataclass(frozen=True)
class Push:
    """One push of a robot plan as executed: the pushed object's (true) name and the simulated times
    the tcp passed the push's start (its ``move`` keypoint) and its end (the ``release`` after it), s."""

    element: str
    start: float
    end: float


def align_keypoints(points: np.ndarray, path: np.ndarray) -> np.ndarray:
    """For each of ``points`` (k, 3), in order, the index of the sample of ``path`` (n, 3) where it was
    passed: the non-decreasing indices that minimise the sum of the distances (a tcp that comes near
    a later keypoint's place before an earlier one's is not taken to have skipped ahead)."""
    points, path = np.asarray(points, dtype=float), np.asarray(path, dtype=float)
    if len(points) == 0 or len(path) == 0:
        return np.zeros(0, dtype=int)
    distance = np.linalg.norm(points[:, None, :] - path[None, :, :], axis=2)
    samples = np.arange(len(path))
    cost, before = distance[0], []
    for row in distance[1:]:
        best = np.minimum.accumulate(cost)  # the cheapest way to have passed the keypoints so far by j
        before.append(np.maximum.accumulate(np.where(cost <= best, samples, 0)))  # ... and where
        cost = row + best
    indices = [int(np.argmin(cost))]
    for arg in reversed(before):
        indices.append(int(arg[indices[-1]]))
    return np.array(indices[::-1])


def push_times(
    plan: HighLevelPlan,
    times: np.ndarray,
    tcp: np.ndarray,
    *,
    table_height: float,
    keypoint_height: float,
    names: Mapping[str, str | None] | None = None,
) -> list[Push]:
    """The pushes of the robot plan ``plan`` as executed by a tcp at ``tcp`` (n, 3) at ``times`` (n,):
    each ``move`` keypoint to the ``release`` after it, timed where the tcp passed them
    (``align_keypoints``); a push whose start or end the tcp did not pass within ``PASSED_WITHIN`` is
    left out (it did not run as planned). ``names`` maps a perceived object's name to the true one
    (None: matched to none, left out)."""
    points = keypoint_points(plan, table_height=table_height, keypoint_height=keypoint_height)
    tcp = np.asarray(tcp, dtype=float)
    passed = align_keypoints(points, tcp)
    if len(passed) == 0:
        return []
    actions = [k.action for k in plan.keypoints]
    missed = np.linalg.norm(tcp[passed] - points, axis=1) > PASSED_WITHIN
    pushes = []
    for i, keypoint in enumerate(plan.keypoints):
        if keypoint.action != "move" or "release" not in actions[i + 1 :]:
            continue
        end = actions.index("release", i + 1)
        element = keypoint.element if names is None else names.get(keypoint.element)
        if element is not None and not (missed[i] or missed[end]):
            pushes.append(Push(element, float(times[passed[i]]), float(times[passed[end]])))
    return pushes


def highlight_pushes(
    meshcat: Meshcat, scene: Scene, pushes: Sequence[Push], *, prefix: str = "visualizer"
) -> None:
    """Colour each pushed object while it is pushed, in the recording ``meshcat`` is making: a shell
    in ``PUSHED_COLOUR`` ``PUSHED_MARGIN`` outside its faces, a child of its body's frame
    (``prefix/<name>/<name>/pushed``, so it moves with the object), shown from its push's start to
    its end and hidden before and after. Call it while recording, before ``PublishRecording``."""
    objects = {o.name: o for o in scene.objects}
    paths = {}
    for name in dict.fromkeys(p.element for p in pushes if p.element in objects):
        sx, sy, height = (s + 2.0 * PUSHED_MARGIN for s in objects[name].size)
        shape = Cylinder(sx / 2.0, height) if objects[name].shape == "cylinder" else Box(sx, sy, height)
        paths[name] = f"{prefix}/{name}/{name}/pushed"
        meshcat.SetObject(paths[name], shape, PUSHED_COLOUR)
        meshcat.SetProperty(paths[name], "visible", False, 0.0)
    changes = sorted(
        (time, shown, paths[p.element])
        for p in pushes
        if p.element in paths and p.end > p.start
        for time, shown in ((p.start, True), (p.end, False))
    )
    for time, shown, path in changes:  # in time order: each shell ends hidden
        meshcat.SetProperty(path, "visible", shown, time)


def _swatch(rgba: Rgba | tuple[float, ...], shape: str = "line") -> str:
    """A coloured HTML span: a ``line``, a ``dot`` or a ``box`` (an object; translucent as ``rgba``)."""
    r, g, b, a = (rgba.r(), rgba.g(), rgba.b(), rgba.a()) if isinstance(rgba, Rgba) else rgba
    colour = f"rgba({round(255 * r)},{round(255 * g)},{round(255 * b)},{a:g})"
    width, height, radius = {"line": (28, 6, 3), "dot": (12, 12, 6), "box": (14, 14, 2)}[shape]
    return (
        f'<span style="display:inline-block;vertical-align:middle;width:{width}px;height:{height}px;'
        f'border-radius:{radius}px;background:{colour}"></span>'
    )


def _swatches(colours: Sequence[Rgba | tuple[float, ...]], shape: str) -> str:
    return " ".join(_swatch(c, shape) for c in colours)


def legend_rows(*, perceived: bool = False) -> list[tuple[str, str]]:
    """The legend's rows, (swatches as HTML, text): what ``draw_plan``, ``highlight_pushes`` and (with
    ``perceived``) ``draw_perception`` draw, and the scene's own colours."""
    keypoints = [
        ACTION_COLOURS[a] for a in ("start", "move", "release", "gap", "transit", "approach", "target")
    ]
    rows = [
        (_swatch(PATH_COLOURS["plan"]), "the person's plan (the human-like planner), on the table top"),
        (_swatch(PATH_COLOURS["robot_plan"]), "the robot's path (its plan, at the gripper's height)"),
        (
            _swatches(keypoints, "dot"),
            "the robot's keypoints: start, push, release, gap, lifted, approach, target",
        ),
        (_swatches([TARGET_COLOR, OBSTACLE_COLOR], "box"), "the target and the obstacles, as simulated"),
        (
            _swatch(PUSHED_COLOUR, "box"),
            "an obstacle while the robot pushes it (from its push keypoint to the release)",
        ),
    ]
    if perceived:
        fitted = [PERCEIVED_COLOURS["target"], PERCEIVED_COLOURS["obstacle"]]
        seen = "perceived (translucent): the target and obstacles fitted to the depth camera's points at"
        seen += " the start, what the planners used; they stay where they were seen"
        points = [(*(c / 255.0), 1.0) for c in CLASS_COLOURS]
        cloud = (
            "the depth camera's points at the start: table, object, above the table in no object, the rest"
        )
        rows += [(_swatches(fitted, "box"), seen), (_swatches(points, "dot"), cloud + " (the robot)")]
    return rows


CLOCK_SCRIPT = """<script>
(function () {
  var animator = viewer.animator, update = animator.update.bind(animator);
  var clock = document.getElementById("hlp-clock");
  animator.update = function () {
    update();
    if (animator.duration > 0) {
      var time = animator.time.toFixed(1), duration = animator.duration.toFixed(1);
      clock.textContent = "simulated time " + time + " s of " + duration + " s";
    }
  };
})();
</script>"""
"""Shows the recording's time in ``#hlp-clock``, set with each frame MeshCat's ``viewer.animator`` plays."""


def legend_html(*, perceived: bool = False, title: str | None = None) -> str:
    """The legend (``legend_rows``) as an HTML box at the view's bottom left and, at its top left,
    ``title`` (what ran) over the recording's clock (``CLOCK_SCRIPT``)."""
    body = "".join(
        f"<div>{swatch} {html.escape(text)}</div>" for swatch, text in legend_rows(perceived=perceived)
    )
    box = "position:fixed;z-index:10;padding:8px 10px;background:rgba(255,255,255,0.88);border-radius:6px;"
    box += "color:#222;pointer-events:none;"
    place = "left:12px;bottom:12px;max-width:560px;font:13px/1.5 sans-serif"
    legend = f'<div id="hlp-legend" style="{box}{place}">{body}</div>'
    heading = "" if title is None else f'<div style="font-weight:bold">{html.escape(title)}</div>'
    heading += '<div id="hlp-clock">simulated time 0.0 s</div>'
    place = "left:12px;top:12px;max-width:70%;font:14px/1.4 sans-serif"
    return f'<div id="hlp-title" style="{box}{place}">{heading}</div>{legend}{CLOCK_SCRIPT}'


def with_legend(page: str, *, perceived: bool = False, title: str | None = None) -> str:
    """A MeshCat recording's HTML (``Meshcat.StaticHtml``) with ``legend_html`` over the view."""
    legend = legend_html(perceived=perceived, title=title)
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
