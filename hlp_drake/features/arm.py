"""Arm-configuration regression features Xa (reference 4.5)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from hlp_drake.features.direction import direction_index
from hlp_drake.taskspace import mirror_direction

ARM_FEATURES = ("q1", "q2", "dx", "dy", "direction")


def arm_features(
    arm: Sequence[float], displacement: Sequence[float], direction: str | None, *, mirror: bool = False
) -> np.ndarray:
    """(5,): current (q1, q2), the hand's displacement to the next keypoint / arm length, its class.

    Args:
        arm: current shoulder and elbow angles, radians.
        displacement: planar hand displacement (world x, y) divided by the arm length.
        direction: direction class of the displacement.
        mirror: describe a left arm as its mirror image (y and left/right swapped), so that one
            model serves both arms; the angles are already mirror-invariant.
    """
    dx, dy = displacement
    if mirror:
        dy, direction = -dy, mirror_direction(direction)
    return np.array([arm[0], arm[1], dx, dy, direction_index(direction)], dtype=float)
