"""The objects on the table from the points above it: clusters in plan view, their silhouettes, and
an upright box (with yaw) or cylinder fitted to each.

Seen from above, every point of an upright object (its top and the sides facing the camera) lies
over its footprint, and the pixels where the object ends against something further away (the
table, the background, a lower object) lie over the footprint's boundary: its *silhouette*.
Where something nearer hides it (a taller object, the robot), the object's end in the image is an
*occlusion* boundary, not its own. Shapes are fitted to the silhouette only, so a partly hidden
object keeps the outline of what shows: a circle (least squares) or the rectangle, over the yaws,
whose sides the silhouette lies on best; the one that fits better decides the shape.

The outline is the footprint's boundary without the pixel grid's bias: where the object's top ends
against something further away, the boundary crosses the step to the next pixel, on average half
way, so that edge's point is where the ray through the middle of the step meets the top's plane
(a pixel's own centre lies inside the footprint by half a pixel on average, and more so on the side
away from the camera: a quarter-pixel shift of every off-axis object towards the camera before).
A side's silhouette pixels (a wall facing the camera, where its points end at ``min_height``, or a
cylinder's sides) lie on the footprint's boundary themselves.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import ConvexHull, cKDTree

from hlp_drake.systems.perception.depth_points import (
    NEIGHBOURS,
    CameraView,
    Points,
    TablePlane,
    on_plane,
    valid_depth,
)

NEARER = 0.005
"""A neighbour pixel this much nearer the camera (m) hides what lies beyond: an occlusion boundary."""
YAW_STEPS = (30, 12, 10)
"""The yaw search: 30 yaws over a quarter turn (3 degrees apart), then 12 on each side of the best
(0.25 degrees apart), then 10 on each side of that (0.025 degrees apart)."""
COARSE_EDGE = 64
"""The coarsest yaws are scored on at most this many of the silhouette's points (evenly spaced)."""
TOP_BAND = 0.005
"""An object's top: its points within this (m) below the 99th percentile of their heights."""


@dataclass(frozen=True)
class Cluster:
    """One object's points: its ``points`` and, per point, whether its pixel lies on the silhouette,
    on an occlusion boundary or at the image's border; and where the object ends against something
    further away, per such step to a neighbour pixel the plan-view point (m, 2) where the ray
    through the step's middle meets the plane parallel to the table through the point
    (``step_points``), and that point's index (``step_of``, m)."""

    points: Points
    silhouette: np.ndarray
    occluded: np.ndarray
    at_border: np.ndarray
    step_points: np.ndarray
    step_of: np.ndarray

    def outline(self, on_top: np.ndarray) -> np.ndarray:
        """(m, 2) the footprint's boundary in plan view: per silhouette point ``on_top`` (n,) its
        steps' points, per other silhouette point the point itself (see the module's docstring)."""
        top_steps = on_top[self.step_of]
        own = self.silhouette.copy()
        own[self.step_of[top_steps]] = False
        return np.concatenate([self.points.xyz[own, :2], self.step_points[top_steps]])


@dataclass(frozen=True)
class Fit:
    """An upright shape fitted to a cluster.

    Attributes:
        shape: "box" or "cylinder".
        x, y, yaw: the footprint's centre and heading (a cylinder's yaw is 0), m and rad.
        size: (own x, own y, height), m.
        residual: root-mean-square distance of the silhouette from the fitted outline, m.
    """

    shape: str
    x: float
    y: float
    yaw: float
    size: tuple[float, float, float]
    residual: float


def cluster_points(
    points: Points, *, radius: float, min_points: int, linked: np.ndarray | None = None
) -> list[np.ndarray]:
    """Indices into ``points`` of each object's cluster (at least ``min_points`` points), largest first.

    Single linkage in plan view: points closer than ``radius`` in x and y are one object's
    (scipy's k-d tree pairs, then the graph's connected components). Objects stand apart on the
    table and an upright object's points all lie over its footprint, so its top and its sides
    join however tall it is, and two objects join only if their footprints come within ``radius``.
    With ``linked`` (a mask, ``linked_sample``) only those points are linked so; every other point
    joins the cluster of its nearest linked point within ``radius`` (none: noise).
    """
    n = len(points)
    if n < min_points:
        return []
    xy = points.xyz[:, :2]
    chosen = np.arange(n) if linked is None else np.flatnonzero(linked)
    if len(chosen) == 0:
        return []
    tree = cKDTree(xy[chosen])
    pairs = tree.query_pairs(radius, output_type="ndarray")
    m = len(chosen)
    graph = coo_matrix((np.ones(len(pairs), bool), (pairs[:, 0], pairs[:, 1])), shape=(m, m))
    _, labels = connected_components(graph, directed=False)
    if linked is not None:
        distance, nearest = tree.query(xy, distance_upper_bound=radius)
        joined = np.isfinite(distance)
        chosen, labels = np.flatnonzero(joined), labels[nearest[joined]]
    groups = np.split(chosen[np.argsort(labels, kind="stable")], np.cumsum(np.bincount(labels))[:-1])
    return sorted((g for g in groups if len(g) >= min_points), key=len, reverse=True)


def linked_sample(views: list[CameraView], points: Points, radius: float) -> np.ndarray | None:
    """The points ``cluster_points`` links, or None for all: those on every s-th row and column of
    their camera's image, s the largest stride whose neighbours stay within a third of ``radius``
    apart at the camera's furthest point (1 at the default camera: all). A point has ~(radius /
    pixel)^2 neighbours within ``radius``, so linking every point of a fine camera (4096 x 4096
    pixels) took 21 GB; the strided points keep each object's surface connected, and memory and time
    grow with the pixels, not with their square."""
    strides = np.ones(len(views), dtype=np.int64)
    for k, view in enumerate(views):
        mine = points.camera == k
        if mine.any():
            pixel = float(view.ground_sample(float(points.depth[mine].max())))
            strides[k] = max(1, int(radius / (3.0 * pixel)))
    if strides.max() == 1:
        return None
    stride = strides[points.camera]
    return (points.row % stride == 0) & (points.col % stride == 0)


def boundaries(
    views: list[CameraView], points: Points, groups: list[np.ndarray], border: int, table: TablePlane
) -> list[Cluster]:
    """Each group of ``points`` with its silhouette, occlusion and border pixels (4-neighbours in
    its camera's image: another group's pixel or the robot nearer by ``NEARER`` occludes; a pixel
    without a depth tells nothing; anything else ends the object, a step if it lies further by
    ``NEARER``) and its steps' points (``Cluster``; ``table``'s plane gives their planes)."""
    group = np.full(len(points), -1, dtype=np.int32)
    for g, members in enumerate(groups):
        group[members] = g
    silhouette = np.zeros(len(points), bool)
    occluded = np.zeros(len(points), bool)
    at_border = np.zeros(len(points), bool)
    steps = np.zeros((len(points), len(NEIGHBOURS)), bool)
    for k, view in enumerate(views):
        here = np.flatnonzero((points.camera == k) & (group >= 0))
        if not len(here):
            continue
        h, w = view.depth.shape
        row, col, mine = points.row[here], points.col[here], group[here]
        owner = np.full((h, w), -1, dtype=np.int32)
        owner[row, col] = mine
        own = view.depth[row, col]
        at_border[here] = (row < border) | (col < border) | (row >= h - border) | (col >= w - border)
        sil, occ = np.zeros(len(here), bool), np.zeros(len(here), bool)
        step = np.zeros((len(here), len(NEIGHBOURS)), bool)
        for d, (dr, dc) in enumerate(NEIGHBOURS):
            r, c = row + dr, col + dc
            inside = (r >= 0) & (r < h) & (c >= 0) & (c < w)
            r, c = np.clip(r, 0, h - 1), np.clip(c, 0, w - 1)
            other = inside & (owner[r, c] != mine)
            depth = view.depth[r, c]
            nearer = (depth < own - NEARER) | (depth == 0)
            ends = other & (valid_depth(depth) | np.isposinf(depth))
            occ |= other & nearer
            sil |= ends & ~nearer
            step[:, d] = ends & (depth > own + NEARER)
        silhouette[here], occluded[here], steps[here] = sil & ~occ, occ, step & ~occ[:, None]
    at, towards = np.nonzero(steps)  # by point, so by group once sorted stably
    stepped, (a, b, _) = points.subset(at), table.coefficients
    through = stepped.xyz[:, 2] - a * stepped.xyz[:, 0] - b * stepped.xyz[:, 1]
    half_step = np.array(NEIGHBOURS)[towards, ::-1] / 2.0  # (columns, rows)
    crossings = on_plane(stepped, views, (a, b, through), half_step)[:, :2]
    local = np.zeros(len(points), dtype=np.int64)  # each point's index in its group
    for members in groups:
        local[members] = np.arange(len(members))
    by_group = np.argsort(group[at], kind="stable")
    split = np.split(by_group, np.searchsorted(group[at][by_group], np.arange(1, len(groups) + 1)))
    return [
        Cluster(
            points.subset(members),
            silhouette[members],
            occluded[members],
            at_border[members],
            crossings[mine],
            local[at[mine]],
        )
        for members, mine in zip(groups, split)
    ]


def _circle(xy: np.ndarray) -> tuple[float, float, float, float]:
    """(x, y, radius, rms residual) of the least-squares circle through ``xy`` (Kasa's fit)."""
    A = np.column_stack([2.0 * xy, np.ones(len(xy))])
    (a, b, c), *_ = np.linalg.lstsq(A, (xy**2).sum(axis=1), rcond=None)
    r = float(np.sqrt(max(c + a * a + b * b, 0.0)))
    residual = float(np.sqrt(np.mean((np.hypot(xy[:, 0] - a, xy[:, 1] - b) - r) ** 2)))
    return float(a), float(b), r, residual


def _rectangles(yaws: np.ndarray, hull: np.ndarray, edge: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per yaw (k,): the RMS distance of the ``edge`` points from the nearest side of the rectangle
    at that yaw around the ``hull`` points, and the rectangles' bounds (k, 4: u0, v0, u1, v1) in
    their rotated frames."""
    c, s = np.cos(yaws)[:, None], np.sin(yaws)[:, None]
    hu, hv = hull[:, 0] * c + hull[:, 1] * s, -hull[:, 0] * s + hull[:, 1] * c
    eu, ev = edge[:, 0] * c + edge[:, 1] * s, -edge[:, 0] * s + edge[:, 1] * c
    lo_u, hi_u, lo_v, hi_v = (
        hu.min(1, keepdims=True),
        hu.max(1, keepdims=True),
        hv.min(1, keepdims=True),
        hv.max(1, keepdims=True),
    )
    d = np.minimum(np.minimum(eu - lo_u, hi_u - eu), np.minimum(ev - lo_v, hi_v - ev))
    bounds = np.column_stack([lo_u[:, 0], lo_v[:, 0], hi_u[:, 0], hi_v[:, 0]])
    return np.sqrt(np.mean(d**2, axis=1)), bounds


def _rectangle(xy: np.ndarray, edge: np.ndarray) -> tuple[float, np.ndarray, float]:
    """(yaw, bounds in the frame turned by it, rms residual) of the rectangle whose sides
    ``edge`` lies on best, searched coarse to fine (``YAW_STEPS``)."""
    hull = xy[ConvexHull(xy).vertices] if len(xy) >= 3 else xy
    first, *finer = YAW_STEPS
    step = (np.pi / 2) / first
    yaws = np.arange(first) * step
    sparse = edge[np.linspace(0, len(edge) - 1, min(len(edge), COARSE_EDGE)).astype(int)]
    best = yaws[int(np.argmin(_rectangles(yaws, hull, sparse)[0]))]
    for steps in finer:
        yaws = best + np.linspace(-step, step, 2 * steps + 1)
        residuals, bounds = _rectangles(yaws, hull, edge)
        k = int(np.argmin(residuals))
        best, step = yaws[k], step / steps
    return float(best), bounds[k], float(residuals[k])


def _top(heights: np.ndarray) -> tuple[float, np.ndarray]:
    """(height, per point whether it is on the top) of an object from its points' heights above
    the table: its top is the points within ``TOP_BAND`` below the 99th percentile, its height their
    median."""
    on_top = heights >= np.percentile(heights, 99, method="linear") - TOP_BAND
    return float(np.median(heights[on_top])), on_top


def _sides(edge: np.ndarray, yaw: float, bounds: np.ndarray, corner: float) -> np.ndarray:
    """The rectangle at ``yaw`` (bounds u0, v0, u1, v1 in the frame turned by it) with each side
    where the ``edge`` points nearest to it lie on average (those within ``corner`` of the side's
    ends left out); a side without such points keeps its place in ``bounds``."""
    c, s = np.cos(yaw), np.sin(yaw)
    uv = edge @ np.array([[c, -s], [s, c]])
    across = np.tile(uv, 2)  # per side (u0, v0, u1, v1): the coordinate across it
    nearest = np.argmin(np.abs(across - bounds), axis=1)
    sides = bounds.copy()
    for i in range(4):
        along, lo, hi = uv[:, 1 - i % 2], bounds[1 - i % 2], bounds[3 - i % 2]
        on = (nearest == i) & (along > lo + corner) & (along < hi - corner)
        if on.any():
            sides[i] = float(np.mean(across[on, i]))
    return sides


def fit_object(cluster: Cluster, heights: np.ndarray, pixel: float, *, cylinder: bool | None = None) -> Fit:
    """The upright box or cylinder of ``cluster`` (a cylinder if ``cylinder`` is True, a box if
    False, the better fit if None) to its outline (``Cluster.outline``), as tall as its top above
    the table (``heights``: per point); ``pixel``: a pixel's width on the object, m."""
    xy = cluster.points.xyz[:, :2]
    height, on_top = _top(heights)
    outline = cluster.outline(on_top)
    edge = outline if len(outline) >= 8 else xy
    cx, cy, r, circle_residual = _circle(edge)
    seen = np.concatenate([edge, xy[cluster.occluded]])  # where what shows of it ends
    yaw, bounds, box_residual = (0.0, None, np.inf) if cylinder else _rectangle(seen, edge)
    if cylinder or (cylinder is None and circle_residual < box_residual):
        return Fit("cylinder", cx, cy, 0.0, (2.0 * r, 2.0 * r, height), circle_residual)
    u0, v0, u1, v1 = _sides(edge, yaw, bounds, corner=pixel)
    u, v = (u0 + u1) / 2.0, (v0 + v1) / 2.0
    sides = [float(u1 - u0), float(v1 - v0)]
    turns = round(yaw / (np.pi / 2))  # the same box with its yaw in [-pi/4, pi/4], sides swapped if odd
    if turns % 2:
        sides.reverse()
    c, s = np.cos(yaw), np.sin(yaw)
    x, y = float(c * u - s * v), float(s * u + c * v)
    return Fit("box", x, y, yaw - turns * np.pi / 2, (*sides, height), box_residual)


__all__ = ["Cluster", "Fit", "boundaries", "cluster_points", "fit_object"]
