"""``Workspace``: where a robot fixed in front of the table reaches, and the generators' tables kept
within it (``reach_scale``, ``within_reach``)."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from hlp_drake.errors import SceneError

if TYPE_CHECKING:
    from hlp_drake.scene.generators import RobotSceneRanges

EDGE_INSET = 0.10
"""Gen II: the start's and the target's distance from the table's side edges at least, m."""


@dataclass(frozen=True)
class Workspace:
    """Where a robot fixed in front of the table reaches: the tcp within ``reach`` of (x, y), the
    base's place in the scene's frame (x into the table from the middle of its front edge), m."""

    x: float
    y: float
    reach: float


def reach_scale(ranges: RobotSceneRanges, workspace: Workspace | None) -> float:
    """The one factor (at most 1) the generators scale their tables by so that the farthest start or
    target placed on ``ranges``' largest table is within ``workspace``'s reach; 1 for None (a mobile
    robot).

    Raises:
        SceneError: the factor would be below ``MIN_TABLE_SCALE`` (the objects would not fit).
    """
    if workspace is None:
        return 1.0

    def farthest(scale: float) -> float:  # a Gen II target in the far corner: the farthest point placed
        x = ranges.target_band[1] * ranges.table_length[1] * scale
        y = ranges.table_width[1] * scale / 2.0 - EDGE_INSET + abs(workspace.y)
        return math.hypot(x - workspace.x, y)

    if farthest(1.0) <= workspace.reach:
        return 1.0
    low, high = 0.0, 1.0  # farthest() grows with the scale: bisect
    for _ in range(40):
        middle = (low + high) / 2.0
        low, high = (middle, high) if farthest(middle) <= workspace.reach else (low, middle)
    if low < MIN_TABLE_SCALE:
        raise SceneError(
            f"a robot reaching {workspace.reach} m from ({workspace.x}, {workspace.y}) reaches too little "
            "of a table to generate scenes on"
        )
    return low


def within_reach(ranges: RobotSceneRanges, workspace: Workspace | None) -> RobotSceneRanges:
    """``ranges`` with the table's length and width scaled by ``reach_scale`` so that every generated
    start and target is within ``workspace``'s reach; ``ranges`` itself for None (a mobile robot).

    Gen II's obstacle footprints (box depth and width, cylinder diameter) scale by the same factor, as
    Gen I's scale with the table's width: a smaller table holds as much clutter for its size, not the
    same objects crowded three times as densely. Heights and the target (the gripper's) do not scale.
    """
    scale = reach_scale(ranges, workspace)
    if scale == 1.0:
        return ranges
    scaled = ("table_length", "table_width", "box_depth", "box_width", "cylinder_diameter")
    return replace(ranges, **{name: tuple(scale * v for v in getattr(ranges, name)) for name in scaled})


MIN_TABLE_SCALE = 0.5
"""The smallest table scale ``within_reach`` makes (the objects still have to fit)."""


__all__ = ["EDGE_INSET", "MIN_TABLE_SCALE", "Workspace", "reach_scale", "within_reach"]
