"""The geometry of one row for the row-choice features: the hand's line to the target across it, each
gap's passage and each obstacle's overlap with the hand's corridor, the free space, and the nearest
candidates of a row to a line (``hlp_drake.features.row_choice``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hlp_drake.scene.lazy import LazyRows
from hlp_drake.taskspace import TaskSpace, free_fractions, rect_array
from hlp_drake.taskspace.model import table_walls

CAP = 10.0  # lengths in hand widths saturate here: a gap ten hands wide is as open as a wider one


def line_at(hand: np.ndarray, goal: np.ndarray, x: float) -> np.ndarray:
    """Lateral position at depth ``x`` of the line from each hand (..., 2) to ``goal`` (the goal's
    own where the two share a depth)."""
    hand = np.asarray(hand, float)
    span = goal[0] - hand[..., 0]
    flat = np.abs(span) < 1e-9
    return np.where(
        flat,
        goal[1],
        hand[..., 1] + (x - hand[..., 0]) * (goal[1] - hand[..., 1]) / np.where(flat, 1.0, span),
    )


def passage(y_min: np.ndarray, y_max: np.ndarray, line: np.ndarray, width: float) -> np.ndarray:
    """Lateral point of each interval nearest ``line`` (broadcast) where a hand ``width`` wide
    fits; the interval's middle where it does not."""
    fits = y_max - y_min >= width
    low = np.where(fits, y_min + width / 2.0, (y_min + y_max) / 2.0)
    high = np.where(fits, y_max - width / 2.0, low)
    return np.minimum(np.maximum(line, low), high)  # np.clip's values, at half its cost


def corridor_overlap(y_min: np.ndarray, y_max: np.ndarray, line: np.ndarray, width: float) -> np.ndarray:
    """Lateral overlap (m) of intervals with the hand's corridor ``line`` +- width / 2 (broadcast)."""
    return np.maximum(np.minimum(y_max, line + width / 2.0) - np.maximum(y_min, line - width / 2.0), 0.0)


@dataclass(frozen=True, eq=False)
class RowGeometry:
    """What a row offers, whoever looks at it: its gaps and its obstacles, left to right."""

    x: float
    gap_rows: np.ndarray  # positions in the gap table
    gaps: np.ndarray  # (G, 4)
    at_edge: np.ndarray  # (G,) whether a gap is bounded by the table's edge
    members: np.ndarray  # obstacle positions in scene order
    obstacles: np.ndarray  # (M, 4)

    @classmethod
    def of(cls, space: TaskSpace, row: int) -> RowGeometry:
        """Row ``row`` of ``space``."""
        r = space.rows[row - 1]
        table = space.gap_table
        gap_rows = np.flatnonzero(table.row == row)
        at_edge = np.array([table.left[k] is None or table.right[k] is None for k in gap_rows], dtype=float)
        members = np.array([space.obstacle_index[n] for n in r.members], dtype=int)
        return cls(
            r.x,
            gap_rows,
            table.bounds[gap_rows],
            at_edge,
            members,
            space.obstacle_bounds[members],
        )

    def best(
        self, hands: np.ndarray, goal: np.ndarray, width: float
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per hand (..., 2): (the smallest offset of a gap where the hand fits, that gap's width,
        the obstacles' overlap with the hand's corridor), m, at the row's depth."""
        line = line_at(hands, goal, self.x)[..., None]
        block = corridor_overlap(self.obstacles[:, 1], self.obstacles[:, 3], line, width).sum(axis=-1)
        widths = self.gaps[:, 3] - self.gaps[:, 1]
        open_ = widths >= width
        if not open_.any():
            return np.full(line.shape[:-1], CAP * width), np.zeros(line.shape[:-1]), block
        offsets = np.abs(passage(self.gaps[open_, 1], self.gaps[open_, 3], line, width) - line)
        return offsets.min(axis=-1), widths[open_][np.argmin(offsets, axis=-1)], block


def free_space(space: TaskSpace) -> LazyRows:
    """(n, 8) the free fraction of each obstacle's eight direction blocks in the scene as set up,
    each obstacle's computed when first asked for: the other obstacles and the target occlude, and
    so does everything off the table, however far a block reaches past its edge (walls as thick as
    the table's diagonal)."""
    walls = rect_array(list(table_walls(space.scene.table.bounds, space.scene.table.diagonal).values()))
    occluders = np.vstack([space.obstacle_bounds, rect_array([space.target]), walls])
    blocks = space.obstacle_blocks
    return LazyRows(len(blocks), lambda index: free_fractions(blocks[index], occluders).reshape(-1, 8))


def nearest_candidates(
    geometry: RowGeometry, lines: np.ndarray, width: float, limit: int | None
) -> tuple[list[set[int]], list[set[int]]]:
    """Per hand (its line's lateral position at the row): the row's gaps and obstacles to describe,
    the ``limit`` of each kind laterally nearest the line (all if None)."""
    gaps, obstacles = len(geometry.gaps), len(geometry.obstacles)
    if limit is None or (gaps <= limit and obstacles <= limit):
        return [set(range(gaps))] * len(lines), [set(range(obstacles))] * len(lines)
    gb, ob = geometry.gaps, geometry.obstacles
    gap_offset = np.abs(passage(gb[:, 1], gb[:, 3], lines[:, None], width) - lines[:, None])
    obj_offset = np.abs((ob[:, 1] + ob[:, 3])[None] / 2.0 - lines[:, None])
    return (
        [set(np.argsort(o, kind="stable")[:limit].tolist()) for o in gap_offset],
        [set(np.argsort(o, kind="stable")[:limit].tolist()) for o in obj_offset],
    )


def candidate_points(
    geometry: RowGeometry, gap_union: list[int], obj_union: list[int], line: np.ndarray, width: float
) -> np.ndarray:
    """(B, n, 2) where each hand, whose line to the target is at ``line`` (B,) at the row's depth,
    goes through the row's gaps ``gap_union`` (``passage``) and to its obstacles ``obj_union``
    (their centres); positions in the row, gaps first."""
    gb, ob = geometry.gaps[gap_union], geometry.obstacles[obj_union]
    n_gaps = len(gb)
    points = np.empty((len(line), n_gaps + len(ob), 2))
    points[:, :n_gaps, 0] = geometry.x
    points[:, :n_gaps, 1] = passage(gb[:, 1], gb[:, 3], line[:, None], width)
    points[:, n_gaps:] = np.column_stack([(ob[:, 0] + ob[:, 2]) / 2.0, (ob[:, 1] + ob[:, 3]) / 2.0])[None]
    return points
