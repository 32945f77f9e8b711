"""How much of the occupied space a band swept along a segment covers (a hand path or an arm link).

Two measures of the same quantity, mean over occluders of (covered part of the occluder / its area):
- ``band_collision_sampled``: the original code's estimate (11 parallel copies of the segment,
  50 samples each, the bounding box of the samples inside an occluder);
- ``band_collision``: the exact value from the band polygon (shapely).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import shapely
from shapely.geometry import Polygon, box

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


def band_collision(p0: Sequence[float], p1: Sequence[float], occluders: Sequence[Rect], *,
                   half_width: float, offset: Sequence[float] | None = None) -> float:
    """Exact mean covered fraction of ``occluders`` by the band of ``half_width`` around p0->p1.

    Args:
        offset: the unit vector the band extends along; by default the segment's normal.
    """
    if not occluders:
        return 0.0
    u = normal_of(p0, p1) if offset is None else offset
    band = band_polygon(p0, p1, u, half_width, half_width)
    if band.area == 0.0:
        return 0.0
    rects = [box(r.x_min, r.y_min, r.x_max, r.y_max) for r in occluders]
    covered = shapely.area(shapely.intersection(band, rects))
    return float(np.mean(covered / np.array([r.area for r in occluders])))


def band_collision_sampled(p0: Sequence[float], p1: Sequence[float], occluders: Sequence[Rect], *,
                           offset: Sequence[float], s_minus: float, s_plus: float) -> float:
    """The original code's sampled estimate (reference 4.6); all occluders count in the mean."""
    if not occluders:
        return 0.0
    shifts = np.linspace(-s_minus, s_plus, SAMPLED_LINES)[:, None] * np.asarray(offset, float)
    along = np.linspace(0.0, 1.0, SAMPLES_PER_LINE)[:, None]
    a, b = np.asarray(p0, float), np.asarray(p1, float)
    points = (a + along * (b - a))[None, :, :] + shifts[:, None, :]
    points = points.reshape(-1, 2)
    scores = []
    for rect in occluders:
        inside = points[rect.contains(points)]
        if len(inside) == 0:
            scores.append(0.0)
            continue
        extent = inside.max(axis=0) - inside.min(axis=0)
        scores.append(float(extent[0] * extent[1]) / rect.area)
    return float(np.mean(scores))
