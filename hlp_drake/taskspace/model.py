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
WALLS = ("back", "left", "right", "front")


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


@dataclass(frozen=True)
class Node:
    """A candidate of a row the hand can use: one of its gaps, or one of its obstacles to move.

    Attributes:
        row: the row index.
        kind: "gap" or "object".
        center: (x, y) of the gap's or the obstacle's footprint centre.
        gap: the gap's index in its row (gaps only).
        obstacle: the obstacle's name (objects only).
    """

    row: int
    kind: str
    center: tuple[float, float]
    gap: int | None = None
    obstacle: str | None = None

    @property
    def element(self) -> str:
        return self.obstacle if self.kind == "object" else str(self.gap)


@dataclass(frozen=True, eq=False)
class GapTable:
    """Every gap of a task space as arrays (the fields of ``Gap``), rows in order, left to right."""

    row: np.ndarray
    index: np.ndarray
    bounds: np.ndarray
    left: tuple[str | None, ...]
    right: tuple[str | None, ...]

    @property
    def centers(self) -> np.ndarray:
        """(n, 2) centres, as ``Rect.center``."""
        return rect_centres(self.bounds)


def rect_centres(bounds: np.ndarray) -> np.ndarray:
    """(n, 2) centres of an (n, 4) rectangle array, as ``Rect.center``."""
    return np.column_stack([(bounds[:, 0] + bounds[:, 2]) / 2.0, (bounds[:, 1] + bounds[:, 3]) / 2.0])


def rect_array(rects: list[Rect] | tuple[Rect, ...]) -> np.ndarray:
    """(n, 4) array of (x_min, y_min, x_max, y_max)."""
    return np.array([(r.x_min, r.y_min, r.x_max, r.y_max) for r in rects], dtype=float).reshape(-1, 4)


def overlap_areas(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Overlap areas of rectangle arrays ``a`` (..., 4) and ``b`` (..., 4), broadcast."""
    dx = np.minimum(a[..., 2], b[..., 2]) - np.maximum(a[..., 0], b[..., 0])
    dy = np.minimum(a[..., 3], b[..., 3]) - np.maximum(a[..., 1], b[..., 1])
    return np.maximum(dx, 0.0) * np.maximum(dy, 0.0)


# Per direction (order DIRECTIONS): which of (x_min, x_max, x_max + alpha*depth, x_min - alpha*depth)
# bounds a block along x, and likewise along y.
_BLOCK_X = {1: (1, 2), 0: (0, 1), -1: (3, 0)}
_BLOCK_INDEX = np.array(
    [[*_BLOCK_X[DIRECTION_VECTORS[n][0]], *_BLOCK_X[DIRECTION_VECTORS[n][1]]] for n in DIRECTIONS]
)


def block_array(rects: np.ndarray, alpha: float = ALPHA) -> np.ndarray:
    """(n, 8, 4) direction blocks (order DIRECTIONS) around each of the (n, 4) rectangles."""
    r = np.asarray(rects, dtype=float).reshape(-1, 4)
    d = alpha * (r[:, 2] - r[:, 0])
    w = alpha * (r[:, 3] - r[:, 1])
    xs = np.stack([r[:, 0], r[:, 2], r[:, 2] + d, r[:, 0] - d], axis=1)
    ys = np.stack([r[:, 1], r[:, 3], r[:, 3] + w, r[:, 1] - w], axis=1)
    i = _BLOCK_INDEX
    return np.stack([xs[:, i[:, 0]], ys[:, i[:, 2]], xs[:, i[:, 1]], ys[:, i[:, 3]]], axis=-1)


def direction_blocks(rect: Rect, alpha: float = ALPHA) -> dict[str, Rect]:
    """The eight regions around ``rect``, each touching it; cardinal ones keep its side's extent."""
    blocks = block_array(rect_array([rect]), alpha)[0]
    return {name: Rect(*map(float, b)) for name, b in zip(DIRECTIONS, blocks)}


def free_fractions(blocks: np.ndarray, occluders: np.ndarray) -> np.ndarray:
    """Per block: 1 - (sum of overlap areas with the occluders) / block area (original 2.4).

    Args:
        blocks: (..., 4) rectangles, e.g. the (n, 8, 4) output of ``block_array``.
        occluders: (m, 4) rectangles.

    Overlaps are summed, not merged, as in the original; with non-overlapping occluders (valid
    scenes) the two agree.
    """
    blocks = np.asarray(blocks, dtype=float)
    occupied = overlap_areas(blocks[..., None, :], np.asarray(occluders, dtype=float)).sum(axis=-1)
    area = (blocks[..., 2] - blocks[..., 0]) * (blocks[..., 3] - blocks[..., 1])
    return 1.0 - occupied / area


def table_walls(bounds: tuple[float, float, float, float], thickness: float) -> dict[str, Rect]:
    """The four virtual walls just outside the table's edges (back, left, right, front; they do not
    overlap each other)."""
    x0, y0, x1, y1 = bounds
    t = thickness
    return {
        "back": Rect(x1, y0 - t, x1 + t, y1 + t),
        "left": Rect(x0, y1, x1, y1 + t),
        "right": Rect(x0, y0 - t, x1, y0),
        "front": Rect(x0 - t, y0 - t, x0, y1 + t),
    }


class TaskSpace:
    """The qualitative model of a scene (reference section 2), in the world frame.

    Args:
        scene: a valid scene.
        alpha: scale of the direction blocks.
        row_tolerance: see ``find_rows``.
        wall_thickness: thickness of the virtual walls outside the table edges.
    """

    def __init__(
        self,
        scene: Scene,
        *,
        alpha: float = ALPHA,
        row_tolerance: float | None = None,
        wall_thickness: float = WALL_THICKNESS,
    ) -> None:
        self.scene = scene
        self.alpha = alpha
        bounds = {o.name: footprint_bounds(o) for o in scene.objects}
        self.rows: list[Row] = find_rows(scene, row_tolerance, bounds)
        self.rects: dict[str, Rect] = {name: Rect(*b) for name, b in bounds.items()}
        self.walls: dict[str, Rect] = table_walls(scene.table.bounds, wall_thickness)

    @property
    def target(self) -> Rect:
        return self.rects[self.scene.target.name]

    @property
    def obstacle_names(self) -> list[str]:
        return [o.name for o in self.scene.obstacles]

    @cached_property
    def obstacle_bounds(self) -> np.ndarray:
        """(n_obstacles, 4) rectangles of the obstacles, in scene order."""
        return rect_array([self.rects[n] for n in self.obstacle_names])

    @cached_property
    def obstacle_centres(self) -> np.ndarray:
        """(n_obstacles, 2) centres of the obstacles, in scene order."""
        return rect_centres(self.obstacle_bounds)

    @cached_property
    def obstacle_blocks(self) -> np.ndarray:
        """(n_obstacles, 8, 4) the direction blocks of the obstacles (``block_array``), in scene order
        (a few array operations for all of them, however many)."""
        return block_array(self.obstacle_bounds, self.alpha)

    @cached_property
    def relocated(self) -> np.ndarray:
        """(n_obstacles, 8, 4) per obstacle (scene order) the regions it is pushed into, per
        direction (``relocation.relocated_array``)."""
        from hlp_drake.taskspace.relocation import relocated_array  # relocation builds on this module

        return relocated_array(self.obstacle_bounds, self.alpha, blocks=self.obstacle_blocks)

    @cached_property
    def obstacle_index(self) -> dict[str, int]:
        """Each obstacle's position in scene order."""
        return {n: i for i, n in enumerate(self.obstacle_names)}

    @cached_property
    def obstacle_rows(self) -> np.ndarray:
        """(n_obstacles,) row index of each obstacle, in scene order."""
        rows = np.zeros(len(self.obstacle_index), dtype=int)
        for row in self.rows:
            rows[[self.obstacle_index[n] for n in row.members]] = row.index
        return rows

    @cached_property
    def gap_table(self) -> GapTable:
        """Every gap as arrays, rows in order (nearest first), left to right; empty intervals skipped."""
        y_left, y_right = self.scene.table.width / 2.0, -self.scene.table.width / 2.0
        row, index, bounds, left, right = [], [], [], [], []
        for r in self.rows:
            edges: list[tuple[float, str | None]] = [(y_left, None)]
            for name in r.members:  # left to right
                rect = self.rects[name]
                edges += [(rect.y_max, name), (rect.y_min, name)]
            edges.append((y_right, None))
            count = 0
            for (y_hi, name_left), (y_lo, name_right) in zip(edges[0::2], edges[1::2]):
                if y_hi - y_lo > 0.0:
                    count += 1
                    row.append(r.index)
                    index.append(count)
                    bounds.append((r.x_min, y_lo, r.x_max, y_hi))
                    left.append(name_left)
                    right.append(name_right)
        return GapTable(
            np.array(row, dtype=int),
            np.array(index, dtype=int),
            np.array(bounds, dtype=float).reshape(-1, 4),
            tuple(left),
            tuple(right),
        )

    @cached_property
    def gaps(self) -> list[list[Gap]]:
        """Gaps per row (list index = row index - 1), left to right; empty intervals are skipped."""
        table = self.gap_table
        result: list[list[Gap]] = [[] for _ in self.rows]
        for k, (row, index) in enumerate(zip(table.row.tolist(), table.index.tolist())):
            rect = Rect(*table.bounds[k].tolist())
            result[row - 1].append(Gap(row, index, rect, table.left[k], table.right[k]))
        return result

    def nodes(self, row: int) -> list[Node]:
        """Row ``row``'s candidates: its gaps left to right, then its obstacles in scene order."""
        members = set(self.rows[row - 1].members)
        gaps = [Node(row, "gap", gap.center, gap=gap.index) for gap in self.gaps[row - 1]]
        objects = [
            Node(row, "object", self.rects[n].center, obstacle=n) for n in self.obstacle_names if n in members
        ]
        return gaps + objects

    def connecting_space(self, row: int) -> Rect:
        """The free band between row ``row`` and row ``row + 1`` across the table."""
        near, far = self.rows[row - 1], self.rows[row]
        half = self.scene.table.width / 2.0
        return Rect(near.x_max, -half, far.x_min, half)

    def blocks(self, name: str) -> dict[str, Rect]:
        """The eight direction blocks around object ``name``."""
        return direction_blocks(self.rects[name], self.alpha)

    def occluder_bounds(self, *, target: bool = False, walls: tuple[str, ...] = WALLS) -> np.ndarray:
        """(m, 4) bounds of the obstacles (and of the target, and of the named walls)."""
        extra = ([self.target] if target else []) + [self.walls[w] for w in walls]
        return np.vstack([self.obstacle_bounds, rect_array(extra)])

    def free_space(self, name: str) -> np.ndarray:
        """Free fraction of each direction block of ``name`` (order ``DIRECTIONS``), the obstacles and
        the four walls occluding."""
        blocks = block_array(rect_array([self.rects[name]]), self.alpha)[0]
        return free_fractions(blocks, self.occluder_bounds())
