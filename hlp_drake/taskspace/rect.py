"""Axis-aligned rectangles in the table plane (world x = depth, y = lateral, + left)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Rect:
    """The rectangle x in [x_min, x_max], y in [y_min, y_max] (metres, world frame)."""

    x_min: float
    y_min: float
    x_max: float
    y_max: float

    @property
    def depth(self) -> float:
        return self.x_max - self.x_min

    @property
    def width(self) -> float:
        return self.y_max - self.y_min

    @property
    def area(self) -> float:
        return max(self.depth, 0.0) * max(self.width, 0.0)

    @property
    def center(self) -> tuple[float, float]:
        return ((self.x_min + self.x_max) / 2.0, (self.y_min + self.y_max) / 2.0)

    def overlap(self, other: Rect) -> float:
        """Area shared with ``other`` (0 when they only touch or are apart)."""
        dx = min(self.x_max, other.x_max) - max(self.x_min, other.x_min)
        dy = min(self.y_max, other.y_max) - max(self.y_min, other.y_min)
        return dx * dy if dx > 0.0 and dy > 0.0 else 0.0

    def contains(self, points: np.ndarray) -> np.ndarray:
        """Boolean mask of the (N, 2) points inside or on the boundary."""
        p = np.asarray(points, dtype=float)
        return (
            (p[:, 0] >= self.x_min)
            & (p[:, 0] <= self.x_max)
            & (p[:, 1] >= self.y_min)
            & (p[:, 1] <= self.y_max)
        )
