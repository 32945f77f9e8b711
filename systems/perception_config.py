"""The scenario's ``perception`` section: where the planning blocks' scene comes from, the cameras and
the settings of ``ScenePerception``.

A scenario file gives only what it changes::

    perception:
      source: camera                 # truth (the plant's body poses, the default) or camera
      cameras:                       # the world's RGB-D cameras (default: one above the table)
      - {name: table_camera, position: [0.0, 0.0, 1.6], depth_noise: 0.002, dropout: 0.05, seed: 3}
      cluster_radius: 0.005
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

PERCEPTION_SOURCES = ("truth", "camera")


@dataclass(frozen=True)
class CameraSettings:
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
    width: int = 640
    height: int = 480
    fov_y: float = 42.0
    frame: Literal["table", "world"] = "table"
    position: tuple[float, float, float] = (0.0, 0.0, 1.6)
    look_at: tuple[float, float, float] = (0.0, 0.0, 0.0)
    up: tuple[float, float, float] = (1.0, 0.0524, 0.0)  # tan(3 degrees)
    min_depth: float = 0.1
    max_depth: float = 4.0
    depth_noise: float = 0.001
    dropout: float = 0.01
    seed: int = 0


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

    source: Literal["truth", "camera"] = "truth"
    cameras: tuple[CameraSettings, ...] = field(default_factory=lambda: (CameraSettings(),))
    table_tolerance: float = 0.005
    min_height: float = 0.01
    cluster_radius: float = 0.004
    min_points: int = 40
    cylinder_fill: float = 0.9
    border_margin: int = 2
    table_margin: float = 0.02
    ransac_points: int = 1000
    seed: int = 0


__all__ = ["PERCEPTION_SOURCES", "CameraSettings", "PerceptionConfig"]
