"""Where a moved obstacle is expected to end up (reference 6.4, ``object_location_movement.m``)."""

from __future__ import annotations

from hlp_drake.taskspace import ALPHA, Rect, direction_blocks

CARDINAL_SHIFT = 0.2  # sideways shift of cardinal moves, fraction of the object's size


def relocated(rect: Rect, direction: str, alpha: float = ALPHA) -> Rect:
    """The region the obstacle is pushed into: its direction block, cardinal ones shifted sideways
    by 0.2 of the object's size so the moved object does not stay aligned with the row."""
    block = direction_blocks(rect, alpha)[direction]
    dx, dy = 0.0, 0.0
    if direction == "FF" or direction == "BB":
        dy = CARDINAL_SHIFT * rect.width  # the original shifts towards its -x, i.e. world +y
    elif direction == "LL" or direction == "RR":
        dx = CARDINAL_SHIFT * rect.depth
    return Rect(block.x_min + dx, block.y_min + dy, block.x_max + dx, block.y_max + dy)
