"""When objects moved (reference 3.4, 3.5): the moved obstacle of each row and its motion period."""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import numpy as np

from hlp_drake.dataset.records import ARM_PARTS, Interaction

MOTION_TOLERANCE = 1e-3  # m per frame (the original's pos_change_tol)
MOVE_KINDS = ("PickedUp", "Pushed")
LIMBS = ARM_PARTS  # the acting body parts in the interaction log


def motion_period(
    positions: np.ndarray, *, faithful: bool, tolerance: float = MOTION_TOLERANCE
) -> tuple[int, int] | None:
    """(first, last) frame of an object's motion, or None if it never moved.

    A frame pair counts as motion when the object moved more than ``tolerance`` between them. The
    original looks at the lateral coordinate only (world y; depth-wise motion is invisible to it);
    the fixed mode at the planar displacement. The period starts one frame before the first moving
    pair and ends at the frame after the last one, as in the original.
    """
    planar = np.asarray(positions)[:, :2]
    step = np.abs(np.diff(planar[:, 1])) if faithful else np.linalg.norm(np.diff(planar, axis=0), axis=1)
    moving = np.flatnonzero(step > tolerance)
    if len(moving) == 0:
        return None
    return max(int(moving[0]) - 1, 0), int(moving[-1]) + 1


def first_moved_per_row(
    interactions: Iterable[Interaction], row_of: Mapping[str, int], *, faithful: bool
) -> dict[int, str]:
    """The obstacle each row's decision is about: the first one picked up or pushed in that row.

    The original takes every PickedUp/Pushed row except those acting on the Target, including
    pushes of one obstacle by another (a carried obstacle bumping its neighbour); the fixed mode
    keeps only interactions whose acting body is the arm, since an object-on-object push is not a
    decision. Per row, the interaction with the earliest start wins.
    """
    first: dict[str, float] = {}
    for event in interactions:
        if event.kind not in MOVE_KINDS or event.non_dominant not in row_of:
            continue
        if not faithful and event.dominant not in LIMBS:
            continue
        first.setdefault(event.non_dominant, event.start_time)
    chosen: dict[int, tuple[float, str]] = {}
    for name, start in first.items():
        row = row_of[name]
        if row not in chosen or start < chosen[row][0]:
            chosen[row] = (start, name)
    return {row: name for row, (_, name) in sorted(chosen.items())}
