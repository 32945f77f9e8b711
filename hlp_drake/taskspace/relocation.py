"""Where a moved obstacle is expected to end up (reference 6.4, ``object_location_movement.m``)."""

from __future__ import annotations

import numpy as np

from hlp_drake.taskspace.directions import DIRECTIONS
from hlp_drake.taskspace.model import ALPHA, block_array, rect_array
from hlp_drake.taskspace.rect import Rect

CARDINAL_SHIFT = 0.2  # sideways shift of cardinal moves, fraction of the object's size
# Per direction (order DIRECTIONS): whether a move shifts along x (by the depth) and along y (by the
# width): LL and RR along +x, FF and BB towards +y (the original's -x).
_SHIFTS = np.array([(d in ("LL", "RR"), d in ("FF", "BB")) for d in DIRECTIONS], dtype=float)


def relocated_array(
    rects: np.ndarray, alpha: float = ALPHA, *, blocks: np.ndarray | None = None
) -> np.ndarray:
    """(n, 8, 4): the region each of the (n, 4) rectangles is pushed into, per direction (order
    ``DIRECTIONS``): its direction block, cardinal ones shifted sideways by 0.2 of the object's
    size so the moved object does not stay aligned with the row. ``blocks``: the rectangles'
    ``block_array``, where known."""
    r = np.asarray(rects, dtype=float).reshape(-1, 4)
    blocks = block_array(r, alpha) if blocks is None else blocks
    size = np.column_stack([r[:, 2] - r[:, 0], r[:, 3] - r[:, 1]])  # (depth, width)
    shift = CARDINAL_SHIFT * size[:, None, :] * _SHIFTS[None]  # (n, 8, 2)
    return blocks + np.concatenate([shift, shift], axis=2)


def relocated(rect: Rect, direction: str, alpha: float = ALPHA) -> Rect:
    """The region the obstacle is pushed into (see ``relocated_array``)."""
    return Rect(*relocated_array(rect_array([rect]), alpha)[0, DIRECTIONS.index(direction)].tolist())
