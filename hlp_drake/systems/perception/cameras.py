"""The world's RGB-D cameras: Drake ``RgbdSensor``s rendered with VTK, seeded depth noise and dropout,
and a label image of semantic classes.

``add_cameras`` (called by ``make_world_diagram``) adds one sensor per ``CameraConfig`` of the
scenario's ``perception.cameras``, fixed in the world, and exports for a camera named N:

- ``N.depth_image``: ``ImageDepth32F``, metres along the optical axis, with the camera's noise and
  dropout (NaN); pixels out of range are Drake's (0 too near, +inf too far);
- ``N.label_image``: ``ImageLabel16I``, every pixel's class: ``TABLE_LABEL``, ``TARGET_LABEL``,
  ``OBSTACLE_LABEL``, ``ROBOT_LABEL``, or Drake's ``RenderLabel.kEmpty`` where nothing was hit;
- ``N.color_image``: ``ImageRgba8U`` (rendered only when evaluated);
- ``N.camera_pose``: ``RigidTransform``, the camera's pose in the world (its optical frame: +z
  along the view, +x to the image's right, +y down the image).

The classes stand in for a semantic segmentation (what a detector trained on the target would give):
they tell the target from the obstacles and the robot from the scene, never one object from another.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Annotated, Literal

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.geometry import (
    ClippingRange,
    ColorRenderCamera,
    DepthRange,
    DepthRenderCamera,
    MakeRenderEngineVtk,
    PerceptionProperties,
    RenderCameraCore,
    RenderEngineVtkParams,
    RenderLabel,
    Role,
    SceneGraph,
)
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import ModelInstanceIndex
from pydrake.systems.framework import Context, DiagramBuilder, LeafSystem
from pydrake.systems.sensors import CameraInfo, ImageDepth32F, RgbdSensor

from hlp_drake.config.ranges import MAX_SEED, Between, First, Rule
from hlp_drake.scene.model import Scene
from hlp_drake.scene.validation import name_problem
from hlp_drake.systems.names import PERCEPTION_SOURCES, PerceptionSource
from hlp_drake.systems.world.scene_models import SceneModels

RENDERER = "vtk"
TABLE_LABEL, TARGET_LABEL, OBSTACLE_LABEL, ROBOT_LABEL = 1, 2, 3, 4
"""The label image's classes (``RenderLabel`` values)."""
CLIPPING = (0.01, 10.0)
"""The render cameras' clipping range, m (the depth range lies inside it)."""


def camera_pose(camera: CameraConfig, scene: Scene) -> RigidTransform:
    """The camera's optical frame in the world (+z along the view, +x right, +y down the image).

    Raises:
        ValueError: ``look_at`` is ``position``, or ``up`` is parallel to the view.
    """
    origin = np.zeros(3)
    if camera.frame == "table":
        origin = np.array([scene.table.length / 2.0, 0.0, scene.table.height])
    eye = origin + np.asarray(camera.position, float)
    view = origin + np.asarray(camera.look_at, float) - eye
    if np.linalg.norm(view) < 1e-9:
        raise ValueError(f"camera {camera.name!r}: look_at is its position")
    z = view / np.linalg.norm(view)
    up = np.asarray(camera.up, float)
    down = -(up - up.dot(z) * z)
    if np.linalg.norm(down) < 1e-6 * max(np.linalg.norm(up), 1e-9):
        raise ValueError(f"camera {camera.name!r}: up {list(camera.up)} is parallel to its view")
    y = down / np.linalg.norm(down)
    return RigidTransform(RotationMatrix(np.column_stack([np.cross(y, z), y, z])), eye)


def camera_info(camera: CameraConfig) -> CameraInfo:
    """The camera's pinhole intrinsics: square pixels, the principal point at the image centre."""
    return CameraInfo(width=camera.width, height=camera.height, fov_y=math.radians(camera.fov_y))


def render_cameras(camera: CameraConfig) -> tuple[ColorRenderCamera, DepthRenderCamera]:
    """The colour/label and depth render cameras of ``camera`` (sharing intrinsics and pose)."""
    core = RenderCameraCore(RENDERER, camera_info(camera), ClippingRange(*CLIPPING), RigidTransform())
    return ColorRenderCamera(core), DepthRenderCamera(core, DepthRange(camera.min_depth, camera.max_depth))


class DepthNoise(LeafSystem):
    """Seeded sensor noise on a depth image: Gaussian noise of ``depth_noise`` m on every pixel with
    a depth, and ``dropout`` of all pixels set to NaN (no return).

    Input and output port ``depth_image`` (``ImageDepth32F``). The draw depends on the seed and on
    the context's time only: the same frame is the same image, and frames at other times differ.
    """

    def __init__(self, camera: CameraConfig) -> None:
        super().__init__()
        self._noise, self._dropout, self._seed = camera.depth_noise, camera.dropout, camera.seed
        model = AbstractValue.Make(ImageDepth32F(camera.width, camera.height))
        self._input = self.DeclareAbstractInputPort(name="depth_image", model_value=model)
        self.DeclareAbstractOutputPort(
            name="depth_image",
            alloc=model.Clone,
            calc=self._calc,
            prerequisites_of_calc={self.time_ticket(), self._input.ticket()},
        )

    def _calc(self, context: Context, output: AbstractValue) -> None:
        image = self._input.Eval(context)
        noisy = output.get_mutable_value()
        noisy.resize(image.width(), image.height())
        depth = np.array(image.data, dtype=np.float32, copy=True)
        rng = np.random.default_rng([self._seed, round(context.get_time() * 1e6)])
        if self._noise > 0:
            hit = np.isfinite(depth) & (depth > 0)
            depth[hit] += rng.normal(0.0, self._noise, size=int(hit.sum())).astype(np.float32)
        if self._dropout > 0:
            depth[rng.random(depth.shape) < self._dropout] = np.nan
        noisy.mutable_data[:] = depth


def _relabel(scene_graph: SceneGraph, source, geometry, label: int) -> None:
    """Give ``geometry``'s perception role the class ``label`` (keeping its other properties)."""
    inspector = scene_graph.model_inspector()
    properties = PerceptionProperties(inspector.GetPerceptionProperties(geometry))
    properties.UpdateProperty("label", "id", RenderLabel(label))
    scene_graph.RemoveRole(source, geometry, Role.kPerception)
    scene_graph.AssignRole(source, geometry, properties)


def label_classes(
    plant: MultibodyPlant,
    scene_graph: SceneGraph,
    robot: ModelInstanceIndex,
    models: SceneModels,
    scene: Scene,
) -> None:
    """Label every perceived geometry with its class (the plant labels them by body by default)."""
    classes = {robot: ROBOT_LABEL, models.table: TABLE_LABEL}
    classes.update({models.objects[o.name]: OBSTACLE_LABEL for o in scene.obstacles})
    classes[models.objects[scene.target.name]] = TARGET_LABEL
    inspector = scene_graph.model_inspector()
    for instance, label in classes.items():
        for body in plant.GetBodyIndices(instance):
            frame = plant.GetBodyFrameIdOrThrow(body)
            for geometry in inspector.GetGeometries(frame, Role.kPerception):
                _relabel(scene_graph, plant.get_source_id(), geometry, label)


def add_cameras(
    builder: DiagramBuilder, scene_graph: SceneGraph, cameras: tuple[CameraConfig, ...], scene: Scene
) -> None:
    """Add ``cameras`` (placed over ``scene``'s table) to a world being built (its plant already
    finalized, the geometry labelled by ``label_classes``) and export their ports (see the module's
    docstring)."""
    if not cameras:
        return
    if not scene_graph.HasRenderer(RENDERER):
        scene_graph.AddRenderer(RENDERER, MakeRenderEngineVtk(RenderEngineVtkParams()))
    world = scene_graph.world_frame_id()
    for camera in cameras:
        color, depth = render_cameras(camera)
        sensor = builder.AddNamedSystem(
            f"{camera.name}_sensor",
            RgbdSensor(world, camera_pose(camera, scene), color_camera=color, depth_camera=depth),
        )
        builder.Connect(scene_graph.get_query_output_port(), sensor.query_object_input_port())
        noise = builder.AddNamedSystem(f"{camera.name}_noise", DepthNoise(camera))
        builder.Connect(sensor.depth_image_32F_output_port(), noise.get_input_port())
        builder.ExportOutput(noise.get_output_port(), f"{camera.name}.depth_image")
        builder.ExportOutput(sensor.label_image_output_port(), f"{camera.name}.label_image")
        builder.ExportOutput(sensor.color_image_output_port(), f"{camera.name}.color_image")
        builder.ExportOutput(sensor.body_pose_in_world_output_port(), f"{camera.name}.camera_pose")


# The scenario's ``perception`` section: where the planning blocks' scene comes from, the cameras and
# the settings of ``ScenePerception``.
#
# A scenario file gives only what it changes::
#
#     perception:
#       source: camera                 # truth (the plant's body poses, the default) or camera
#       cameras:                       # the world's RGB-D cameras (default: one above the table)
#       - {name: table_camera, position: [0.0, 0.0, 1.6], depth_noise: 0.002, dropout: 0.05, seed: 3}
#       cluster_radius: 0.005
MAX_PIXELS = 4096
"""The widest and tallest camera image, pixels; its square is the most pixels of all cameras together
(memory per frame grows with them)."""
MAX_CAMERAS = 8
"""Most cameras in a world."""
FINITE = Rule(lambda v: all(map(math.isfinite, v)), "{where} must be finite, got {value}", list)
DROPOUT = Rule(lambda v: 0.0 <= v < 1.0, "{where} must be in [0, 1), got {value:g}")
SOURCE = Rule(
    lambda v: v in PERCEPTION_SOURCES,
    f"{{where}} must be one of {', '.join(PERCEPTION_SOURCES)}, got {{value!r}}",
)


@dataclass(frozen=True)
class CameraConfig:
    """One simulated RGB-D camera (Drake's ``RgbdSensor``, rendered with VTK): pinhole intrinsics,
    a pose given by where it is and what it looks at, and seeded depth noise and dropout.

    Attributes:
        name: the camera's name; its world ports are ``{name}.depth_image``, ``{name}.label_image``,
            ``{name}.color_image`` and ``{name}.camera_pose``.
        width, height: image size, pixels.
        fov_y: vertical field of view, degrees (square pixels, principal point at the image centre).
        frame: "table": ``position`` and ``look_at`` are relative to the centre of the table top
            (metres along world x, y, z), so the camera follows the scene's table; "world": in the
            world frame.
        position: where the camera is, m.
        look_at: the point on the optical axis, m.
        up: the world direction the image's top points to (must not be parallel to the view; default
            3 degrees from +x, the table's far edge at the top of the image: turned so, edges along
            the table's axes cross the pixel grid and locate to a fraction of a pixel; along the
            grid they cannot: at 15 objects 94.4 % of the plans' row decisions matched the true
            scene's, turned 1-5 degrees 95.6-98.8 %, docs/perception.md).
        min_depth, max_depth: the depth sensor's range, m; nearer or further pixels have no depth.
        depth_noise: standard deviation of the Gaussian noise added to every depth pixel, m.
        dropout: fraction of depth pixels that return no depth (NaN), chosen at random.
        seed: seed of the noise and the dropout (a frame's draw also depends on its time).
    """

    name: str = "table_camera"
    width: Annotated[int, Between(8, MAX_PIXELS, "pixels")] = 640
    height: Annotated[int, Between(8, MAX_PIXELS, "pixels")] = 480
    fov_y: Annotated[float, Between(1.0, 170.0, "degrees")] = 42.0
    frame: Literal["table", "world"] = "table"
    position: Annotated[tuple[float, float, float], FINITE] = (0.0, 0.0, 1.6)
    look_at: Annotated[tuple[float, float, float], FINITE] = (0.0, 0.0, 0.0)
    up: Annotated[tuple[float, float, float], FINITE] = (1.0, 0.0524, 0.0)  # tan(3 degrees)
    min_depth: float = 0.1
    max_depth: float = 4.0
    depth_noise: Annotated[float, Between(0.0, 0.1, "m")] = 0.001
    dropout: Annotated[float, DROPOUT] = 0.01
    seed: Annotated[int, Between(0, MAX_SEED)] = 0

    def problems(self, where: str) -> list[str]:
        """The rules across the fields (``where``: the camera's path); its pose: ``Scenario.problems``."""
        problems = []
        named = name_problem(self.name) or ("name is empty" if not self.name else None)
        if named:
            problems.append(f"{where}: {named}")
        near, far = CLIPPING
        if not near <= self.min_depth < self.max_depth <= far:
            problems.append(
                f"{where}: the depth range must satisfy {near:g} <= min_depth < max_depth <= {far:g} m, "
                f"got {self.min_depth:g} and {self.max_depth:g}"
            )
        return problems


@dataclass(frozen=True)
class PerceptionConfig:
    """Where the planning blocks' ``scene`` comes from, and how ``ScenePerception`` reads it from
    depth images.

    Attributes:
        source: "truth": ``SceneFromPlant`` (the plant's true body poses); "camera": the cameras'
            depth images through ``ScenePerception`` (the simulation still runs the true scene).
        cameras: the world's cameras (default: one 640 x 480 camera 1.6 m above the table's centre,
            looking straight down).
        table_tolerance: how far a point may lie from the fitted table plane and still belong to it, m.
        min_height: points at least this far above the table plane belong to objects, m.
        cluster_radius: points closer than this in plan view belong to one object, m (at least
            1.5 pixel widths are used; objects closer than it are seen as one).
        min_points: clusters with fewer points are noise, not objects.
        cylinder_fill: a footprint filling less than this fraction of its smallest enclosing
            rectangle is a cylinder (a disc fills pi/4 = 0.785 of its square, a box all of it).
        border_margin: an object with pixels this close to the image's border (pixels) is cut off.
        table_margin: how far beyond each fitted table edge a camera must see (m), else the table
            reaches out of view.
        ransac_points: points drawn (seeded) for the RANSAC plane fit; the fit is then refined on
            all points.
        seed: seed of the RANSAC fit.
    """

    source: Annotated[PerceptionSource, SOURCE] = "truth"
    cameras: Annotated[tuple[CameraConfig, ...], First(MAX_CAMERAS)] = field(
        default_factory=lambda: (CameraConfig(),)
    )
    table_tolerance: Annotated[float, Between(1e-5, 0.1)] = 0.005
    min_height: Annotated[float, Between(1e-4, 1.0)] = 0.01
    cluster_radius: Annotated[float, Between(0.0, 0.5)] = 0.004
    min_points: Annotated[int, Between(1, 1_000_000)] = 40
    cylinder_fill: Annotated[float, Between(0.5, 1.0)] = 0.9
    border_margin: Annotated[int, Between(0, MAX_PIXELS // 2)] = 2
    table_margin: Annotated[float, Between(0.0, 1.0)] = 0.02
    ransac_points: Annotated[int, Between(3, 1_000_000)] = 1000
    seed: Annotated[int, Between(0, MAX_SEED)] = 0

    def problems(self, where: str) -> list[str]:
        """The rules across the fields and the cameras (``where``: the section's path)."""
        problems, cameras = [], self.cameras
        if self.source == "camera" and not cameras:
            problems.append(
                f"{where}.cameras is empty, but {where}.source is camera: the scene needs a camera"
            )
        if len(cameras) > MAX_CAMERAS:
            problems.append(f"{where}.cameras: at most {MAX_CAMERAS} cameras, got {len(cameras)}")
        pixels = sum(camera.width * camera.height for camera in cameras)
        if pixels > MAX_PIXELS**2:
            problems.append(f"{where}.cameras: at most {MAX_PIXELS**2} pixels in all, got {pixels}")
        names = [camera.name for camera in cameras]
        for name in sorted({n for n in names if names.count(n) > 1}):
            problems.append(f"{where}.cameras: two cameras are named {name!r}")
        return problems


__all__ = [
    "MAX_CAMERAS",
    "MAX_PIXELS",
    "OBSTACLE_LABEL",
    "PERCEPTION_SOURCES",
    "ROBOT_LABEL",
    "TABLE_LABEL",
    "TARGET_LABEL",
    "CameraConfig",
    "DepthNoise",
    "PerceptionConfig",
    "add_cameras",
    "camera_info",
    "camera_pose",
    "label_classes",
    "render_cameras",
]
