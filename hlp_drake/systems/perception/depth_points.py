"""Depth images to world points, and the table: a RANSAC plane, its edges, and whether the cameras saw
past them.

``CameraView`` is one camera's frame as ``ScenePerception`` reads it (depth, labels, pose,
intrinsics); ``view_points`` turns every pixel with a depth into a world point that remembers its
camera and pixel; ``fit_table`` finds the table (scikit-learn's ``RANSACRegressor`` on a seeded
sample, refined by least squares on all points) and its extent.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field, fields, replace

import numpy as np
import sklearn
from pydrake.math import RigidTransform
from pydrake.systems.sensors import CameraInfo
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.linear_model import RANSACRegressor

MAX_TILT = np.tan(np.radians(10.0))
"""A table plane tilts less than 10 degrees from horizontal (the world's z is up)."""
MIN_TABLE_POINTS = 500
MIN_TABLE_SHARE = 0.1
"""The table plane holds at least this many points and this share of the points with a depth."""
EDGE_SAMPLES = 7
"""Points sampled along each table edge for the visibility test."""
NEIGHBOURS = ((0, 1), (0, -1), (1, 0), (-1, 0))
"""A pixel's 4-neighbours, (rows, columns) away."""
EDGES = ("front", "right", "back", "left")
"""The table's edges in the order of its bounds (x_min, y_min, x_max, y_max), as seen from the start."""
RENDERED_PIXEL_CENTRE = 0.5
"""Where Drake's VTK renderer samples pixel (col, row): at (col + 0.5, row + 0.5) of ``CameraInfo``'s
model, whose documentation puts pixel centres at whole coordinates (drake#10190). Measured: the
depths of a tilted view of a plane fit the model with the principal point half a pixel up and left
of ``CameraInfo``'s and its focal length exactly, to 1e-7 m, on Drake 1.51 and 1.58."""


@dataclass(frozen=True)
class CameraView:
    """One camera's frame: ``depth`` (h, w) in metres along the optical axis (NaN, 0 or inf where
    there is none), ``labels`` (h, w) its class image, ``X_WC`` its optical frame's pose, ``info``
    its intrinsics."""

    depth: np.ndarray
    labels: np.ndarray
    X_WC: RigidTransform
    info: CameraInfo

    def ground_sample(self, depth: float | np.ndarray) -> float | np.ndarray:
        """The width of one pixel seen at ``depth``, m."""
        return depth / self.info.focal_x()

    def project(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(columns, rows, depths) of the world ``points`` (n, 3) in this image (depth <= 0: behind)."""
        p_C = self.X_WC.inverse().multiply(np.asarray(points, float).T)
        z = p_C[2]
        with np.errstate(divide="ignore", invalid="ignore"):
            u = self.info.focal_x() * p_C[0] / z + self.info.center_x() - RENDERED_PIXEL_CENTRE
            v = self.info.focal_y() * p_C[1] / z + self.info.center_y() - RENDERED_PIXEL_CENTRE
        return u, v, z

    def sees(self, points: np.ndarray, margin: float = 0.0) -> np.ndarray:
        """Per world point (n, 3): whether it lies in front of the camera and inside the image,
        ``margin`` pixels from its border."""
        u, v, z = self.project(points)
        w, h = self.info.width(), self.info.height()
        return (z > 0) & (u >= margin) & (u <= w - 1 - margin) & (v >= margin) & (v <= h - 1 - margin)


@dataclass(frozen=True)
class Points:
    """World points from the pixels with a depth: ``xyz`` (n, 3), and per point its ``camera``
    (index into the views), ``row``, ``col``, ``depth`` (along its camera's axis, m) and ``label``
    (the class image's value)."""

    xyz: np.ndarray
    camera: np.ndarray
    row: np.ndarray
    col: np.ndarray
    depth: np.ndarray
    label: np.ndarray

    def subset(self, mask: np.ndarray) -> Points:
        return Points(*(getattr(self, f.name)[mask] for f in fields(self)))

    def __len__(self) -> int:
        return len(self.xyz)


def valid_depth(depth: np.ndarray) -> np.ndarray:
    """Pixels with a depth: finite and positive (Drake marks too near 0, too far inf; dropout NaN)."""
    return np.isfinite(depth) & (depth > 0)


@functools.lru_cache(maxsize=16)
def _rays(width: int, height: int, fx: float, fy: float, cx: float, cy: float) -> np.ndarray:
    """(h, w, 3) per pixel, the point at unit depth in the camera frame."""
    col, row = np.meshgrid(
        np.arange(width) + RENDERED_PIXEL_CENTRE, np.arange(height) + RENDERED_PIXEL_CENTRE
    )
    return np.dstack([(col - cx) / fx, (row - cy) / fy, np.ones((height, width))])


def _pixel_rays(
    views: list[CameraView], points: Points, offset: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Per point (n, 3): the ray in the world (the point at unit depth, relative to the camera)
    through its pixel's centre moved by ``offset`` pixels (n, 2: columns, rows; none if None), and
    its camera's position."""
    rays, origins = np.zeros((len(points), 3)), np.zeros((len(points), 3))
    for k, view in enumerate(views):
        mine = points.camera == k
        info, X = view.info, view.X_WC
        grid = _rays(
            info.width(), info.height(), info.focal_x(), info.focal_y(), info.center_x(), info.center_y()
        )
        ray = grid[points.row[mine], points.col[mine]]
        if offset is not None:
            ray[:, :2] += offset[mine] / [info.focal_x(), info.focal_y()]
        rays[mine] = ray @ X.rotation().matrix().T
        origins[mine] = X.translation()
    return rays, origins


def on_plane(
    points: Points,
    views: list[CameraView],
    coefficients: tuple[float, float, float | np.ndarray],
    offset: np.ndarray | None = None,
) -> np.ndarray:
    """(n, 3): where each point's pixel ray (through its pixel's centre moved by ``offset`` pixels:
    n, 2, columns and rows) meets the plane z = a x + b y + c (its depth's noise left out; ``c``
    one for all or one per point)."""
    a, b, c = coefficients
    rays, origins = _pixel_rays(views, points, offset)
    normal = np.array([-a, -b, 1.0])
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (c - np.einsum("ij,j->i", origins, normal)) / (rays @ normal)
    return origins + t[:, None] * rays


def pixel_points(views: list[CameraView], masks: list[np.ndarray]) -> Points:
    """The world points of each view's pixels where its (h, w) ``masks`` entry is True (they must
    have a depth), camera by camera, row-major."""
    parts = []
    for k, (view, mask) in enumerate(zip(views, masks)):
        info, flat = view.info, mask.ravel()
        pixel = np.flatnonzero(flat)
        row, col = np.divmod(pixel.astype(np.int32), np.int32(mask.shape[1]))
        z = view.depth.ravel()[pixel].astype(float)
        rays = _rays(
            info.width(), info.height(), info.focal_x(), info.focal_y(), info.center_x(), info.center_y()
        ).reshape(-1, 3)[pixel]
        X = view.X_WC
        xyz = (rays * z[:, None]) @ X.rotation().matrix().T + X.translation()
        camera = np.full(len(z), k, dtype=np.int16)
        parts.append((xyz, camera, row, col, z, view.labels.ravel()[pixel].astype(np.int32)))
    if not parts:
        empty = np.zeros(0, np.int32)
        return Points(np.zeros((0, 3)), empty, empty, empty, np.zeros(0), empty)
    return Points(*(np.concatenate(column) for column in zip(*parts)))


def view_points(views: list[CameraView]) -> tuple[Points, int]:
    """Every pixel with a depth as a world point, and the number of pixels without one."""
    masks = [valid_depth(v.depth) for v in views]
    return pixel_points(views, masks), sum(int(m.size - m.sum()) for m in masks)


class _Plane(RegressorMixin, BaseEstimator):
    """z = a x + b y + c by least squares: ``RANSACRegressor``'s base estimator for planes, without
    ``LinearRegression``'s input checks on every 3-point trial (RANSAC checks its input once; this
    is 6x faster on a frame's sample)."""

    def fit(self, X: np.ndarray, y: np.ndarray) -> _Plane:
        A = np.column_stack([X, np.ones(len(X))])
        (a, b, c), *_ = np.linalg.lstsq(A, y, rcond=None)
        self.coef_, self.intercept_ = np.array([a, b]), float(c)
        return self

    def predict(self, X: np.ndarray) -> np.ndarray:
        return X @ self.coef_ + self.intercept_

    def score(self, X: np.ndarray, y: np.ndarray) -> float:
        """R squared, as ``LinearRegression``'s (RANSAC's tie-break between equal inlier counts)."""
        total = float(np.sum((y - np.mean(y)) ** 2))
        return 1.0 - float(np.sum((y - self.predict(X)) ** 2)) / total if total > 0 else 0.0


@dataclass(frozen=True)
class TablePlane:
    """The fitted table: the plane z = a x + b y + c and its points' extent.

    Attributes:
        coefficients: (a, b, c).
        bounds: (x_min, y_min, x_max, y_max) of the table top, from where the rays through the
            middles of the steps from its pixels to others meet the plane (``step_crossings``;
            not its noisy points: their extremes lie beyond the edges): per side the mean of
            those within a pixel of the extreme.
        inliers: how many points lie on it.
        pixel: the width of a pixel seen on it (the median over its points), m.
        unseen_edges: the edges (``EDGES``) the cameras did not see past (the table may go on there).
        heights: per view of the fit, ``height_image`` of it (kept for the frame's other steps).
    """

    coefficients: tuple[float, float, float]
    bounds: tuple[float, float, float, float]
    inliers: int
    pixel: float
    unseen_edges: tuple[str, ...] = ()
    heights: tuple[np.ndarray, ...] = field(default=(), compare=False, repr=False)

    def height_above(self, xyz: np.ndarray) -> np.ndarray:
        """Per point (n, 3), its height above the plane, m."""
        a, b, c = self.coefficients
        return xyz[:, 2] - (a * xyz[:, 0] + b * xyz[:, 1] + c)

    def height_image(self, view: CameraView) -> np.ndarray:
        """(h, w) per pixel of ``view``, the height of its point above the plane, m (NaN or inf
        where it has no depth): the plane's normal (-a, -b, 1) along the pixel's ray, times the
        depth, plus the camera's height above the plane."""
        a, b, c = self.coefficients
        info, X = view.info, view.X_WC
        rays = _rays(
            info.width(), info.height(), info.focal_x(), info.focal_y(), info.center_x(), info.center_y()
        )
        normal = np.array([-a, -b, 1.0])
        along = rays @ (X.rotation().matrix().T @ normal)
        with np.errstate(invalid="ignore"):
            return view.depth * along + (normal @ X.translation() - c)

    def height_at(self, x: float, y: float) -> float:
        a, b, c = self.coefficients
        return float(a * x + b * y + c)


def fit_table(
    views: list[CameraView],
    masks: list[np.ndarray],
    *,
    tolerance: float,
    sample: int,
    seed: int,
    margin: float,
) -> TablePlane | str:
    """The table under the pixels of ``views`` where ``masks`` (h, w each) are True (pixels with a
    depth, the robot's left out), or why there is none.

    The largest plane by RANSAC on ``sample`` of those pixels' points drawn with ``seed``,
    refitted by least squares to the sample's points within ``tolerance`` of it; the table's
    pixels are all those within ``tolerance`` of the refit (by ``TablePlane.height_image``: no
    pixel but the sample's becomes a point). The plane must be within 10 degrees of horizontal and
    hold ``MIN_TABLE_POINTS`` points and ``MIN_TABLE_SHARE`` of all. Its bounds come from the
    steps out of its region in the image (``TablePlane.bounds``; a region's extremes lie on its
    border: the image maps to the plane by a homography).
    """
    n = sum(int(m.sum()) for m in masks)
    if n < MIN_TABLE_POINTS:
        return "no table plane found (too few pixels with a depth)"
    rng = np.random.default_rng(seed)
    drawn = rng.choice(n, size=min(sample, n), replace=False)
    chosen = np.sort(drawn)
    picked, start = [], 0
    for mask in masks:
        flat = np.zeros(mask.size, bool)
        count = int(mask.sum())
        mine = chosen[(chosen >= start) & (chosen < start + count)] - start
        flat[np.flatnonzero(mask.ravel())[mine]] = True
        picked.append(flat.reshape(mask.shape))
        start += count
    sampled = pixel_points(views, picked).subset(np.argsort(np.argsort(drawn)))  # in the drawn order
    xy, z = sampled.xyz[:, :2], sampled.xyz[:, 2]
    ransac = RANSACRegressor(
        _Plane(), min_samples=3, residual_threshold=tolerance, max_trials=100, random_state=seed
    )
    try:
        with sklearn.config_context(assume_finite=True, skip_parameter_validation=True):
            ransac.fit(xy, z)
    except ValueError:
        return "no table plane found"
    a, b = ransac.estimator_.coef_
    c = ransac.estimator_.intercept_
    sx, sy, sz = xy[:, 0], xy[:, 1], z
    for _ in range(2):  # least squares on the sample's points of the RANSAC plane, then of the refit's
        near = np.abs(sz - (a * sx + b * sy + c)) <= tolerance
        A = np.column_stack([sx[near], sy[near], np.ones(int(near.sum()))])
        (a, b, c), *_ = np.linalg.lstsq(A, sz[near], rcond=None)
    plane = TablePlane((float(a), float(b), float(c)), (0.0, 0.0, 0.0, 0.0), 0, 0.0)
    heights = tuple(plane.height_image(view) for view in views)
    with np.errstate(invalid="ignore"):
        on = [mask & (np.abs(h) <= tolerance) for mask, h in zip(masks, heights)]
    count = sum(int(o.sum()) for o in on)
    if count < max(MIN_TABLE_POINTS, MIN_TABLE_SHARE * n):
        return "no table plane found (no plane holds enough of the points)"
    if np.hypot(a, b) > MAX_TILT:
        return "no table plane found (the largest plane is not horizontal)"
    xy = step_crossings(views, on, (a, b, c))
    focal = np.array([v.info.focal_x() for v in views])
    pixel = float(np.median(sampled.depth / focal[sampled.camera]))
    bounds = _sides(xy, band=pixel)
    table = replace(
        plane, bounds=tuple(float(v) for v in bounds), inliers=count, pixel=pixel, heights=heights
    )
    return replace(table, unseen_edges=unseen_edges(table, views, margin))


def step_crossings(
    views: list[CameraView], regions: list[np.ndarray], coefficients: tuple[float, float, float]
) -> np.ndarray:
    """(m, 2): per step from a pixel of a view's region (h, w mask) to a 4-neighbour outside it
    (inside the image), where the ray through the step's middle meets the plane z = a x + b y + c.
    An edge crosses the step half way on average, where the pixel's own centre lies inside by
    half a pixel."""
    parts = []
    for dr, dc in NEIGHBOURS:
        stepping = []
        for region in regions:
            h, w = region.shape
            beyond = np.pad(region, 1, constant_values=True)[1 + dr : 1 + dr + h, 1 + dc : 1 + dc + w]
            stepping.append(region & ~beyond)
        points = pixel_points(views, stepping)
        half_step = np.broadcast_to([dc / 2.0, dr / 2.0], (len(points), 2))
        parts.append(on_plane(points, views, coefficients, half_step)[:, :2])
    return np.concatenate(parts)


def _sides(xy: np.ndarray, band: float) -> tuple[float, float, float, float]:
    """(x_min, y_min, x_max, y_max) of the points ``xy`` (n, 2) on a rectangle's outline: per side,
    the mean of the points within ``band`` of the extreme."""
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    low = [float(np.mean(xy[xy[:, i] <= lo[i] + band, i])) for i in (0, 1)]
    high = [float(np.mean(xy[xy[:, i] >= hi[i] - band, i])) for i in (0, 1)]
    return (*low, *high)


def unseen_edges(table: TablePlane, views: list[CameraView], margin: float) -> tuple[str, ...]:
    """The edges of ``table`` beyond which (by ``margin`` m, at the table's height) no camera sees
    at least half the points sampled along them: the table may go on out of view there."""
    x0, y0, x1, y1 = table.bounds
    s = (np.arange(EDGE_SAMPLES) + 0.5) / EDGE_SAMPLES
    xs, ys = x0 + s * (x1 - x0), y0 + s * (y1 - y0)
    lines = {
        "front": np.column_stack([np.full_like(ys, x0 - margin), ys]),
        "right": np.column_stack([xs, np.full_like(xs, y0 - margin)]),
        "back": np.column_stack([np.full_like(ys, x1 + margin), ys]),
        "left": np.column_stack([xs, np.full_like(xs, y1 + margin)]),
    }
    unseen = []
    for edge in EDGES:
        xy = lines[edge]
        xyz = np.column_stack([xy, [table.height_at(x, y) for x, y in xy]])
        seen = np.any([view.sees(xyz) for view in views], axis=0)
        if seen.mean() < 0.5:
            unseen.append(edge)
    return tuple(unseen)


__all__ = [
    "EDGES",
    "NEIGHBOURS",
    "CameraView",
    "Points",
    "TablePlane",
    "fit_table",
    "on_plane",
    "pixel_points",
    "step_crossings",
    "unseen_edges",
    "valid_depth",
    "view_points",
]
