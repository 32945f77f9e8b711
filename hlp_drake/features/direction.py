"""Direction features Xd of an obstacle to move: 8 free fractions + 2 direction classes (reference 4.3)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from hlp_drake.features.plane import corner_origin
from hlp_drake.segmentation.modes import Mode, is_faithful
from hlp_drake.taskspace import (
    DIRECTIONS,
    TaskSpace,
    block_array,
    direction_of,
    free_fractions,
    rect_array,
    rect_centres,
)

DIRECTION_FEATURES = (*(f"free_{d}" for d in DIRECTIONS), "hand_to_object", "object_to_target")
UNDEFINED_DIRECTION = -1  # class index of a zero displacement (the original's empty label)


def direction_index(name: str | None) -> int:
    """Index of a direction class in ``DIRECTIONS``; ``UNDEFINED_DIRECTION`` for None."""
    return UNDEFINED_DIRECTION if name is None else DIRECTIONS.index(name)


def direction_features(
    space: TaskSpace,
    name: str,
    *,
    hand: Sequence[float],
    mode: Mode,
    training: bool = False,
    hand_to_object: str | None = None,
) -> np.ndarray:
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
    table = DirectionTable(space, [name], mode=mode, training=training)
    to_object = hand_to_object if is_faithful(mode) and training else table.hand_direction(0, hand)
    return table.features(0, direction_index(to_object))


class DirectionTable:
    """The hand-independent part of Xd for several obstacles, computed together.

    Attributes:
        free: (k, 8) free fractions of the direction blocks.
        origins: (k, 2) the points directions are measured from (centres; corner origins in faithful mode).
        to_target: (k,) class index of the direction from each obstacle to the target.
    """

    def __init__(self, space: TaskSpace, names: Sequence[str], *, mode: Mode, training: bool = False) -> None:
        self.faithful = is_faithful(mode)
        rects = space.obstacle_bounds[[space.obstacle_index[n] for n in names]].reshape(-1, 4)
        if self.faithful and training:
            occluders = space.occluder_bounds()
        elif self.faithful:
            occluders = space.occluder_bounds(target=True, walls=("back", "left", "right"))
        else:
            occluders = space.occluder_bounds(target=True)
        self.free = free_fractions(block_array(rects, space.alpha), occluders)
        target = rect_array([space.target])
        if self.faithful:
            self.origins, target_origin = corner_origin(rects), corner_origin(target[0])
        else:
            self.origins = rect_centres(rects)
            target_origin = np.array(space.target.center)
        self.to_target = np.array(
            [
                direction_index(direction_of(*(target_origin - o), faithful=self.faithful))
                for o in self.origins
            ],
            dtype=int,
        ).reshape(-1)

    def hand_direction(self, k: int, hand: Sequence[float]) -> str | None:
        """Direction class from a hand at ``hand`` to obstacle ``k``."""
        return direction_of(*(self.origins[k] - np.asarray(hand, float)), faithful=self.faithful)

    def features(self, index: int | np.ndarray, hand_class: int | np.ndarray) -> np.ndarray:
        """Xd of obstacles ``index`` approached from direction class indices ``hand_class``
        (broadcast together): (..., 10)."""
        index, hand_class = np.broadcast_arrays(index, hand_class)
        return np.concatenate(
            [self.free[index], hand_class[..., None], self.to_target[index][..., None]], axis=-1
        )
