"""Shared conventions of the feature vectors: angles and normalisers (reference section 4).

Angles are measured as in the original: in the top view, counter-clockwise from the lateral axis
pointing to the start's right (world -y), so straight ahead (+x) is pi/2. With this choice the
vectors the features use (ahead of the start, behind the target) never cross the +-pi wrap.
"""

from __future__ import annotations

import math

import numpy as np

from hlp_drake.scene.model import Table

GAP_DEPTH = 0.05  # the gap "size" feature uses the row band's depth (the original's obstacle depth)
HAND_WIDTH = 0.05  # width of the band swept by the hand along a path segment, m


def paper_angle(vectors: np.ndarray) -> np.ndarray:
    """Angle of world-plane vectors (..., 2), counter-clockwise from world -y."""
    v = np.asarray(vectors, dtype=float)
    return np.arctan2(v[..., 0], -v[..., 1])


def table_diagonal(table: Table) -> float:
    """The table top's diagonal, the distance normaliser of all features (0.95268 m in the VR study)."""
    return math.hypot(table.length, table.width)


def corner_origin(rect: np.ndarray) -> np.ndarray:
    """The original's corner-format origin of a (..., 4) rectangle: its near-left corner (x_min, y_max)."""
    r = np.asarray(rect, dtype=float)
    return np.stack([r[..., 0], r[..., 3]], axis=-1)
