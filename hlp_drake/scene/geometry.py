"""Planar footprints of scene objects (shapely geometry)."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import shapely
from shapely.geometry import Polygon

from hlp_drake.scene.model import SceneObject

CYLINDER_SEGMENTS = 16  # quarter-circle segments used to approximate a cylinder's footprint
_CORNERS = np.array([(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)])  # a box's, counter-clockwise


def footprint(obj: SceneObject) -> Polygon:
    """The object's top-down footprint in the world frame."""
    return footprints([obj])[0]


def footprints(objects: Sequence[SceneObject]) -> np.ndarray:
    """The footprints of ``objects`` as an array of polygons (built in bulk: cylinders as buffered
    points, boxes from their rotated corners)."""
    shapes = np.empty(len(objects), dtype=object)
    cylinders = np.array([obj.shape == "cylinder" for obj in objects], dtype=bool)
    if cylinders.any():
        round_ = [obj for obj, c in zip(objects, cylinders) if c]
        points = shapely.points([(obj.x, obj.y) for obj in round_])
        radii = np.array([obj.size[0] / 2.0 for obj in round_])
        shapes[cylinders] = shapely.buffer(points, radii, quad_segs=CYLINDER_SEGMENTS)
    if not cylinders.all():
        boxes = [obj for obj, c in zip(objects, cylinders) if not c]
        x, y = (np.array([getattr(obj, k) for obj in boxes], dtype=float) for k in ("x", "y"))
        half = np.array([(obj.size[0] / 2.0, obj.size[1] / 2.0) for obj in boxes], dtype=float)
        c = np.array([math.cos(obj.yaw) for obj in boxes])[:, None]  # math's, as everywhere else
        s = np.array([math.sin(obj.yaw) for obj in boxes])[:, None]
        u, v = half[:, :1] * _CORNERS[:, 0], half[:, 1:] * _CORNERS[:, 1]
        corners = np.stack([x[:, None] + c * u - s * v, y[:, None] + s * u + c * v], axis=-1)
        shapes[~cylinders] = shapely.polygons(corners)
    return shapes


def footprint_bounds(obj: SceneObject) -> tuple[float, float, float, float]:
    """(x_min, y_min, x_max, y_max) of the object's footprint (exact for cylinders)."""
    if obj.shape == "cylinder":
        r = obj.size[0] / 2.0
        return (obj.x - r, obj.y - r, obj.x + r, obj.y + r)
    half_x, half_y = obj.size[0] / 2.0, obj.size[1] / 2.0
    c, s = abs(math.cos(obj.yaw)), abs(math.sin(obj.yaw))
    ex, ey = c * half_x + s * half_y, s * half_x + c * half_y
    return (obj.x - ex, obj.y - ey, obj.x + ex, obj.y + ey)
