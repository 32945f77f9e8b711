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

from hlp_drake.features.row_geometry import (
    CAP,
    RowGeometry,
    candidate_points,
    corridor_overlap,
    free_space,
    line_at,
    nearest_candidates,
)
from hlp_drake.taskspace import TaskSpace
from hlp_drake.taskspace.routes import FreeRoutes, lengths, segment_inside

HUMAN_HAND_WIDTH = 0.05  # m: the VR study's hand (the original's hand_width)
ROUTE_CAP = 3.0  # route length ratios saturate here (and stand for "no route")
ROW_CHOICE_FEATURES = (
    "is_object", "size", "depth", "offset", "signed_offset", "offset_angle", "offset_beyond_best",
    "at_table_edge", "corridor_overlap", "free_space", "free_sideways", "approach_collision",
    "route_via", "route_gain",
    "row_best_offset", "row_best_angle", "row_best_width", "row_corridor_block", "row_members", "progress",
    "route_detour", "next_best_offset", "next_corridor_block", "ahead", "distance",
    "target_offset", "target_beyond",
)  # fmt: skip
CONTEXT_FEATURES = ("came_by_move", "came_by_gap", "moves_before", "turn")
"""The way the hand came (``RowChoiceScene.candidates``' ``previous``): how it reached its
keypoint (releasing a moved obstacle, through a gap; neither: from the start), how many obstacles
it moved on the way, and the angle between its heading there and its way to the candidate."""
ROW_CONTEXT_FEATURES = ROW_CHOICE_FEATURES + CONTEXT_FEATURES
"""Xr with the context (a model trained without it reads the first ``len(ROW_CHOICE_FEATURES)``)."""


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


ROUTE_OBSTACLES = 6
"""Obstacles in the route graph: every VR scene (structured and unstructured) has six. The graph's
cost then no longer grows with the object count (``benchmarks/planning_time.py``: a two-row
50-box plan took 1.8x a 6-box one with 16, 1.3x with 6, see docs/results.md)."""


class RowChoiceScene:
    """The row-choice features of one scene for a hand of one width (``candidates``), with what
    every row and every hand position share computed once: the rows' geometry and the route graph.

    Args:
        space: the scene's task space.
        hand_width: the hand's (gripper's) width, m; lengths are measured in it.
        route_obstacles: the route graph holds at most this many obstacles, those nearest the
            straight line from the start to the target, so its cost is the same on any table
            (``ROUTE_OBSTACLES``: as many as every VR scene has, so the features the models
            learnt from are the ones they are asked about).
    """

    def __init__(
        self, space: TaskSpace, hand_width: float, *, route_obstacles: int = ROUTE_OBSTACLES
    ) -> None:
        self.space, self.width = space, hand_width
        self.goal = np.asarray(space.target.center, float)
        start, centres = np.asarray(space.scene.start, float), space.obstacle_centres
        span = self.goal - start
        offset = np.abs(
            span[0] * (centres[:, 1] - start[1]) - span[1] * (centres[:, 0] - start[0])
        )  # ~ distance
        ids = np.sort(np.argsort(offset, kind="stable")[:route_obstacles])
        self.routes = FreeRoutes(
            space.obstacle_bounds[ids], ids, space.scene.table.bounds, hand_width, self.goal
        )
        self._free = free_space(space)
        self._grown = (
            space.obstacle_bounds + np.array([-hand_width, -hand_width, hand_width, hand_width]) / 2.0
        )
        self._rows: dict[int, RowGeometry] = {}

    def row(self, index: int) -> RowGeometry:
        if index not in self._rows:
            self._rows[index] = RowGeometry.of(self.space, index)
        return self._rows[index]

    def candidates(
        self,
        row: int,
        hands: np.ndarray,
        removed: Sequence[Collection[int]] | None = None,
        *,
        mirror: bool = False,
        limit: int | None = None,
        previous: np.ndarray | None = None,
        came_by: Sequence[str] | None = None,
    ) -> list[RowCandidates]:
        """The candidates of ``row`` and their features Xr, for each hand of ``hands`` heading for
        the target.

        Args:
            row: the row index (from 1).
            hands: (B, 2) planar hand positions, m (one plan each).
            removed: per hand, the obstacles (scene order) moved earlier on its way: no longer
                where they stood (they are of earlier rows).
            mirror: describe a left arm as its mirror image (lateral signs swapped), so one model
                serves both arms (the planner models a right arm).
            limit: keep only this many gaps and this many obstacles, those laterally nearest each
                hand's line (all if None).
            previous: (B, 2) per hand, the keypoint before it (its heading is from there to the
                hand; None, or a hand at its own previous keypoint: heading for the target).
            came_by: per hand, the action that brought it to its keypoint: "release" (an
                obstacle moved), "gap", or anything else (the start).

        Returns:
            One ``RowCandidates`` per hand.
        """
        hands = np.asarray(hands, float).reshape(-1, 2)
        removed = [frozenset(r) for r in removed] if removed is not None else [frozenset()] * len(hands)
        geometry = self.row(row)
        line = line_at(hands, self.goal, geometry.x)  # (B,)
        gap_keep, obj_keep = nearest_candidates(
            geometry, line, self.width, limit
        )  # per hand, positions in the row
        gap_union, obj_union = sorted(set().union(*gap_keep)), sorted(set().union(*obj_keep))
        points = candidate_points(geometry, gap_union, obj_union, line, self.width)
        X = self._features(row, hands, line, points, gap_union, obj_union, removed, mirror=mirror)
        X = np.concatenate([X, self._context(hands, points, removed, previous, came_by)], axis=2)
        return self._per_hand(row, gap_union, obj_union, gap_keep, obj_keep, points, X)

    def _features(
        self,
        row: int,
        hands: np.ndarray,
        line: np.ndarray,
        points: np.ndarray,
        gap_union: list[int],
        obj_union: list[int],
        removed: list[frozenset[int]],
        *,
        mirror: bool,
    ) -> np.ndarray:
        """(B, n, len(ROW_CHOICE_FEATURES)) the features Xr of the row's gaps ``gap_union`` and
        obstacles ``obj_union`` (positions in the row) at ``points`` (B, n, 2), per hand (B, 2)
        whose line to the target is at ``line`` (B,) at the row's depth."""
        w, goal, geometry = self.width, self.goal, self.row(row)
        gb, ob = geometry.gaps[gap_union], geometry.obstacles[obj_union]
        members = geometry.members[obj_union]
        free = self._free[members].reshape(-1, 8)
        n_gaps = len(gb)
        lateral = points[..., 1] - line[:, None]
        depth = np.maximum(geometry.x - hands[:, 0], w / 2.0)[:, None]
        best_offset, best_width, block = geometry.best(hands, goal, w)

        X = np.zeros((len(hands), points.shape[1], len(ROW_CHOICE_FEATURES)))
        X[:, n_gaps:, 0] = 1.0
        X[:, :, 1] = np.minimum(np.concatenate([gb[:, 3] - gb[:, 1], ob[:, 3] - ob[:, 1]]) / w, CAP)
        X[:, n_gaps:, 2] = np.minimum((ob[:, 2] - ob[:, 0]) / w, CAP)
        X[:, :, 3] = np.minimum(np.abs(lateral) / w, CAP)
        X[:, :, 4] = np.minimum(np.maximum((-1.0 if mirror else 1.0) * lateral / w, -CAP), CAP)
        X[:, :, 5] = np.arctan2(np.abs(lateral), depth)
        X[:, :n_gaps, 6] = np.minimum(
            np.maximum(np.abs(lateral[:, :n_gaps]) - best_offset[:, None], 0.0) / w, CAP
        )
        X[:, :n_gaps, 7] = geometry.at_edge[gap_union]
        X[:, n_gaps:, 8] = np.minimum(corridor_overlap(ob[:, 1], ob[:, 3], line[:, None], w) / w, CAP)
        X[:, :n_gaps, 9:11] = 1.0
        X[:, n_gaps:, 9] = free.mean(axis=1)
        X[:, n_gaps:, 10] = np.minimum(free[:, 2], free[:, 3])
        X[:, :, 11] = np.minimum(self._approach_collision(hands, points, members, n_gaps, removed), CAP)
        X[:, :, 14] = np.minimum(best_offset / w, CAP)[:, None]
        X[:, :, 15] = np.arctan2(best_offset, depth[:, 0])[:, None]
        X[:, :, 16] = np.minimum(best_width / w, CAP)[:, None]
        X[:, :, 17] = np.minimum(block / w, CAP)[:, None]
        X[:, :, 18] = min(len(geometry.members), CAP)
        X[:, :, 19] = np.clip((geometry.x - hands[:, 0]) / np.maximum(goal[0] - hands[:, 0], w), -1.0, 2.0)[
            :, None
        ]
        if row < len(self.space.rows):
            next_offset, _, next_block = self.row(row + 1).best(points, goal, w)
            X[:, :, 21], X[:, :, 22] = np.minimum(next_offset / w, CAP), np.minimum(next_block / w, CAP)
        X[:, :, 23] = np.minimum((geometry.x - hands[:, 0]) / w, CAP)[:, None]
        X[:, :, 24] = np.minimum(lengths(points - hands[:, None]) / w, CAP)
        X[:, :, 25] = np.minimum(
            np.maximum((-1.0 if mirror else 1.0) * (points[..., 1] - goal[1]) / w, -CAP), CAP
        )
        X[:, :, 26] = np.minimum((goal[0] - geometry.x) / w, CAP)
        self._route_features(X, hands, points, members, n_gaps, removed)
        return X

    def _context(
        self,
        hands: np.ndarray,
        points: np.ndarray,
        removed: list[frozenset[int]],
        previous: np.ndarray | None,
        came_by: Sequence[str] | None,
    ) -> np.ndarray:
        """(B, n, len(CONTEXT_FEATURES)) the way each hand came (see ``CONTEXT_FEATURES``)."""
        B, n = points.shape[:2]
        context = np.zeros((B, n, len(CONTEXT_FEATURES)))
        if came_by is not None:
            context[:, :, 0] = np.array([c == "release" for c in came_by], float)[:, None]
            context[:, :, 1] = np.array([c == "gap" for c in came_by], float)[:, None]
        context[:, :, 2] = np.array([min(len(r), CAP) for r in removed], float)[:, None]
        heading = (
            self.goal - hands if previous is None else hands - np.asarray(previous, float).reshape(-1, 2)
        )
        still = np.hypot(*heading.T) < 1e-9
        heading[still] = (self.goal - hands)[still]
        way = points - hands[:, None]
        cross = heading[:, None, 0] * way[..., 1] - heading[:, None, 1] * way[..., 0]
        dot = heading[:, None, 0] * way[..., 0] + heading[:, None, 1] * way[..., 1]
        context[:, :, 3] = np.abs(np.arctan2(cross, dot))
        return context

    def _per_hand(
        self,
        row: int,
        gap_union: list[int],
        obj_union: list[int],
        gap_keep: list[set[int]],
        obj_keep: list[set[int]],
        points: np.ndarray,
        X: np.ndarray,
    ) -> list[RowCandidates]:
        """Per hand, its own candidates (``gap_keep``, ``obj_keep``: positions in the row) out of
        the union ``gap_union`` + ``obj_union`` whose ``points`` and features ``X`` were computed."""
        geometry = self.row(row)
        n_gaps, n_obj = len(gap_union), len(obj_union)
        gaps = np.concatenate(
            [self.space.gap_table.index[geometry.gap_rows[gap_union]], np.zeros(n_obj, dtype=int)]
        )
        obstacles = np.concatenate([np.full(n_gaps, -1), geometry.members[obj_union]]).astype(int)
        kinds = ("gap",) * n_gaps + ("object",) * n_obj
        at = {g: k for k, g in enumerate(gap_union)}
        at_obj = {o: n_gaps + k for k, o in enumerate(obj_union)}
        result = []
        for b in range(len(points)):
            keep = np.array(
                [at[g] for g in sorted(gap_keep[b])] + [at_obj[o] for o in sorted(obj_keep[b])], dtype=int
            )
            result.append(
                RowCandidates(
                    row,
                    tuple(kinds[k] for k in keep),
                    gaps[keep],
                    obstacles[keep],
                    points[b, keep],
                    X[b, keep],
                )
            )
        return result

    def _approach_collision(
        self,
        hands: np.ndarray,
        points: np.ndarray,
        members: np.ndarray,
        n_gaps: int,
        removed: list[frozenset[int]],
    ) -> np.ndarray:
        """(B, n) per hand and candidate: the length of the hand's straight way from the hand to the
        candidate inside the obstacles grown by half the hand's width, in hand widths (not counting
        the candidate's own obstacle, nor the ones moved away)."""
        B, n = points.shape[:2]
        inside = segment_inside(np.repeat(hands, n, axis=0), points.reshape(-1, 2), self._grown).reshape(
            B, n, -1
        )
        for b, gone in enumerate(removed):
            if gone:
                inside[b, :, list(gone)] = 0.0
        inside[:, np.arange(n_gaps, n), members] = 0.0
        return inside.sum(axis=2) / self.width

    def _route_features(
        self,
        X: np.ndarray,
        hands: np.ndarray,
        points: np.ndarray,
        members: np.ndarray,
        n_gaps: int,
        removed: list[frozenset[int]],
    ) -> None:
        """Fill columns 12, 13 and 20 of ``X`` (B, n, k): a gap's shortest route through it / the
        shortest route; an obstacle's shortening of the shortest route if it were moved, in hand
        widths (for the obstacles across the straight way from the hand to the target; 0 for the
        others); the shortest route / the straight distance (ROUTE_CAP where there is no route)."""
        routes, w, B, G = self.routes, self.width, len(hands), n_gaps
        gap_points = points[:, :G].reshape(-1, 2)
        sight, pair_hits = routes.sight(
            np.vstack([hands, gap_points]), pairs=(np.repeat(hands, G, axis=0), gap_points)
        )
        straight = np.maximum(np.hypot(*(self.goal - hands).T), w)
        for gone in set(removed):
            group = np.array([b for b in range(B) if removed[b] == gone])
            shortest = routes.to_goal(sight, group, gone)
            shortest = np.where(np.isfinite(shortest), shortest, ROUTE_CAP * straight[group])
            X[group, :, 20] = np.minimum(shortest / straight[group], ROUTE_CAP)[:, None]
            if G:
                pairs = (group[:, None] * G + np.arange(G)).reshape(-1)
                via = (
                    routes.between(sight, np.repeat(group, G), B + pairs, pair_hits[pairs], gone)
                    + routes.to_goal(sight, B + pairs, gone)
                ).reshape(len(group), G)
                X[group, :G, 12] = np.minimum(via / shortest[:, None], ROUTE_CAP)
            for k, obstacle in enumerate(members):  # moved away: the route from the hands it stands before
                r = routes.position.get(int(obstacle))
                if r is None or int(obstacle) in gone:
                    continue
                before = np.flatnonzero(sight.goal_hits[group, r])
                if len(before) == 0:
                    continue
                without = routes.to_goal_without(sight, group[before], gone, int(obstacle))
                without = np.where(np.isfinite(without), without, ROUTE_CAP * straight[group[before]])
                X[group[before], G + k, 13] = np.minimum(
                    np.maximum((shortest[before] - without) / w, 0.0), CAP
                )
