"""The world frame, and the one place where the VR data's Unity frame is converted into it.

World frame (Drake's convention): metres, radians, right-handed, **z up**. The origin is on the floor
below the middle of the table's front edge (the edge the robot or person starts at). **x** points away
from the start into the table (depth, towards the target), **y** points to the left as seen from the
start facing the target, so the robot faces +x.

Unity frame of the VR dataset: metres, degrees, left-handed; x lateral (+ = the participant's right),
y up (floor at 0), z depth (+ = away from the participant). The table's front edge is at
``z = table_center_z - table_depth / 2`` (-0.35 in every trial of the dataset).
"""

from __future__ import annotations

import numpy as np


def unity_to_world(points: np.ndarray, *, table_front_z: float, table_center_x: float = 0.0) -> np.ndarray:
    """Convert Unity positions (..., 3) in (x, y, z) order into world positions (..., 3).

    Args:
        points: Unity positions, last axis (x lateral-right, y up, z depth).
        table_front_z: Unity z of the table's front edge (becomes world x = 0).
        table_center_x: Unity x of the table's centre line (becomes world y = 0).
    """
    points = np.asarray(points, dtype=np.float64)
    if points.shape[-1] != 3:
        raise ValueError(f"expected points with 3 coordinates, got shape {points.shape}")
    world = np.empty_like(points)
    world[..., 0] = points[..., 2] - table_front_z
    world[..., 1] = table_center_x - points[..., 0]
    world[..., 2] = points[..., 1]
    return world


def unity_yaw_to_world(rot_y_deg: np.ndarray | float) -> np.ndarray | float:
    """Unity rotation about its up axis (degrees, clockwise seen from above) -> world yaw (radians).

    The result is wrapped to (-pi, pi].
    """
    yaw = -np.radians(rot_y_deg)
    return np.pi - np.mod(np.pi - yaw, 2.0 * np.pi)
