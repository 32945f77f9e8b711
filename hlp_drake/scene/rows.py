"""Rows of obstacles: clusters of obstacle depths (world x), nearest the start first."""

from __future__ import annotations

import statistics
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from hlp_drake.scene.geometry import footprint_bounds
from hlp_drake.scene.model import Scene

DEFAULT_TOLERANCE_FRACTION = 0.5  # of the median obstacle depth


@dataclass(frozen=True)
class Row:
    """Obstacles whose depths cluster together.

    Attributes:
        index: 1 for the row nearest the start, counting away from it.
        x: mean depth (world x) of the members' centres, m.
        x_min, x_max: depth extent of the members' footprints, m.
        members: obstacle names, ordered from left (+y) to right as seen from the start.
    """

    index: int
    x: float
    x_min: float
    x_max: float
    members: tuple[str, ...]


def find_rows(
    scene: Scene,
    tolerance: float | None = None,
    bounds: Mapping[str, tuple[float, float, float, float]] | None = None,
) -> list[Row]:
    """Cluster obstacle centres along x (single linkage): neighbours closer than ``tolerance`` join.

    Args:
        scene: the scene.
        tolerance: largest depth difference (m) between neighbouring centres of one row; by default
            half the median obstacle depth, so exact rows and roughly aligned rows both cluster.
        bounds: the obstacles' footprint bounds by name, if already known.
    """
    obstacles = list(scene.obstacles)
    if not obstacles:
        return []
    if bounds is None:
        bounds = {o.name: footprint_bounds(o) for o in obstacles}
    if tolerance is None:
        depths = [bounds[o.name][2] - bounds[o.name][0] for o in obstacles]
        tolerance = DEFAULT_TOLERANCE_FRACTION * statistics.median(depths)
    order = sorted(obstacles, key=lambda o: (o.x, -o.y))
    clusters: list[list] = [[order[0]]]
    for obstacle in order[1:]:
        if obstacle.x - clusters[-1][-1].x <= tolerance:
            clusters[-1].append(obstacle)
        else:
            clusters.append([obstacle])
    rows = []
    for index, members in enumerate(clusters, start=1):
        members = sorted(members, key=lambda o: -o.y)
        rows.append(
            Row(
                index=index,
                x=float(np.mean([o.x for o in members])),
                x_min=min(bounds[o.name][0] for o in members),
                x_max=max(bounds[o.name][2] for o in members),
                members=tuple(o.name for o in members),
            )
        )
    return rows
