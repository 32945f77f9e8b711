"""Shortest hand routes across the table among the obstacles (a visibility graph).

The hand is a disc of the hand's width: obstacles are their footprint rectangles grown by half of
it, and the hand's centre keeps half of it from the table's back and side edges. The shortest
route between two points then runs straight or from corner to corner of the grown rectangles. The
corners' graph is built once per scene (``FreeRoutes``); routes between a few points of interest
add those points' visibility of the corners (``RouteQuery``), and routes with some obstacles moved
away reuse the same segment tests, so one query answers every "what if this one were moved".
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

CORNER_OFFSET = 1e-6  # corners sit just outside their grown rectangle, so they see along its sides


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
    (touching its boundary does not count)."""
    low, high = _clip(p0, p1, rects)
    return high - low > 1e-9


def segment_inside(p0: np.ndarray, p1: np.ndarray, rects: np.ndarray) -> np.ndarray:
    """(n, m): the length of segment p0[i] -> p1[i] inside rectangle j."""
    low, high = _clip(p0, p1, rects)
    length = np.linalg.norm(np.asarray(p1, float).reshape(-1, 2) - np.asarray(p0, float).reshape(-1, 2), axis=1)
    return np.maximum(high - low, 0.0) * length[:, None]


def all_pairs_shortest(graph: np.ndarray) -> np.ndarray:
    """Floyd-Warshall on a dense (n, n) matrix of edge lengths (inf: no edge)."""
    d = graph.copy()
    np.fill_diagonal(d, 0.0)
    for k in range(len(d)):
        np.minimum(d, d[:, k, None] + d[None, k, :], out=d)
    return d


class FreeRoutes:
    """The corner graph of a hand ``hand_width`` wide among ``rects`` on a table.

    Args:
        rects: (m, 4) obstacle footprints (x_min, y_min, x_max, y_max).
        table_bounds: (x_min, y_min, x_max, y_max) of the table top.
        hand_width: the hand's (gripper's) width, m.
    """

    def __init__(self, rects: np.ndarray, table_bounds: tuple[float, float, float, float], hand_width: float) -> None:
        half = hand_width / 2.0
        self.grown = np.asarray(rects, float).reshape(-1, 4) + np.array([-half, -half, half, half])
        g, e = self.grown, CORNER_OFFSET
        corners = np.concatenate([
            np.column_stack([g[:, 0] - e, g[:, 1] - e]), np.column_stack([g[:, 0] - e, g[:, 3] + e]),
            np.column_stack([g[:, 2] + e, g[:, 1] - e]), np.column_stack([g[:, 2] + e, g[:, 3] + e])])
        owner = np.tile(np.arange(len(g)), 4)
        x0, y0, x1, y1 = table_bounds
        keep = ((corners[:, 0] >= x0) & (corners[:, 0] <= x1 - half)
                & (corners[:, 1] >= y0 + half) & (corners[:, 1] <= y1 - half))
        if len(g):
            inside = ((corners[:, None, 0] > g[None, :, 0]) & (corners[:, None, 0] < g[None, :, 2])
                      & (corners[:, None, 1] > g[None, :, 1]) & (corners[:, None, 1] < g[None, :, 3]))
            keep &= ~inside.any(axis=1)
        self.corners, self.owner = corners[keep], owner[keep]
        n = len(self.corners)
        self._edge_hits = segment_hits(np.repeat(self.corners, n, axis=0), np.tile(self.corners, (n, 1)),
                                       self.grown).reshape(n, n, -1)
        self._edge_length = np.linalg.norm(self.corners[:, None] - self.corners[None], axis=2)
        self._distances: dict[frozenset[int], np.ndarray] = {}

    def kept(self, removed: frozenset[int]) -> np.ndarray:
        """(m,) which obstacles stand (not ``removed``)."""
        kept = np.ones(len(self.grown), dtype=bool)
        kept[list(removed)] = False
        return kept

    def corner_distances(self, removed: frozenset[int] = frozenset()) -> np.ndarray:
        """(c, c) shortest route lengths between the corners, the ``removed`` obstacles taken away
        (their own corners unusable: inf)."""
        if removed not in self._distances:
            kept = self.kept(removed)
            usable = kept[self.owner]
            open_ = ~self._edge_hits[:, :, kept].any(axis=2) & usable[:, None] & usable[None, :]
            self._distances[removed] = all_pairs_shortest(np.where(open_, self._edge_length, np.inf))
        return self._distances[removed]

    def query(self, points: np.ndarray) -> RouteQuery:
        """Routes between ``points`` (p, 2)."""
        return RouteQuery(self, points)

    def lengths(self, a: np.ndarray, b: np.ndarray, removed: Iterable[int] = ()) -> np.ndarray:
        """(n, k) shortest route lengths from each of ``a`` (n, 2) to each of ``b`` (k, 2), the
        obstacles ``removed`` taken away; inf where there is none."""
        a, b = np.asarray(a, float).reshape(-1, 2), np.asarray(b, float).reshape(-1, 2)
        return self.query(np.vstack([a, b])).lengths(removed)[: len(a), len(a) :]


class RouteQuery:
    """Shortest routes between a few points, with any obstacles taken away (``lengths``)."""

    def __init__(self, routes: FreeRoutes, points: np.ndarray) -> None:
        self.routes = routes
        self.points = np.asarray(points, float).reshape(-1, 2)
        p, c = len(self.points), len(routes.corners)
        pairs = segment_hits(np.repeat(self.points, p, axis=0), np.tile(self.points, (p, 1)), routes.grown)
        self._direct_hits = pairs.reshape(p, p, -1)
        self._direct_length = np.linalg.norm(self.points[:, None] - self.points[None], axis=2)
        reach = segment_hits(np.repeat(self.points, c, axis=0), np.tile(routes.corners, (p, 1)), routes.grown)
        self._reach_hits = reach.reshape(p, c, -1)
        self._reach_length = np.linalg.norm(self.points[:, None] - routes.corners[None], axis=2)

    def lengths(self, removed: Iterable[int] = (), sources: np.ndarray | None = None,
                targets: np.ndarray | None = None) -> np.ndarray:
        """Shortest route lengths between the points (rows ``sources``, columns ``targets``: index
        arrays, default all), the obstacles ``removed`` taken away; inf where there is none."""
        removed = frozenset(int(k) for k in removed)
        every = np.arange(len(self.points))
        sources = every if sources is None else np.asarray(sources, int)
        targets = every if targets is None else np.asarray(targets, int)
        kept = self.routes.kept(removed)
        direct = np.where(self._direct_hits[np.ix_(sources, targets)][:, :, kept].any(axis=2), np.inf,
                          self._direct_length[np.ix_(sources, targets)])
        if len(self.routes.corners) == 0:
            return direct
        unusable = ~kept[self.routes.owner]
        reach = np.where(self._reach_hits[:, :, kept].any(axis=2) | unusable[None], np.inf, self._reach_length)
        to_corner = np.min(reach[sources, :, None] + self.routes.corner_distances(removed)[None], axis=1)
        via = np.min(to_corner[:, None, :] + reach[targets][None, :, :], axis=2)
        return np.minimum(direct, via)
