"""Planar footprints of scene objects (shapely geometry)."""

from __future__ import annotations

import math

import numpy as np
import shapely
from shapely.geometry import Polygon

from hlp_drake.scene.model import SceneObject

CYLINDER_SEGMENTS = 16  # quarter-circle segments used to approximate a cylinder's footprint


def footprint(obj: SceneObject) -> Polygon:
    """The object's top-down footprint in the world frame."""
    if obj.shape == "cylinder":
        return shapely.Point(obj.x, obj.y).buffer(obj.size[0] / 2.0, quad_segs=CYLINDER_SEGMENTS)
    half_x, half_y = obj.size[0] / 2.0, obj.size[1] / 2.0
    c, s = math.cos(obj.yaw), math.sin(obj.yaw)
    corners = [(-half_x, -half_y), (half_x, -half_y), (half_x, half_y), (-half_x, half_y)]
    return Polygon([(obj.x + c * u - s * v, obj.y + s * u + c * v) for u, v in corners])


def footprint_bounds(obj: SceneObject) -> tuple[float, float, float, float]:
    """(x_min, y_min, x_max, y_max) of the object's footprint (exact for cylinders)."""
    if obj.shape == "cylinder":
        r = obj.size[0] / 2.0
        return (obj.x - r, obj.y - r, obj.x + r, obj.y + r)
    half_x, half_y = obj.size[0] / 2.0, obj.size[1] / 2.0
    c, s = abs(math.cos(obj.yaw)), abs(math.sin(obj.yaw))
    ex, ey = c * half_x + s * half_y, s * half_x + c * half_y
    return (obj.x - ex, obj.y - ey, obj.x + ex, obj.y + ey)


def _sweep(b: np.ndarray, axis: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Boxes (n, 4) sorted along ``axis`` (order, sorted boxes) and, per sorted box, how many after
    it start before it ends along that axis."""
    order = np.argsort(b[:, axis], kind="stable")
    s = b[order]
    return (
        order,
        s,
        np.maximum(np.searchsorted(s[:, axis], s[:, axis + 2], side="left") - np.arange(1, len(b) + 1), 0),
    )


def overlapping_bounds(bounds: np.ndarray, margin: float = 0.0) -> np.ndarray:
    """Pairs (i, j), i < j, of the (n, 4) boxes (x_min, y_min, x_max, y_max) that overlap once
    grown by ``margin``: (k, 2), sorted. Sort and sweep along the axis that pairs up fewer boxes
    (along a row of objects, across it), so spread-out scenes cost ~n log n."""
    b = np.asarray(bounds, dtype=float).reshape(-1, 4) + np.array([-margin, -margin, margin, margin])
    n = len(b)
    order, s, count = min((_sweep(b, axis) for axis in (0, 1)), key=lambda sweep: sweep[2].sum())
    p = np.repeat(np.arange(n), count)
    q = p + 1 + np.arange(len(p)) - np.repeat(np.cumsum(count) - count, count)
    meet = np.all((s[p, :2] < s[q, 2:]) & (s[q, :2] < s[p, 2:]), axis=1)
    i, j = order[p[meet]], order[q[meet]]
    key = np.sort(np.minimum(i, j) * n + np.maximum(i, j))
    return np.column_stack([key // n, key % n])
