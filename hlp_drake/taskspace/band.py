"""How much of the occupied space a band swept along a segment covers (a hand path or an arm link).

Two measures of the same quantity, mean over occluders of (covered part of the occluder / its area):
- ``band_collision_sampled``: the original code's estimate (11 parallel copies of the segment,
  50 samples each, the bounding box of the samples inside an occluder);
- ``band_collision``: the exact value from the band polygon (shapely).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from shapely.geometry import Polygon

from hlp_drake.taskspace.model import rect_array
from hlp_drake.taskspace.rect import Rect

SAMPLED_LINES = 11  # area_scan_resolution 10 -> 11 lines
SAMPLES_PER_LINE = 50


def band_polygon(
    p0: Sequence[float], p1: Sequence[float], offset: Sequence[float], s_minus: float, s_plus: float
) -> Polygon:
    """The parallelogram swept by segment p0->p1 shifted by t * offset for t in [-s_minus, s_plus]."""
    a, b, u = np.asarray(p0, float), np.asarray(p1, float), np.asarray(offset, float)
    corners = [a - s_minus * u, b - s_minus * u, b + s_plus * u, a + s_plus * u]
    return Polygon(corners)


def normal_of(p0: Sequence[float], p1: Sequence[float]) -> np.ndarray:
    """Unit normal of p0->p1 (+90 degrees); (0, 1) for a zero-length segment."""
    d = np.asarray(p1, float) - np.asarray(p0, float)
    length = float(np.hypot(*d))
    return np.array([0.0, 1.0]) if length == 0.0 else np.array([-d[1], d[0]]) / length


def _relu_mean(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Mean of max(0, v) along a segment over which v runs linearly from ``a`` to ``b``."""
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    with np.errstate(divide="ignore", invalid="ignore"):
        crossing = hi * hi / (2.0 * (hi - lo))
    return np.where(lo >= 0.0, 0.5 * (a + b), np.where(hi > 0.0, crossing, 0.0))


def _relation(
    x: np.ndarray, y: np.ndarray, qx: np.ndarray, qy: np.ndarray, box: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Whether each convex polygon (edges (x, y) -> (qx, qy), each (k, K)) is apart from its box
    (k, 4) (on the outer side of one of its own edges, touching included: they share no area),
    and whether it contains it."""
    ex, ey = qx - x, qy - y
    orientation = np.sign(np.sum(x * qy - qx * y, axis=1))[:, None, None]
    cx, cy = box[:, None, [0, 2, 2, 0]], box[:, None, [1, 1, 3, 3]]  # the corners, (k, 1, 4)
    left = orientation * (ex[..., None] * (cy - y[..., None]) - ey[..., None] * (cx - x[..., None]))
    edge = (ex != 0.0) | (ey != 0.0)
    apart = np.any(np.all(left <= 0.0, axis=2) & edge, axis=1)
    contains = (orientation[:, 0, 0] != 0.0) & np.all((left >= 0.0) | ~edge[..., None], axis=(1, 2))
    return apart, contains


def _paired_overlap(poly: np.ndarray, box: np.ndarray) -> np.ndarray:
    """Areas of convex polygons (k, K, 2) inside boxes (k, 4), paired: (k,).

    Green's theorem over the polygon's edges: each edge's part within the box's x range adds its
    integral of the height of the box below the edge (its y clamped to the box), signed by its
    direction. Shapes that share no area get exactly 0, a contained box exactly its area.
    """
    x, y = poly[..., 0], poly[..., 1]
    following = np.roll(np.arange(poly.shape[1]), -1)
    qx, qy = x[:, following], y[:, following]
    lo, hi = box[:, 0, None], box[:, 2, None]
    u, v = np.minimum(np.maximum(x, lo), hi), np.minimum(np.maximum(qx, lo), hi)
    dx = qx - x
    slope = (qy - y) / np.where(dx != 0.0, dx, 1.0)
    # The edge's y at u and at v, each above the box's bottom and above its top: (k, K, 2, 2).
    above = (y[..., None] + (np.stack([u, v], axis=-1) - x[..., None]) * slope[..., None])[..., None] - box[
        :, None, None, [1, 3]
    ]
    mean = _relu_mean(above[..., 0, :], above[..., 1, :])
    inside = mean[..., 0] - mean[..., 1]
    apart, contains = _relation(x, y, qx, qy, box)
    full = (box[:, 2] - box[:, 0]) * (box[:, 3] - box[:, 1])
    return np.where(apart, 0.0, np.where(contains, full, np.abs(np.sum((u - v) * inside, axis=1))))


def _touching(lo: np.ndarray, hi: np.ndarray, rects: np.ndarray) -> np.ndarray:
    """Whether boxes [lo, hi] (..., 2) and rectangles (..., 4) overlap (broadcast)."""
    return (
        (lo[..., 0] < rects[..., 2])
        & (hi[..., 0] > rects[..., 0])
        & (lo[..., 1] < rects[..., 3])
        & (hi[..., 1] > rects[..., 1])
    )


def convex_rect_overlap(polygons: np.ndarray, rects: np.ndarray) -> np.ndarray:
    """Exact areas of convex polygons (n, K, 2) inside rectangles (m, 4): (n, m).

    Only pairs whose bounding boxes overlap are measured, so sparse scenes stay cheap.
    """
    poly = np.asarray(polygons, float)
    r = np.asarray(rects, float).reshape(-1, 4)
    areas = np.zeros((len(poly), len(r)))
    if len(poly) == 0:
        return areas
    lo, hi = poly.min(axis=1), poly.max(axis=1)
    near = np.flatnonzero(_touching(lo.min(axis=0), hi.max(axis=0), r))  # rectangles within reach of any
    i, j = np.nonzero(_touching(lo[:, None], hi[:, None], r[near][None]))
    if len(i) == 0:
        return areas
    j = near[j]
    areas[i, j] = _paired_overlap(poly[i], r[j])
    return areas


def band_coverage(
    p0: np.ndarray, p1: np.ndarray, offsets: np.ndarray, s_minus: float, s_plus: float, rects: np.ndarray
) -> np.ndarray:
    """Exact covered fraction of each rectangle by each band: (n, m).

    Args:
        p0, p1: (n, 2) segment ends.
        offsets: (n, 2) unit vectors the bands extend along (from -s_minus to +s_plus).
        rects: (m, 4) rectangles (x_min, y_min, x_max, y_max).
    """
    a, b = np.asarray(p0, float).reshape(-1, 2), np.asarray(p1, float).reshape(-1, 2)
    u = np.asarray(offsets, float).reshape(-1, 2)
    r = np.asarray(rects, float).reshape(-1, 4)
    corners = np.stack([a - s_minus * u, b - s_minus * u, b + s_plus * u, a + s_plus * u], axis=1)
    covered = convex_rect_overlap(corners, r)
    return covered / ((r[:, 2] - r[:, 0]) * (r[:, 3] - r[:, 1]))[None, :]


def band_coverage_sampled(
    p0: np.ndarray, p1: np.ndarray, offsets: np.ndarray, s_minus: float, s_plus: float, rects: np.ndarray
) -> np.ndarray:
    """The original's sampled estimate of ``band_coverage`` (reference 4.6): (n, m).

    11 parallel copies of each segment, 50 samples each; per rectangle the bounding box of the
    samples inside it (closed bounds) over its area.
    """
    a, b = np.asarray(p0, float).reshape(-1, 2), np.asarray(p1, float).reshape(-1, 2)
    u = np.asarray(offsets, float).reshape(-1, 2)
    r = np.asarray(rects, float).reshape(-1, 4)
    shifts = np.linspace(-s_minus, s_plus, SAMPLED_LINES)
    along = np.linspace(0.0, 1.0, SAMPLES_PER_LINE)
    base = a[:, None, :] + along[None, :, None] * (b - a)[:, None, :]  # (n, S, 2)
    points = (base[:, None, :, :] + shifts[None, :, None, None] * u[:, None, None, :]).reshape(len(a), -1, 2)
    x, y = points[:, None, :, 0], points[:, None, :, 1]  # (n, 1, P)
    inside = (
        (x >= r[None, :, 0, None])
        & (x <= r[None, :, 2, None])
        & (y >= r[None, :, 1, None])
        & (y <= r[None, :, 3, None])
    )  # (n, m, P)
    any_inside = inside.any(axis=2)
    x_hi = np.where(inside, x, -np.inf).max(axis=2)
    x_lo = np.where(inside, x, np.inf).min(axis=2)
    y_hi = np.where(inside, y, -np.inf).max(axis=2)
    y_lo = np.where(inside, y, np.inf).min(axis=2)
    area = np.where(any_inside, (x_hi - x_lo) * (y_hi - y_lo), 0.0)
    return area / ((r[:, 2] - r[:, 0]) * (r[:, 3] - r[:, 1]))[None, :]


def band_collision(
    p0: Sequence[float],
    p1: Sequence[float],
    occluders: Sequence[Rect],
    *,
    half_width: float,
    offset: Sequence[float] | None = None,
) -> float:
    """Exact mean covered fraction of ``occluders`` by the band of ``half_width`` around p0->p1.

    Args:
        offset: the unit vector the band extends along; by default the segment's normal.
    """
    if not occluders:
        return 0.0
    u = normal_of(p0, p1) if offset is None else offset
    return float(band_coverage(p0, p1, u, half_width, half_width, rect_array(occluders)).mean())


def band_collision_sampled(
    p0: Sequence[float],
    p1: Sequence[float],
    occluders: Sequence[Rect],
    *,
    offset: Sequence[float],
    s_minus: float,
    s_plus: float,
) -> float:
    """The original code's sampled estimate (reference 4.6); all occluders count in the mean."""
    if not occluders:
        return 0.0
    return float(band_coverage_sampled(p0, p1, offset, s_minus, s_plus, rect_array(occluders)).mean())
