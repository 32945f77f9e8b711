"""Direction features Xd of an obstacle to move: 8 free fractions + 2 direction classes (reference 4.3)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from hlp_drake.features.plane import corner_origin
from hlp_drake.segmentation.modes import Mode, is_faithful
from hlp_drake.taskspace import DIRECTIONS, TaskSpace, block_array, direction_of, free_fractions, rect_array

DIRECTION_FEATURES = (*(f"free_{d}" for d in DIRECTIONS), "hand_to_object", "object_to_target")
UNDEFINED_DIRECTION = -1  # class index of a zero displacement (the original's empty label)


def direction_index(name: str | None) -> int:
    """Index of a direction class in ``DIRECTIONS``; ``UNDEFINED_DIRECTION`` for None."""
    return UNDEFINED_DIRECTION if name is None else DIRECTIONS.index(name)


def direction_features(space: TaskSpace, name: str, *, hand: Sequence[float], mode: Mode,
                       training: bool = False, hand_to_object: str | None = None) -> np.ndarray:
    """Xd of obstacle ``name`` for a hand at ``hand``: (10,) = 8 free fractions, 2 class indices.

    Args:
        space: the task space (obstacle at its original position).
        name: the obstacle.
        hand: planar hand position the obstacle is approached from.
        mode: "fixed": the same rule for training and planning (hand and target directions
            between centres; the target counts as an occluder). "faithful": the original's
            train/plan mismatch (B6): in training the free space ignores the target and the hand
            direction is the demonstration's approach label ``hand_to_object``; at planning the
            target is an occluder, the front wall is not, and directions go to corner origins.
        training: whether the features describe a demonstration (faithful mode only).
        hand_to_object: the demonstration's approach direction (faithful training only).
    """
    rect = rect_array([space.rects[name]])
    target = rect_array([space.target])
    faithful = is_faithful(mode)
    if faithful and training:
        occluders = space.occluders()
    elif faithful:
        occluders = space.occluders(target=True, walls=("back", "left", "right"))
    else:
        occluders = space.occluders(target=True)
    free = free_fractions(block_array(rect, space.alpha), rect_array(occluders))[0]
    if faithful:
        corner, target_corner = corner_origin(rect[0]), corner_origin(target[0])
        if training:
            to_object = hand_to_object
        else:
            to_object = direction_of(*(corner - np.asarray(hand, float)), faithful=True)
        to_target = direction_of(*(target_corner - corner), faithful=True)
    else:
        centre = np.array(space.rects[name].center)
        to_object = direction_of(*(centre - np.asarray(hand, float)))
        to_target = direction_of(*(np.array(space.target.center) - centre))
    return np.concatenate([free, [direction_index(to_object), direction_index(to_target)]])
