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

from hlp_drake.taskspace.rect import Rect

SAMPLED_LINES = 11  # area_scan_resolution 10 -> 11 lines
SAMPLES_PER_LINE = 50


def band_polygon(p0: Sequence[float], p1: Sequence[float], offset: Sequence[float],
                 s_minus: float, s_plus: float) -> Polygon:
    """The parallelogram swept by segment p0->p1 shifted by t * offset for t in [-s_minus, s_plus]."""
    a, b, u = np.asarray(p0, float), np.asarray(p1, float), np.asarray(offset, float)
    corners = [a - s_minus * u, b - s_minus * u, b + s_plus * u, a + s_plus * u]
    return Polygon(corners)


def normal_of(p0: Sequence[float], p1: Sequence[float]) -> np.ndarray:
    """Unit normal of p0->p1 (+90 degrees); (0, 1) for a zero-length segment."""
    d = np.asarray(p1, float) - np.asarray(p0, float)
    length = float(np.hypot(*d))
    return np.array([0.0, 1.0]) if length == 0.0 else np.array([-d[1], d[0]]) / length


def _clip(points: np.ndarray, axis: int, bound: np.ndarray, keep_above: bool) -> np.ndarray:
    """Clip closed polygons (k, K, 2) to the half-plane coordinate ``axis`` >= (or <=) ``bound`` (k,).

    Each edge contributes the two ends of its part inside the half-plane; an end outside is moved
    onto the clipping line (where the edge crosses it, else anywhere on the line). Consecutive
    points off the original edges then lie on the clipping line, which adds no area in the
    shoelace formula, so the fixed-size result (k, 2K, 2) has exactly the area of the clipped
    polygon (for convex input).
    """
    p = points
    q = np.concatenate([p[:, 1:], p[:, :1]], axis=1)
    b = bound[:, None]
    sign = 1.0 if keep_above else -1.0
    dp, dq = sign * (p[..., axis] - b), sign * (q[..., axis] - b)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.nan_to_num(np.clip(dp / (dp - dq), 0.0, 1.0))
    cut = p + t[..., None] * (q - p)
    cut[..., axis] = b
    start = np.where((dp >= 0.0)[..., None], p, cut)
    end = np.where((dq >= 0.0)[..., None], q, cut)
    return np.stack([start, end], axis=2).reshape(len(p), -1, 2)


def convex_rect_overlap(polygons: np.ndarray, rects: np.ndarray) -> np.ndarray:
    """Exact areas of convex polygons (n, K, 2) inside rectangles (m, 4): (n, m).

    Only pairs whose bounding boxes overlap are clipped, so sparse scenes stay cheap.
    """
    poly = np.asarray(polygons, float)
    r = np.asarray(rects, float).reshape(-1, 4)
    lo, hi = poly.min(axis=1), poly.max(axis=1)
    touching = (
        (lo[:, None, 0] < r[None, :, 2]) & (hi[:, None, 0] > r[None, :, 0])
        & (lo[:, None, 1] < r[None, :, 3]) & (hi[:, None, 1] > r[None, :, 1])
    )
    i, j = np.nonzero(touching)
    areas = np.zeros(touching.shape)
    if len(i) == 0:
        return areas
    clipped, box = poly[i], r[j]
    for axis, column, above in ((0, 0, True), (0, 2, False), (1, 1, True), (1, 3, False)):
        clipped = _clip(clipped, axis, box[:, column], above)
    x, y = clipped[..., 0], clipped[..., 1]
    areas[i, j] = 0.5 * np.abs(np.sum(x * np.roll(y, -1, axis=-1) - np.roll(x, -1, axis=-1) * y, axis=-1))
    return areas


def band_coverage(p0: np.ndarray, p1: np.ndarray, offsets: np.ndarray, s_minus: float, s_plus: float,
                  rects: np.ndarray) -> np.ndarray:
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


def band_coverage_sampled(p0: np.ndarray, p1: np.ndarray, offsets: np.ndarray, s_minus: float, s_plus: float,
                          rects: np.ndarray) -> np.ndarray:
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
    inside = (x >= r[None, :, 0, None]) & (x <= r[None, :, 2, None]) & (y >= r[None, :, 1, None]) & (
        y <= r[None, :, 3, None])  # (n, m, P)
    any_inside = inside.any(axis=2)
    x_hi = np.where(inside, x, -np.inf).max(axis=2)
    x_lo = np.where(inside, x, np.inf).min(axis=2)
    y_hi = np.where(inside, y, -np.inf).max(axis=2)
    y_lo = np.where(inside, y, np.inf).min(axis=2)
    area = np.where(any_inside, (x_hi - x_lo) * (y_hi - y_lo), 0.0)
    return area / ((r[:, 2] - r[:, 0]) * (r[:, 3] - r[:, 1]))[None, :]


def _rects(occluders: Sequence[Rect]) -> np.ndarray:
    return np.array([(o.x_min, o.y_min, o.x_max, o.y_max) for o in occluders], float).reshape(-1, 4)


def band_collision(p0: Sequence[float], p1: Sequence[float], occluders: Sequence[Rect], *,
                   half_width: float, offset: Sequence[float] | None = None) -> float:
    """Exact mean covered fraction of ``occluders`` by the band of ``half_width`` around p0->p1.

    Args:
        offset: the unit vector the band extends along; by default the segment's normal.
    """
    if not occluders:
        return 0.0
    u = normal_of(p0, p1) if offset is None else offset
    return float(band_coverage(p0, p1, u, half_width, half_width, _rects(occluders)).mean())


def band_collision_sampled(p0: Sequence[float], p1: Sequence[float], occluders: Sequence[Rect], *,
                           offset: Sequence[float], s_minus: float, s_plus: float) -> float:
    """The original code's sampled estimate (reference 4.6); all occluders count in the mean."""
    if not occluders:
        return 0.0
    return float(band_coverage_sampled(p0, p1, offset, s_minus, s_plus, _rects(occluders)).mean())
