"""Path-segment features Xc between a node of one row and a node of the next (reference 4.4)."""

from __future__ import annotations

import numpy as np

from hlp_drake.features.plane import HAND_WIDTH, paper_angle, table_diagonal
from hlp_drake.segmentation.modes import Mode, is_faithful
from hlp_drake.taskspace import Node, Rect, TaskSpace, rect_array
from hlp_drake.taskspace.band import band_coverage, band_coverage_sampled

SEGMENT_FEATURES = ("lateral_span", "slope_difference", "band_collision", "target_overlap")
TARGET_BAND = 0.05  # half-width of the lateral window around the target (the original uses 0.05)


def _misread_wall(wall: Rect) -> Rect:
    """Bug B3: the original passes a wall's corner-format rectangle where a centre format is read,
    so the wall is centred on its near-left corner."""
    hd, hw = wall.depth / 2.0, wall.width / 2.0
    return Rect(wall.x_min - hd, wall.y_max - hw, wall.x_min + hd, wall.y_max + hw)


PATH_WALLS = ("back", "left", "right")  # the front wall is not an occluder of hand or arm paths


def path_occluders(space: TaskSpace, *, faithful: bool) -> np.ndarray:
    """(n_obstacles + 3, 4): every obstacle (scene order), then the back, left and right walls
    (misplaced as the original does, bug B3, in faithful mode)."""
    walls = [space.walls[w] for w in PATH_WALLS]
    walls = [_misread_wall(w) for w in walls] if faithful else walls
    return np.vstack([space.obstacle_bounds, rect_array(walls)])


def segment_feature_matrix(
    space: TaskSpace, near: list[Node], far: list[Node], *, mode: Mode, training: bool = False
) -> np.ndarray:
    """Xc of every pair (a in ``near``, b in ``far``), a-major: (len(near) * len(far), 4).

    1 lateral span |b_y - a_y| / N; 2 the segment's lateral-per-depth slope minus the start-target
    line's; 3 the collision of a 5 cm band around the segment with the obstacles (without a's and
    b's own) and the back, left and right walls; 4 the lateral overlap of the segment with the
    target's +-0.05 m window, / N. N is the table diagonal, except in faithful training where the
    original divides by the table width (bug B1). The band is exact (shapely, true normal) in fixed
    mode and the original's sampled estimate, with its tilted offset vector (B5) and misplaced
    walls (B3), in faithful mode.
    """
    return pair_features(space, *node_pairs(space, near, far), mode=mode, training=training)


def node_pairs(space: TaskSpace, near: list[Node], far: list[Node]) -> tuple[np.ndarray, ...]:
    """The arguments ``pa, pb, own_a, own_b`` of ``pair_features`` for every pair (a in ``near``,
    b in ``far``), a-major."""
    a, b = (np.array([n.center for n in nodes], float).reshape(-1, 2) for nodes in (near, far))
    own_a, own_b = (
        np.array([-1 if n.obstacle is None else space.obstacle_index[n.obstacle] for n in nodes], dtype=int)
        for nodes in (near, far)
    )
    return (
        np.repeat(a, len(far), axis=0),
        np.tile(b, (len(near), 1)),
        np.repeat(own_a, len(far)),
        np.tile(own_b, len(near)),
    )


def pair_features(
    space: TaskSpace,
    pa: np.ndarray,
    pb: np.ndarray,
    own_a: np.ndarray,
    own_b: np.ndarray,
    *,
    mode: Mode,
    training: bool = False,
) -> np.ndarray:
    """Xc of the segments pa[i] -> pb[i] (see ``segment_feature_matrix``): (n, 4).

    Args:
        pa, pb: (n, 2) segment ends (node centres).
        own_a, own_b: (n,) the ends' obstacles (positions in scene order; -1 for a gap), which are
            not occluders of their segment.
    """
    faithful = is_faithful(mode)
    table = space.scene.table
    norm = table.width if (faithful and training) else table_diagonal(table)
    start, target = np.asarray(space.scene.start, float), np.asarray(space.target.center, float)
    d = pb - pa
    # Lateral coordinates grow to the right (-y), as the original's x does.
    span = np.abs(d[:, 1]) / norm
    slope = -d[:, 1] / d[:, 0] - (-(target[1] - start[1])) / (target[0] - start[0])
    rects = path_occluders(space, faithful=faithful)
    half = HAND_WIDTH / 2.0
    if faithful:
        theta = paper_angle(d)
        offsets = np.column_stack([np.cos(theta), -np.sin(theta)])  # the original's (sin, cos) in its frame
        coverage = band_coverage_sampled(pa, pb, offsets, half, half, rects)
    else:
        length = np.linalg.norm(d, axis=1, keepdims=True)
        offsets = np.column_stack([-d[:, 1], d[:, 0]]) / np.where(length > 0.0, length, 1.0)
        coverage = band_coverage(pa, pb, offsets, half, half, rects)
    own = np.zeros_like(coverage, dtype=bool)
    pairs = np.arange(len(pa))
    for ends in (own_a, own_b):
        own[pairs[ends >= 0], ends[ends >= 0]] = True
    collision = np.where(own, 0.0, coverage).sum(axis=1) / (~own).sum(axis=1)
    lateral_a, lateral_b, lateral_t = -pa[:, 1], -pb[:, 1], -target[1]
    low, high = np.minimum(lateral_a, lateral_b), np.maximum(lateral_a, lateral_b)
    overlap = np.maximum(
        np.minimum(high, lateral_t + TARGET_BAND) - np.maximum(low, lateral_t - TARGET_BAND), 0.0
    )
    return np.column_stack([span, slope, collision, overlap / norm])


def segment_features(space: TaskSpace, a: Node, b: Node, *, mode: Mode, training: bool = False) -> np.ndarray:
    """Xc of the hand moving from node ``a`` to node ``b``: (4,). See ``segment_feature_matrix``."""
    return segment_feature_matrix(space, [a], [b], mode=mode, training=training)[0]
