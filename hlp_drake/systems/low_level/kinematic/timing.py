"""``PathTiming``: how a kinematic planner times its joint path into a commanded motion
(``timed``), as ``KeypointIk`` times the initialiser's: every piece lasts the longest of its joint
motion at a fraction of the velocity limits, its tcp path at the tcp's speed, and a floor (and of
the planner's own time for it, if it has one)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Annotated

import numpy as np

from hlp_drake.config.ranges import MAX_DURATION, Positive
from hlp_drake.systems.low_level.control_sequence import ControlSequence

if TYPE_CHECKING:
    from hlp_drake.systems.low_level.kinematic.world import KinematicWorld


@dataclass(frozen=True)
class PathTiming:
    """How a path is timed (the defaults are ``MotionConfig``'s, the initialiser's timing).

    Attributes:
        tcp_speed: the tcp's speed along the path, m/s (pushes happen at it).
        joint_speed_fraction: the share of every joint's velocity limit used.
        min_piece_s: the shortest time between two knots, s.
    """

    tcp_speed: Annotated[float, Positive(0.01, 2.0)] = 0.1
    joint_speed_fraction: Annotated[float, Positive(0.01, 1.0)] = 0.5
    min_piece_s: Annotated[float, Positive(upper=MAX_DURATION)] = 0.02


def timed(
    world: KinematicWorld, path: np.ndarray, timing: PathTiming, planned: np.ndarray | None = None
) -> ControlSequence:
    """``path`` (k, positions), k >= 2, as a motion through its knots timed by ``timing`` (each piece
    at least its ``planned`` duration (k - 1,) where the planner timed it)."""
    path = np.asarray(path, dtype=float)
    velocity = world.limits[2]
    tcp = np.array([world.tcp(q) for q in path])
    joint_s = np.max(np.abs(np.diff(path, axis=0)) / (timing.joint_speed_fraction * velocity), axis=1)
    tcp_s = np.linalg.norm(np.diff(tcp, axis=0), axis=1) / timing.tcp_speed
    pieces = np.maximum.reduce([joint_s, tcp_s, np.full(len(joint_s), timing.min_piece_s)])
    if planned is not None:
        pieces = np.maximum(pieces, planned)
    return ControlSequence(np.concatenate([[0.0], np.cumsum(pieces)]), path)


__all__ = ["PathTiming", "timed"]
