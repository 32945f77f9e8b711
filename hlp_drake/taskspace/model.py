"""The qualitative task space of a scene: rows, gaps, virtual walls, direction blocks, free space."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from hlp_drake.scene.geometry import footprint_bounds
from hlp_drake.scene.model import Scene
from hlp_drake.scene.rows import Row, find_rows
from hlp_drake.taskspace.directions import DIRECTION_VECTORS, DIRECTIONS
from hlp_drake.taskspace.rect import Rect

ALPHA = 1.5  # scaling factor of the direction blocks (the original's scaling_factor)
WALL_THICKNESS = 0.05  # virtual walls just outside the table edges, m


@dataclass(frozen=True)
class Gap:
    """Free lateral interval of a row, between two obstacles or an obstacle and a table edge.

    Attributes:
        row: row index (1 = nearest the start).
        index: 1-based within the row, counted from the left as seen from the start.
        rect: the gap's rectangle (the row's depth band x its lateral interval).
        left, right: the neighbouring obstacle names, None for a table edge.
    """

    row: int
    index: int
    rect: Rect
    left: str | None
    right: str | None

    @property
    def center(self) -> tuple[float, float]:
        return self.rect.center

    @property
    def width(self) -> float:
        return self.rect.width


def direction_blocks(rect: Rect, alpha: float = ALPHA) -> dict[str, Rect]:
    """The eight regions around ``rect``, each touching it; cardinal ones keep its side's extent."""
    d, w = alpha * rect.depth, alpha * rect.width
    x_ranges = {1: (rect.x_max, rect.x_max + d), 0: (rect.x_min, rect.x_max), -1: (rect.x_min - d, rect.x_min)}
    y_ranges = {1: (rect.y_max, rect.y_max + w), 0: (rect.y_min, rect.y_max), -1: (rect.y_min - w, rect.y_min)}
    blocks = {}
    for name in DIRECTIONS:
        sx, sy = DIRECTION_VECTORS[name]
        (x0, x1), (y0, y1) = x_ranges[sx], y_ranges[sy]
        blocks[name] = Rect(x0, y0, x1, y1)
    return blocks


def free_fractions(regions: dict[str, Rect] | list[Rect], occluders: list[Rect]) -> np.ndarray:
    """Per region: 1 - (sum of overlap areas with ``occluders``) / region area (original 2.4).

    Overlaps are summed, not merged, as in the original; with non-overlapping occluders (valid
    scenes) the two agree.
    """
    values = regions.values() if isinstance(regions, dict) else regions
    return np.array([1.0 - sum(r.overlap(o) for o in occluders) / r.area for r in values])


class TaskSpace:
    """The qualitative model of a scene (reference section 2), in the world frame.

    Args:
        scene: a valid scene.
        alpha: scale of the direction blocks.
        row_tolerance: see ``find_rows``.
        wall_thickness: thickness of the virtual walls outside the table edges.
    """

    def __init__(self, scene: Scene, *, alpha: float = ALPHA, row_tolerance: float | None = None,
                 wall_thickness: float = WALL_THICKNESS) -> None:
        self.scene = scene
        self.alpha = alpha
        self.rows: list[Row] = find_rows(scene, row_tolerance)
        self.rects: dict[str, Rect] = {o.name: Rect(*footprint_bounds(o)) for o in scene.objects}
        x0, y0, x1, y1 = scene.table.bounds
        t = wall_thickness
        self.walls: dict[str, Rect] = {
            "back": Rect(x1, y0 - t, x1 + t, y1 + t),
            "left": Rect(x0, y1, x1, y1 + t),
            "right": Rect(x0, y0 - t, x1, y0),
            "front": Rect(x0 - t, y0 - t, x0, y1 + t),
        }

    @property
    def target(self) -> Rect:
        return self.rects[self.scene.target.name]

    @property
    def obstacle_names(self) -> list[str]:
        return [o.name for o in self.scene.obstacles]

    @cached_property
    def gaps(self) -> list[list[Gap]]:
        """Gaps per row (list index = row index - 1), left to right; empty intervals are skipped."""
        y_left, y_right = self.scene.table.width / 2.0, -self.scene.table.width / 2.0
        result = []
        for row in self.rows:
            edges: list[tuple[float, str | None]] = [(y_left, None)]
            for name in row.members:  # left to right
                rect = self.rects[name]
                edges += [(rect.y_max, name), (rect.y_min, name)]
            edges.append((y_right, None))
            gaps = []
            for (y_hi, left), (y_lo, right) in zip(edges[0::2], edges[1::2]):
                if y_hi - y_lo > 0.0:
                    rect = Rect(row.x_min, y_lo, row.x_max, y_hi)
                    gaps.append(Gap(row.index, len(gaps) + 1, rect, left, right))
            result.append(gaps)
        return result

    def connecting_space(self, row: int) -> Rect:
        """The free band between row ``row`` and row ``row + 1`` across the table."""
        near, far = self.rows[row - 1], self.rows[row]
        half = self.scene.table.width / 2.0
        return Rect(near.x_max, -half, far.x_min, half)

    def blocks(self, name: str) -> dict[str, Rect]:
        """The eight direction blocks around object ``name``."""
        return direction_blocks(self.rects[name], self.alpha)

    def occluders(self, *, target: bool = False, walls: tuple[str, ...] = ("back", "left", "right", "front"),
                  exclude: tuple[str, ...] = ()) -> list[Rect]:
        """Obstacle rectangles (and the target's, and the named walls), minus ``exclude``."""
        names = [n for n in self.obstacle_names if n not in exclude]
        if target:
            names.append(self.scene.target.name)
        return [self.rects[n] for n in names] + [self.walls[w] for w in walls]

    def free_space(self, name: str, occluders: list[Rect] | None = None) -> np.ndarray:
        """Free fraction of each direction block of ``name`` (order ``DIRECTIONS``)."""
        return free_fractions(self.blocks(name), self.occluders() if occluders is None else occluders)
