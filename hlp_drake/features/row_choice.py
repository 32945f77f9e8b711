"""Row-choice features Xr: every candidate of a row seen from the hand on its way to the target.

The candidates of a row are its gaps and its obstacles. Each is described from where the hand is
(the previous keypoint: the start, the passage through the previous row, or the release of the
obstacle moved there) towards the target, in quantities that mean the same on any table: lengths
in hand widths, angles, and ratios of route lengths. Nothing depends on the table's absolute size
or on where the rows lie on it, so a model trained on the 0.74 m VR table describes a 1.3 m robot
table, any number of rows and any layout the same way.

Route features come from ``FreeRoutes``: the shortest way of the hand to the target among the
obstacles (grown by half the hand's width), through a gap, or with an obstacle moved away.
"""

from __future__ import annotations

from collections.abc import Collection, Sequence
from dataclasses import dataclass

import numpy as np

from hlp_drake.taskspace import TaskSpace, block_array, free_fractions
from hlp_drake.taskspace.routes import FreeRoutes, segment_hits, segment_inside

HUMAN_HAND_WIDTH = 0.05  # m: the VR study's hand (the original's hand_width)
CAP = 10.0  # lengths in hand widths saturate here: a gap ten hands wide is as open as a wider one
ROUTE_CAP = 3.0  # route length ratios saturate here (and stand for "no route")
ROW_CHOICE_FEATURES = (
    "is_object", "size", "depth", "offset", "signed_offset", "offset_angle", "offset_beyond_best",
    "at_table_edge", "corridor_overlap", "free_space", "free_sideways", "approach_collision",
    "route_via", "route_gain",
    "row_best_offset", "row_best_angle", "row_best_width", "row_corridor_block", "row_members", "progress",
    "route_detour", "next_best_offset", "next_corridor_block",
)  # fmt: skip


@dataclass(frozen=True, eq=False)
class RowCandidates:
    """The candidates of one row from one hand position, and their features.

    Attributes:
        row: the row index.
        kinds: (n,) "gap" or "object".
        gaps: (n,) the gap's index in its row (from 1, left to right); 0 for obstacles.
        obstacles: (n,) the obstacle's position in scene order; -1 for gaps. Gaps come first, then
            obstacles, each kind from left to right.
        points: (n, 2) where the hand goes: the point of the gap nearest the hand's line to the
            target where the hand fits (the gap's middle if it does not), or the obstacle's centre.
        X: (n, len(ROW_CHOICE_FEATURES)) features.
    """

    row: int
    kinds: tuple[str, ...]
    gaps: np.ndarray
    obstacles: np.ndarray
    points: np.ndarray
    X: np.ndarray

    def __len__(self) -> int:
        return len(self.kinds)

    def element(self, k: int, names: list[str]) -> str:
        """Candidate ``k`` as a plan element: the gap index as text or the obstacle's name."""
        return names[self.obstacles[k]] if self.kinds[k] == "object" else str(int(self.gaps[k]))


def line_at(hand: np.ndarray, goal: np.ndarray, x: float) -> np.ndarray:
    """Lateral position at depth ``x`` of the line from each hand (..., 2) to ``goal`` (the goal's
    own where the two share a depth)."""
    hand = np.asarray(hand, float)
    span = goal[0] - hand[..., 0]
    flat = np.abs(span) < 1e-9
    return np.where(flat, goal[1], hand[..., 1] + (x - hand[..., 0]) * (goal[1] - hand[..., 1]) / np.where(flat, 1.0, span))


def _passage(y_min: np.ndarray, y_max: np.ndarray, line: np.ndarray, width: float) -> np.ndarray:
    """Lateral point of each interval nearest ``line`` (broadcast) where a hand ``width`` wide
    fits; the interval's middle where it does not."""
    fits = y_max - y_min >= width
    low = np.where(fits, y_min + width / 2.0, (y_min + y_max) / 2.0)
    high = np.where(fits, y_max - width / 2.0, low)
    return np.clip(line, low, high)


def _corridor_overlap(y_min: np.ndarray, y_max: np.ndarray, line: np.ndarray, width: float) -> np.ndarray:
    """Lateral overlap (m) of intervals with the hand's corridor ``line`` +- width / 2 (broadcast)."""
    return np.maximum(np.minimum(y_max, line + width / 2.0) - np.maximum(y_min, line - width / 2.0), 0.0)


@dataclass(frozen=True, eq=False)
class _RowGeometry:
    """What a row offers, whoever looks at it: its gaps and its obstacles, left to right."""

    x: float
    gap_rows: np.ndarray  # positions in the gap table
    gaps: np.ndarray  # (G, 4)
    members: np.ndarray  # obstacle positions in scene order
    obstacles: np.ndarray  # (M, 4)

    @classmethod
    def of(cls, space: TaskSpace, row: int) -> _RowGeometry:
        r = space.rows[row - 1]
        gap_rows = np.flatnonzero(space.gap_table.row == row)
        members = np.array([space.obstacle_index[n] for n in r.members], dtype=int)
        return cls(r.x, gap_rows, space.gap_table.bounds[gap_rows], members, space.obstacle_bounds[members])

    def best(self, hands: np.ndarray, goal: np.ndarray, width: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Per hand (..., 2): (the smallest offset of a gap where the hand fits, that gap's width,
        the obstacles' overlap with the hand's corridor), m, at the row's depth."""
        line = line_at(hands, goal, self.x)[..., None]
        block = _corridor_overlap(self.obstacles[:, 1], self.obstacles[:, 3], line, width).sum(axis=-1)
        widths = self.gaps[:, 3] - self.gaps[:, 1]
        open_ = widths >= width
        if not open_.any():
            return np.full(line.shape[:-1], CAP * width), np.zeros(line.shape[:-1]), block
        offsets = np.abs(_passage(self.gaps[open_, 1], self.gaps[open_, 3], line, width) - line)
        best = np.argmin(offsets, axis=-1)
        return np.take_along_axis(offsets, best[..., None], -1)[..., 0], widths[open_][best], block


def row_candidates(space: TaskSpace, row: int, hands: np.ndarray, goal: np.ndarray, *, hand_width: float,
                   routes: FreeRoutes, removed: Sequence[Collection[int]] | None = None, mirror: bool = False,
                   limit: int | None = None) -> list[RowCandidates]:
    """The candidates of ``row`` and their features Xr, for each hand of ``hands`` heading for ``goal``.

    Args:
        space: the scene's task space.
        row: the row index (from 1).
        hands: (B, 2) planar hand positions, m (one plan each); goal: (2,).
        hand_width: the hand's (gripper's) width, m; lengths are measured in it.
        routes: the scene's ``FreeRoutes`` for the same hand width.
        removed: per hand, the obstacles (scene order) moved earlier on its way: no longer
            where they stood (they are of earlier rows).
        mirror: describe a left arm as its mirror image (lateral signs swapped), so one model
            serves both arms (the planner models a right arm).
        limit: keep only this many gaps and this many obstacles, those laterally nearest each
            hand's line (all if None).

    Returns:
        One ``RowCandidates`` per hand.
    """
    hands, goal = np.asarray(hands, float).reshape(-1, 2), np.asarray(goal, float)
    removed = [frozenset(r) for r in removed] if removed is not None else [frozenset()] * len(hands)
    w = hand_width
    geometry = _RowGeometry.of(space, row)
    gb, ob = geometry.gaps, geometry.obstacles
    n_gaps, n_obj = len(gb), len(ob)
    n = n_gaps + n_obj
    line = line_at(hands, goal, geometry.x)  # (B,)
    points = np.empty((len(hands), n, 2))
    points[:, :n_gaps, 0] = geometry.x
    points[:, :n_gaps, 1] = _passage(gb[:, 1], gb[:, 3], line[:, None], w)
    points[:, n_gaps:] = np.column_stack([(ob[:, 0] + ob[:, 2]) / 2.0, (ob[:, 1] + ob[:, 3]) / 2.0])[None]
    lateral = points[..., 1] - line[:, None]
    depth = np.maximum(geometry.x - hands[:, 0], w / 2.0)[:, None]
    best_offset, best_width, block = geometry.best(hands, goal, w)

    X = np.zeros((len(hands), n, len(ROW_CHOICE_FEATURES)))
    X[:, n_gaps:, 0] = 1.0
    X[:, :, 1] = np.minimum(np.concatenate([gb[:, 3] - gb[:, 1], ob[:, 3] - ob[:, 1]]) / w, CAP)
    X[:, n_gaps:, 2] = np.minimum((ob[:, 2] - ob[:, 0]) / w, CAP)
    X[:, :, 3] = np.minimum(np.abs(lateral) / w, CAP)
    X[:, :, 4] = np.clip((-1.0 if mirror else 1.0) * lateral / w, -CAP, CAP)
    X[:, :, 5] = np.arctan2(np.abs(lateral), depth)
    X[:, :n_gaps, 6] = np.minimum(np.maximum(np.abs(lateral[:, :n_gaps]) - best_offset[:, None], 0.0) / w, CAP)
    table = space.gap_table
    X[:, :n_gaps, 7] = [float(table.left[k] is None or table.right[k] is None) for k in geometry.gap_rows]
    X[:, n_gaps:, 8] = np.minimum(_corridor_overlap(ob[:, 1], ob[:, 3], line[:, None], w) / w, CAP)
    X[:, :n_gaps, 9:11] = 1.0
    if n_obj:
        free = free_fractions(block_array(ob, space.alpha), space.occluder_bounds(target=True))
        X[:, n_gaps:, 9] = free.mean(axis=1)
        X[:, n_gaps:, 10] = np.minimum(free[:, 2], free[:, 3])
    X[:, :, 11] = np.minimum(_approach_collision(space, hands, points, geometry.members, n_gaps, w, removed), CAP)
    X[:, :, 14] = np.minimum(best_offset / w, CAP)[:, None]
    X[:, :, 15] = np.arctan2(best_offset, depth[:, 0])[:, None]
    X[:, :, 16] = np.minimum(best_width / w, CAP)[:, None]
    X[:, :, 17] = np.minimum(block / w, CAP)[:, None]
    X[:, :, 18] = min(n_obj, CAP)
    X[:, :, 19] = np.clip((geometry.x - hands[:, 0]) / np.maximum(goal[0] - hands[:, 0], w), -1.0, 2.0)[:, None]
    if row < len(space.rows):
        next_offset, _, next_block = _RowGeometry.of(space, row + 1).best(points, goal, w)
        X[:, :, 21], X[:, :, 22] = np.minimum(next_offset / w, CAP), np.minimum(next_block / w, CAP)
    _route_features(X, routes, hands, goal, points, geometry.members, n_gaps, w, removed)

    gaps = np.concatenate([table.index[geometry.gap_rows], np.zeros(n_obj, dtype=int)])
    obstacles = np.concatenate([np.full(n_gaps, -1), geometry.members]).astype(int)
    kinds = ("gap",) * n_gaps + ("object",) * n_obj
    result = []
    for b in range(len(hands)):
        keep = np.arange(n)
        if limit is not None:  # the nearest of each kind, kept in their order from left to right
            gap_keep = np.sort(np.argsort(np.abs(lateral[b, :n_gaps]), kind="stable")[:limit])
            obj_keep = n_gaps + np.sort(np.argsort(np.abs(lateral[b, n_gaps:]), kind="stable")[:limit])
            keep = np.concatenate([gap_keep, obj_keep])
        result.append(RowCandidates(row, tuple(kinds[k] for k in keep), gaps[keep], obstacles[keep], points[b, keep],
                                    X[b, keep]))
    return result


def _approach_collision(space: TaskSpace, hands: np.ndarray, points: np.ndarray, members: np.ndarray, n_gaps: int,
                        width: float, removed: list[frozenset[int]]) -> np.ndarray:
    """(B, n) per hand and candidate: the length of the hand's straight way from the hand to the
    candidate inside the obstacles grown by half the hand's width, in hand widths (not counting
    the candidate's own obstacle, nor the ones moved away)."""
    B, n = points.shape[:2]
    grown = space.obstacle_bounds + np.array([-width, -width, width, width]) / 2.0
    inside = segment_inside(np.repeat(hands, n, axis=0), points.reshape(-1, 2), grown).reshape(B, n, -1)
    for b, gone in enumerate(removed):
        inside[b, :, list(gone)] = 0.0
    inside[:, np.arange(n_gaps, n), members] = 0.0
    return inside.sum(axis=2) / width


def _route_features(X: np.ndarray, routes: FreeRoutes, hands: np.ndarray, goal: np.ndarray, points: np.ndarray,
                    members: np.ndarray, n_gaps: int, width: float, removed: list[frozenset[int]]) -> None:
    """Fill columns 12, 13 and 20 of ``X`` (B, n, k): a gap's shortest route through it / the
    shortest route; an obstacle's shortening of the shortest route if it were moved, in hand
    widths (for the obstacles across the straight way from the hand to the target; 0 for the
    others); the shortest route / the straight distance (ROUTE_CAP where there is no route)."""
    B = len(hands)
    per_hand = 1 + n_gaps  # each hand's points in the query: the hand, then its gap points
    query = routes.query(np.vstack([goal[None], *(np.vstack([h[None], p[:n_gaps]]) for h, p in zip(hands, points))]))
    starts = 1 + per_hand * np.arange(B)
    straight = np.maximum(np.hypot(*(goal - hands).T), width)
    in_the_way = segment_hits(np.repeat(hands, len(members), axis=0), np.tile(goal, (B * len(members), 1)),
                              routes.grown[np.tile(members, B)]).reshape(B, len(members), -1)[..., 0] if len(members) \
        else np.zeros((B, 0), dtype=bool)
    for gone in set(removed):
        group = [b for b in range(B) if removed[b] == gone]
        lengths = query.lengths(gone)
        for b in group:
            s = starts[b]
            shortest = lengths[s, 0] if np.isfinite(lengths[s, 0]) else ROUTE_CAP * straight[b]
            X[b, :, 20] = min(shortest / straight[b], ROUTE_CAP)
            if n_gaps:
                via = lengths[s, s + 1 : s + per_hand] + lengths[s + 1 : s + per_hand, 0]
                X[b, :n_gaps, 12] = np.minimum(via / shortest, ROUTE_CAP)
            for k in np.flatnonzero(in_the_way[b]):
                without = query.lengths(gone | {int(members[k])}, sources=[s], targets=[0])[0, 0]
                without = without if np.isfinite(without) else ROUTE_CAP * straight[b]
                X[b, n_gaps + k, 13] = np.clip((shortest - without) / width, 0.0, CAP)
