"""The initialiser's sub-goals for a kinematic planner (``sub_goals``) and what it may touch
(``allowed_objects``).

The sub-goals are the knots of the initialiser's joint trajectory in order (``KeypointIk``'s: the
start, the human-like plan's keypoints, the target; the straight line has the start and the target
only). The human-like plan names what it pushes ("move" and "release" keypoints); those and the
target are the objects the robot may touch, every other object and the table are obstacles.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from pydrake.trajectories import PiecewisePolynomial

    from hlp_drake.scene.model import Scene
    from hlp_drake.systems.planning.keyframes import Keyframes

PUSH_ACTIONS = ("move", "release")
"""The keypoints whose element is an object the plan pushes."""


def allowed_objects(scene: Scene, keyframes: Keyframes | None) -> frozenset[str]:
    """The target and the objects ``keyframes``' plan pushes."""
    pushed = () if keyframes is None else (k.element for k in keyframes.keypoints if k.action in PUSH_ACTIONS)
    return frozenset({scene.target.name, *(name for name in pushed if name)})


def sub_goals(initial: PiecewisePolynomial) -> np.ndarray:
    """(k, positions) the knots of the initialiser's first-order hold, consecutive repeats dropped."""
    knots = np.column_stack([initial.value(t) for t in initial.get_segment_times()]).T
    kept = [knots[0]]
    for knot in knots[1:]:
        if np.max(np.abs(knot - kept[-1])) > 1e-9:
            kept.append(knot)
    return np.array(kept)


__all__ = ["PUSH_ACTIONS", "allowed_objects", "sub_goals"]
