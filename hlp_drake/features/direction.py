"""Direction features Xd of an obstacle to move: 8 free fractions + 2 direction classes (reference 4.3)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from hlp_drake.features.plane import corner_origin
from hlp_drake.scene.lazy import LazyRows
from hlp_drake.segmentation.modes import Mode, is_faithful
from hlp_drake.taskspace import (
    DIRECTIONS,
    TaskSpace,
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
    """The hand-independent part of Xd for several obstacles, each obstacle's computed the first
    time it is asked about (``LazyRows``: a planner moves few of a scene's obstacles).

    Per obstacle: the free fractions of its direction blocks, the point directions are measured
    from (its centre; its corner origin in faithful mode) and the class index of the direction
    from it to the target.
    """

    def __init__(self, space: TaskSpace, names: Sequence[str], *, mode: Mode, training: bool = False) -> None:
        self.faithful = is_faithful(mode)
        positions = [space.obstacle_index[n] for n in names]
        self._rects = space.obstacle_bounds[positions].reshape(-1, 4)
        self._blocks = space.obstacle_blocks[positions].reshape(-1, 8, 4)
        if self.faithful and training:
            self._occluders = space.occluder_bounds()
        elif self.faithful:
            self._occluders = space.occluder_bounds(target=True, walls=("back", "left", "right"))
        else:
            self._occluders = space.occluder_bounds(target=True)
        target = rect_array([space.target])
        self._target_origin = corner_origin(target[0]) if self.faithful else np.array(space.target.center)
        self._rows = LazyRows(len(self._rects), self._compute)

    def _compute(self, index: np.ndarray) -> np.ndarray:
        """(k, 11) per obstacle of ``index``: 8 free fractions, origin (x, y), direction class to the target."""
        rects = self._rects[index]
        free = free_fractions(self._blocks[index], self._occluders)
        origins = corner_origin(rects) if self.faithful else rect_centres(rects)
        to_target = [
            direction_index(direction_of(*(self._target_origin - o), faithful=self.faithful)) for o in origins
        ]
        return np.column_stack([free, origins, np.asarray(to_target, float)])

    def hand_direction(self, k: int, hand: Sequence[float]) -> str | None:
        """Direction class from a hand at ``hand`` to obstacle ``k``."""
        return self.hand_directions([k], [hand])[0]

    def hand_directions(self, index: Sequence[int], hands: Sequence[Sequence[float]]) -> list[str | None]:
        """Direction class from each hand of ``hands`` to its obstacle of ``index``."""
        origins = self._rows[np.asarray(index, dtype=int)][:, 8:10]
        return [
            direction_of(*(o - np.asarray(hand, float)), faithful=self.faithful)
            for o, hand in zip(origins, hands)
        ]

    def features(self, index: int | np.ndarray, hand_class: int | np.ndarray) -> np.ndarray:
        """Xd of obstacles ``index`` approached from direction class indices ``hand_class``
        (broadcast together): (..., 10)."""
        index, hand_class = np.broadcast_arrays(index, hand_class)
        rows = self._rows[index]
        return np.concatenate([rows[..., :8], hand_class[..., None], rows[..., 10:]], axis=-1)
