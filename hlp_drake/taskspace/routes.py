"""Shortest hand routes to the target among the obstacles (a visibility graph).

The hand is a disc of the hand's width: obstacles are their footprint rectangles grown by half of
it, and the hand's centre keeps half of it from the table's back and side edges. The shortest
route between two points then runs straight or from corner to corner of the grown rectangles.
``FreeRoutes`` builds the corners' graph once per scene and, per set of obstacles taken away
(moved), the corners' distances to each other and to the goal (a moved obstacle's corners stay as
points of the free space); ``Sight`` holds what a few points
of interest see (the corners, the goal), so routes from them cost a few array operations.
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass, field

import numpy as np

CORNER_OFFSET = (
    1e-5  # hand widths: corners sit just outside their grown rectangle, so they see along its sides
)


def _clip(p0: np.ndarray, p1: np.ndarray, rects: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(n, m) Liang-Barsky entry and exit parameters of segment p0[i] -> p1[i] through rectangle j
    (the segment is inside it for parameters between them, where entry < exit)."""
    a = np.asarray(p0, float).reshape(-1, 1, 2)
    d = np.asarray(p1, float).reshape(-1, 1, 2) - a
    r = np.asarray(rects, float).reshape(1, -1, 4)
    low = np.zeros((a.shape[0], r.shape[1]))
    high = np.ones_like(low)
    for axis in (0, 1):
        lo, hi, start, step = r[..., axis], r[..., axis + 2], a[..., axis], d[..., axis]
        moving = step != 0.0
        safe = np.where(moving, step, 1.0)
        t_lo, t_hi = (lo - start) / safe, (hi - start) / safe
        within = (start > lo) & (start < hi)  # a segment parallel to this axis: inside the slab or not
        low = np.maximum(low, np.where(moving, np.minimum(t_lo, t_hi), np.where(within, -np.inf, np.inf)))
        high = np.minimum(high, np.where(moving, np.maximum(t_lo, t_hi), np.where(within, np.inf, -np.inf)))
    return low, high


def segment_hits(p0: np.ndarray, p1: np.ndarray, rects: np.ndarray) -> np.ndarray:
    """(n, m): whether segment p0[i] -> p1[i] passes through the open interior of rectangle j
    (touching its boundary does not count).

    The separating-axis test: the segment meets the open rectangle unless their projections on x,
    on y or on the segment's normal do not overlap (a third of the operations of a clip)."""
    a, b = np.asarray(p0, float).reshape(-1, 2), np.asarray(p1, float).reshape(-1, 2)
    r = np.asarray(rects, float).reshape(-1, 4)
    d = b - a
    # A way that only touches within 1e-9 of its length does not count (as in the clip).
    tolerance = 1e-9 * np.abs(d)
    low, high = np.minimum(a, b) + tolerance, np.maximum(a, b) - tolerance
    hits = (low[:, 0, None] < r[None, :, 2]) & (high[:, 0, None] > r[None, :, 0])
    hits &= (low[:, 1, None] < r[None, :, 3]) & (high[:, 1, None] > r[None, :, 1])
    centre, half = (r[:, :2] + r[:, 2:]) / 2.0, (r[:, 2:] - r[:, :2]) / 2.0
    across = d[:, 0, None] * (centre[None, :, 1] - a[:, 1, None]) - d[:, 1, None] * (
        centre[None, :, 0] - a[:, 0, None]
    )
    spread = np.abs(d[:, 0, None]) * half[None, :, 1] + np.abs(d[:, 1, None]) * half[None, :, 0]
    length = np.hypot(d[:, 0], d[:, 1])[:, None]
    hits &= (np.abs(across) < spread - 1e-9 * length * (half[None, :, 0] + half[None, :, 1])) | (
        length == 0.0
    )
    return hits


def lengths(d: np.ndarray) -> np.ndarray:
    """Euclidean lengths of the vectors along the last axis of ``d``: ``np.linalg.norm(d, axis=-1)``
    to the bit, without its overhead (the planner takes thousands of them per plan)."""
    return np.sqrt((d * d).sum(axis=-1))


REACH_MARGIN = 1e-9  # m: rectangles this far from every segment's bounding box are not clipped


def segment_inside(p0: np.ndarray, p1: np.ndarray, rects: np.ndarray) -> np.ndarray:
    """(n, m): the length of segment p0[i] -> p1[i] inside rectangle j.

    Only the rectangles within ``REACH_MARGIN`` of the segments' common bounding box are clipped
    (the others hold 0), so a few segments among many obstacles stay cheap."""
    a, b = np.asarray(p0, float).reshape(-1, 2), np.asarray(p1, float).reshape(-1, 2)
    r = np.asarray(rects, float).reshape(-1, 4)
    inside = np.zeros((len(a), len(r)))
    if len(a) == 0:
        return inside
    lo = np.minimum(a.min(axis=0), b.min(axis=0)) - REACH_MARGIN
    hi = np.maximum(a.max(axis=0), b.max(axis=0)) + REACH_MARGIN
    near = np.flatnonzero((r[:, 0] <= hi[0]) & (r[:, 2] >= lo[0]) & (r[:, 1] <= hi[1]) & (r[:, 3] >= lo[1]))
    low, high = _clip(a, b, r[near])
    inside[:, near] = np.maximum(high - low, 0.0) * lengths(b - a)[:, None]
    return inside


def all_pairs_shortest(graph: np.ndarray) -> np.ndarray:
    """Floyd-Warshall on a dense (n, n) matrix of edge lengths (inf: no edge)."""
    d = graph.copy()
    np.fill_diagonal(d, 0.0)
    for k in range(len(d)):
        np.minimum(d, d[:, k, None] + d[None, k, :], out=d)
    return d


@dataclass(frozen=True, eq=False)
class Sight:
    """What some points see: per point and corner (and the goal) the straight length, and which
    grown obstacles the straight way passes through.

    Attributes:
        points: (p, 2); corner_hits: (p, c, m); corner_length: (p, c); goal_hits: (p, m);
        goal_length: (p,).
    """

    points: np.ndarray
    corner_hits: np.ndarray
    corner_length: np.ndarray
    goal_hits: np.ndarray
    goal_length: np.ndarray
    memo: dict[tuple[str, frozenset[int]], np.ndarray] = field(default_factory=dict, repr=False)
    """``FreeRoutes``' per-point results for all the points at once, per set of obstacles removed."""


class FreeRoutes:
    """The corner graph of a hand ``hand_width`` wide among obstacles, with routes to ``goal``.

    Args:
        rects: (m, 4) obstacle footprints (x_min, y_min, x_max, y_max).
        ids: (m,) the obstacles' ids (e.g. positions in scene order), the ones ``removed`` names.
        table_bounds: (x_min, y_min, x_max, y_max) of the table top.
        hand_width: the hand's (gripper's) width, m.
        goal: (2,) where every route ends.
    """

    def __init__(
        self,
        rects: np.ndarray,
        ids: np.ndarray,
        table_bounds: tuple[float, float, float, float],
        hand_width: float,
        goal: np.ndarray,
    ) -> None:
        half = hand_width / 2.0
        self.grown = np.asarray(rects, float).reshape(-1, 4) + np.array([-half, -half, half, half])
        self.ids = np.asarray(ids, dtype=int).reshape(-1)
        self.goal = np.asarray(goal, float)
        g, e = self.grown, CORNER_OFFSET * hand_width
        corners = np.concatenate(
            [
                np.column_stack([g[:, 0] - e, g[:, 1] - e]),
                np.column_stack([g[:, 0] - e, g[:, 3] + e]),
                np.column_stack([g[:, 2] + e, g[:, 1] - e]),
                np.column_stack([g[:, 2] + e, g[:, 3] + e]),
            ]
        )
        owner = np.tile(np.arange(len(g)), 4)
        x0, y0, x1, y1 = table_bounds
        keep = (
            (corners[:, 0] >= x0)
            & (corners[:, 0] <= x1 - half)
            & (corners[:, 1] >= y0 + half)
            & (corners[:, 1] <= y1 - half)
        )
        if len(g):
            inside = (
                (corners[:, None, 0] > g[None, :, 0])
                & (corners[:, None, 0] < g[None, :, 2])
                & (corners[:, None, 1] > g[None, :, 1])
                & (corners[:, None, 1] < g[None, :, 3])
            )
            keep &= ~inside.any(axis=1)
        self.corners, self.owner = corners[keep], owner[keep]
        n = len(self.corners)
        upper = np.triu_indices(n, k=1)  # a straight way hits what its reverse hits
        self._edge_hits = np.zeros((n, n, len(g)), dtype=bool)
        self._edge_hits[upper] = segment_hits(self.corners[upper[0]], self.corners[upper[1]], self.grown)
        self._edge_hits |= self._edge_hits.transpose(1, 0, 2)
        self._edge_length = lengths(self.corners[:, None] - self.corners[None])
        # The corners' straight ways to the goal: which grown obstacles they pass through, their lengths.
        self._goal_hits = segment_hits(
            self.corners, np.broadcast_to(self.goal, self.corners.shape), self.grown
        )
        self._goal_length = lengths(self.corners - self.goal)
        self._ends = np.vstack([self.corners, self.goal[None]])  # what ``sight`` looks at
        self.position = {int(k): i for i, k in enumerate(self.ids)}  # an id's obstacle, in ``grown``
        self._tables: dict[frozenset[int], tuple[np.ndarray, np.ndarray, np.ndarray]] = {}

    def kept(self, removed: Collection[int]) -> np.ndarray:
        """(m,) which obstacles stand (their ids not in ``removed``)."""
        return np.array([int(k) not in removed for k in self.ids], dtype=bool)

    def tables(self, removed: frozenset[int]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(kept (m,), corner distances (c, c), corner route lengths to the goal (c,)) with the
        ``removed`` obstacles taken away (their corners stay: points of the free space)."""
        if removed not in self._tables:
            kept = self.kept(removed)
            open_ = ~self._edge_hits[:, :, kept].any(axis=2)
            distances = all_pairs_shortest(np.where(open_, self._edge_length, np.inf))
            straight = np.where(self._goal_hits[:, kept].any(axis=1), np.inf, self._goal_length)
            to_goal = np.min(distances + straight[None, :], axis=1) if len(straight) else straight
            self._tables[removed] = (kept, distances, to_goal)
        return self._tables[removed]

    def sight(self, points: np.ndarray, pairs: tuple[np.ndarray, np.ndarray] | None = None):
        """What the ``points`` (p, 2) see; with ``pairs`` (starts (q, 2), ends (q, 2)) also which
        grown obstacles each of those straight ways passes through, (q, m): ``(Sight, hits)``.
        One segment test for all."""
        points = np.asarray(points, float).reshape(-1, 2)
        c, m = len(self.corners), len(self.grown)
        ends = self._ends
        starts, stops = np.repeat(points, c + 1, axis=0), np.tile(ends, (len(points), 1))
        if pairs is not None:
            starts, stops = np.vstack([starts, pairs[0]]), np.vstack([stops, pairs[1]])
        hits = segment_hits(starts, stops, self.grown)
        seen = hits[: len(points) * (c + 1)].reshape(len(points), c + 1, m)
        length = lengths(points[:, None] - ends[None])
        sight = Sight(points, seen[:, :c], length[:, :c], seen[:, c], length[:, c])
        return sight if pairs is None else (sight, hits[len(points) * (c + 1) :])

    def to_goal(self, sight: Sight, rows: np.ndarray, removed: frozenset[int]) -> np.ndarray:
        """Route lengths from the points ``rows`` of ``sight`` to the goal (inf: no route)."""
        key = ("to_goal", removed)
        if key not in sight.memo:
            kept, _, to_goal = self.tables(removed)
            direct = np.where(sight.goal_hits[:, kept].any(axis=1), np.inf, sight.goal_length)
            if len(self.corners):
                direct = np.minimum(direct, np.min(self._reach(sight, removed) + to_goal[None], axis=1))
            sight.memo[key] = direct
        return sight.memo[key][rows]

    def to_goal_without(
        self, sight: Sight, rows: np.ndarray, removed: frozenset[int], obstacle: int
    ) -> np.ndarray:
        """As ``to_goal`` with the obstacle of id ``obstacle`` taken away too, without a new corner
        graph: the shortest route then crosses the obstacle's (convex) place at most once, along a
        straight way that it alone blocked, between the point or a corner the route reaches with
        it standing and a corner (or the goal) it reaches the goal from."""
        kept, distances, to_goal = self.tables(removed)
        base = self.to_goal(sight, rows, removed)
        r = self.position[int(obstacle)]
        if not kept[r]:
            return base
        others = kept.copy()
        others[r] = False

        def crossing(hits: np.ndarray) -> np.ndarray:  # blocked by the obstacle and by no other
            return hits[..., r] & ~hits[..., others].any(axis=-1)

        direct = np.where(crossing(sight.goal_hits[rows]), sight.goal_length[rows], np.inf)
        best = np.minimum(base, direct)
        if len(self.corners) == 0:
            return best
        reach = self._reach(sight, removed)[rows]  # (n, c) with the obstacle standing
        from_point = np.min(reach[:, :, None] + distances[None], axis=1)  # (n, c)
        through = np.where(crossing(sight.corner_hits[rows]), sight.corner_length[rows], np.inf)
        edge = np.where(crossing(self._edge_hits), self._edge_length, np.inf)
        last = np.where(crossing(self._goal_hits), self._goal_length, np.inf)
        via_edge = np.min(from_point[:, :, None] + edge[None] + to_goal[None, None, :], axis=(1, 2))
        return np.minimum.reduce(
            [best, np.min(through + to_goal[None], axis=1), np.min(from_point + last[None], axis=1), via_edge]
        )

    def between(
        self,
        sight: Sight,
        sources: np.ndarray,
        targets: np.ndarray,
        direct_hits: np.ndarray,
        removed: frozenset[int],
    ) -> np.ndarray:
        """Route lengths from the points ``sources`` to the points ``targets`` of ``sight``, pair
        by pair; ``direct_hits`` (pairs, m): which grown obstacles each straight way passes through."""
        kept, distances, _ = self.tables(removed)
        straight = lengths(sight.points[sources] - sight.points[targets])
        direct = np.where(direct_hits[:, kept].any(axis=1), np.inf, straight)
        if len(self.corners) == 0:
            return direct
        reach = self._reach(sight, removed)[np.concatenate([sources, targets])]
        from_source = np.min(reach[: len(sources), :, None] + distances[None], axis=1)  # (pairs, c)
        return np.minimum(direct, np.min(from_source + reach[len(sources) :], axis=1))

    def _reach(self, sight: Sight, removed: frozenset[int]) -> np.ndarray:
        """(points, c) the straight lengths from the points of ``sight`` to the corners (inf where an
        obstacle not ``removed`` blocks the way)."""
        key = ("reach", removed)
        if key not in sight.memo:
            kept = self.tables(removed)[0]
            sight.memo[key] = np.where(sight.corner_hits[:, :, kept].any(axis=2), np.inf, sight.corner_length)
        return sight.memo[key]
