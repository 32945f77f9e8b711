"""Planar footprints of scene objects (shapely geometry)."""

from __future__ import annotations

import math

import shapely
from shapely.geometry import Polygon, box

from hlp_drake.scene.model import SceneObject, Table

CYLINDER_SEGMENTS = 16  # quarter-circle segments used to approximate a cylinder's footprint


def footprint(obj: SceneObject) -> Polygon:
    """The object's top-down footprint in the world frame."""
    if obj.shape == "cylinder":
        return shapely.Point(obj.x, obj.y).buffer(obj.size[0] / 2.0, quad_segs=CYLINDER_SEGMENTS)
    half_x, half_y = obj.size[0] / 2.0, obj.size[1] / 2.0
    c, s = math.cos(obj.yaw), math.sin(obj.yaw)
    corners = [(-half_x, -half_y), (half_x, -half_y), (half_x, half_y), (-half_x, half_y)]
    return Polygon([(obj.x + c * u - s * v, obj.y + s * u + c * v) for u, v in corners])


def table_polygon(table: Table) -> Polygon:
    return box(*table.bounds)


def footprint_bounds(obj: SceneObject) -> tuple[float, float, float, float]:
    """(x_min, y_min, x_max, y_max) of the object's footprint (exact for cylinders)."""
    if obj.shape == "cylinder":
        r = obj.size[0] / 2.0
        return (obj.x - r, obj.y - r, obj.x + r, obj.y + r)
    half_x, half_y = obj.size[0] / 2.0, obj.size[1] / 2.0
    c, s = abs(math.cos(obj.yaw)), abs(math.sin(obj.yaw))
    ex, ey = c * half_x + s * half_y, s * half_x + c * half_y
    return (obj.x - ex, obj.y - ey, obj.x + ex, obj.y + ey)
