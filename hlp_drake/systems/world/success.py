"""The paper's success test of a reach, shared by the planners that simulate and by the execution:
the target in the gripper's pre-grasp region and no object off the table, read ``settle_s`` after
the motion ends (``SuccessConfig``, a ``Scenario``'s ``success``)."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Annotated

import numpy as np

from hlp_drake.config.ranges import MAX_DURATION, NonNegativeFloat, Positive
from hlp_drake.scene.model import Scene


@dataclass(frozen=True)
class SuccessConfig:
    """The success test's settings.

    Attributes:
        pregrasp_margin: the target is inside the gripper's pre-grasp region when the tcp is within
            its radius plus this (horizontally) and within this of the keypoint height, m.
        settle_s: simulated time after the motion ends before the final state is read, s, in a
            rollout and in the execution alike (a rollout's end is where the execution of the same
            motion ends).
    """

    pregrasp_margin: NonNegativeFloat = 0.03
    settle_s: Annotated[float, Positive(upper=MAX_DURATION, zero_ok=True)] = 1.0


def half_extent(size: tuple[float, float, float]) -> float:
    """An object's horizontal radius as the success test sees it: half its larger side, m."""
    return 0.5 * max(size[0], size[1])


def pregrasp_check(
    tcp: np.ndarray, target_position: np.ndarray, scene: Scene, *, tcp_height: float, margin: float
) -> tuple[bool, float]:
    """Whether the target (centre at ``target_position``) is inside the gripper's pre-grasp region at
    tcp position ``tcp``: horizontally within the target's radius + ``margin``, and the tcp within
    ``margin`` of the grasp height. Also returns the horizontal distance."""
    distance = float(np.hypot(*(np.asarray(tcp)[:2] - np.asarray(target_position)[:2])))
    inside = distance <= half_extent(scene.target.size) + margin and abs(tcp[2] - tcp_height) <= margin
    return inside, distance


def reach_problem(fallen: Iterable[str], inside: bool, distance: float) -> str | None:
    """Why a reach failed the success test (None if it passed)."""
    fallen = list(fallen)
    if fallen:
        return f"objects fell off the table: {', '.join(fallen)}"
    if not inside:
        return f"the target is not in the gripper's pre-grasp region (tcp {distance:.3f} m away)"
    return None


__all__ = ["SuccessConfig", "half_extent", "pregrasp_check", "reach_problem"]
