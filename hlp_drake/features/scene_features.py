"""Per-candidate features of a scene: gaps Xg (5 values) and obstacles Xo (7 values) (reference 4.1, 4.2)."""

from __future__ import annotations

import numpy as np

from hlp_drake.features.plane import GAP_DEPTH, paper_angle, table_diagonal
from hlp_drake.taskspace import TaskSpace, block_array, free_fractions, rect_centres

GAP_FEATURES = ("dist_start", "dist_target", "size", "angle_from_start", "angle_from_target")
OBJECT_FEATURES = (*GAP_FEATURES, "free_space", "target_overlap")


def _relative(centres: np.ndarray, start: np.ndarray, target: np.ndarray, diagonal: float) -> np.ndarray:
    """Columns 1, 2, 4, 5 of Xg/Xo: distances (normalised) and angles from the start and the target."""
    from_start, from_target = centres - start, centres - target
    return np.stack(
        [
            np.linalg.norm(from_start, axis=1) / diagonal,
            np.linalg.norm(from_target, axis=1) / diagonal,
            paper_angle(from_start),
            paper_angle(from_target),
        ],
        axis=1,
    )


def gap_features(space: TaskSpace, index: np.ndarray | None = None) -> np.ndarray:
    """Xg of every gap, rows in order (nearest row first), left to right: (n_gaps, 5); only the
    gaps ``index`` (positions in that order) if given.

    1 |c - start| / D  2 |c - target| / D  3 sqrt(w^2 + 0.05^2) / D  4 angle(c - start)
    5 angle(c - target), with c the gap centre, w its width, D the table diagonal. As in the
    original (reference 4), the start stands for the hand position for every row.
    """
    table = space.gap_table
    bounds = table.bounds if index is None else table.bounds[index]
    if len(bounds) == 0:
        return np.zeros((0, len(GAP_FEATURES)))
    diagonal = table_diagonal(space.scene.table)
    centres = rect_centres(bounds)
    widths = bounds[:, 3] - bounds[:, 1]
    rel = _relative(centres, np.asarray(space.scene.start), np.asarray(space.target.center), diagonal)
    size = np.hypot(widths, GAP_DEPTH) / diagonal
    return np.column_stack([rel[:, 0], rel[:, 1], size, rel[:, 2], rel[:, 3]])


def object_features(space: TaskSpace, index: np.ndarray | None = None) -> np.ndarray:
    """Xo of every obstacle, in scene order: (n_obstacles, 7); only the obstacles ``index``
    (positions in scene order) if given.

    Columns 1-5 as Xg with the obstacle's centre and diagonal sqrt(w^2 + d^2); 6 the mean free
    fraction of its eight direction blocks (occluders: obstacles and the four walls, not the
    target); 7 the lateral overlap of the obstacle with the target's width, / D.
    """
    rects = space.obstacle_bounds if index is None else space.obstacle_bounds[index]
    if len(rects) == 0:
        return np.zeros((0, len(OBJECT_FEATURES)))
    diagonal = table_diagonal(space.scene.table)
    centres = rect_centres(rects)
    target = space.target
    rel = _relative(centres, np.asarray(space.scene.start), np.asarray(target.center), diagonal)
    size = np.hypot(rects[:, 2] - rects[:, 0], rects[:, 3] - rects[:, 1]) / diagonal
    free = free_fractions(block_array(rects, space.alpha), space.occluder_bounds()).mean(axis=1)
    overlap = np.maximum(np.minimum(rects[:, 3], target.y_max) - np.maximum(rects[:, 1], target.y_min), 0.0)
    return np.column_stack([rel[:, 0], rel[:, 1], size, rel[:, 2], rel[:, 3], free, overlap / diagonal])
