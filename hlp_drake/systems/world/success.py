"""The paper's success test of a reach, shared by the planners that simulate and by the execution:
the target in the gripper's pre-grasp region and no object off the table, read ``settle_s`` after
the motion ends (``SuccessConfig``, a ``Scenario``'s ``success``). ``ReachEnd.problem`` names the
real cause of a failure: an object that fell, the tcp too far from the target or off grasp height,
and beside it an object lifted off the table (on the gripper or on another object); a planner
accepting a motion also asks that nothing be lifted.
"""

from __future__ import annotations

from collections.abc import Sequence
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
        max_lift: an object whose centre ends higher than it started by more than this is lifted
            off the table (resting on the gripper or on another object), m: said beside a failure,
            and a planner that simulates accepts no motion that lifts one.
    """

    pregrasp_margin: NonNegativeFloat = 0.03
    settle_s: Annotated[float, Positive(upper=MAX_DURATION, zero_ok=True)] = 1.0
    max_lift: NonNegativeFloat = 0.02


def half_extent(size: tuple[float, float, float]) -> float:
    """An object's horizontal radius as the success test sees it: half its larger side, m."""
    return 0.5 * max(size[0], size[1])


@dataclass(frozen=True)
class ReachEnd:
    """Where a reach ended, as the success test reads it (object arrays in scene order, the target
    first).

    Attributes:
        tcp: (3,) the tcp's position.
        start, end: (m, 3) the objects' centres before and after.
        fallen: the objects off the table at the end.
        tcp_height: the grasp height of the tcp, m.
    """

    tcp: np.ndarray
    start: np.ndarray
    end: np.ndarray
    fallen: Sequence[str]
    tcp_height: float

    def distance(self) -> float:
        """The tcp's horizontal distance from the target's centre, m."""
        return float(np.hypot(*(np.asarray(self.tcp)[:2] - np.asarray(self.end)[0, :2])))

    def lifted(self, scene: Scene, success: SuccessConfig) -> str | None:
        """The objects lifted off the table by more than ``success.max_lift`` (on the gripper or on
        another object), said in a line (None: none)."""
        rise = np.asarray(self.end)[:, 2] - np.asarray(self.start)[:, 2]
        lifted = [f"{o.name} by {r:.3f} m" for o, r in zip(scene.objects, rise) if r > success.max_lift]
        return (
            f"lifted off the table (on the gripper or another object): {', '.join(lifted)}"
            if lifted
            else None
        )

    def problem(
        self, scene: Scene, success: SuccessConfig, *, shrink: float = 0.0, accepting: bool = False
    ) -> str | None:
        """Why the reach failed the success test (None: it passed): an object off the table, or the
        target outside the pre-grasp region (a lifted object said beside, as its likely cause). A
        planner ``accepting`` it asks more: the region shrunk by ``shrink`` m horizontally and
        vertically (its acceptance margin) and no object lifted."""
        if self.fallen:
            return f"objects fell off the table: {', '.join(self.fallen)}"
        lifted = self.lifted(scene, success)
        if accepting and lifted:
            return lifted
        region = self.region_problem(scene, success, shrink=shrink)
        return region if region is None or lifted is None else f"{region}; {lifted}"

    def region_problem(self, scene: Scene, success: SuccessConfig, *, shrink: float = 0.0) -> str | None:
        """Why the target is not in the gripper's pre-grasp region (None: it is), the region shrunk
        by ``shrink`` m."""
        radius = half_extent(scene.target.size) + success.pregrasp_margin - shrink
        distance = self.distance()
        if distance > radius:
            return (
                f"the target is not in the gripper's pre-grasp region: the tcp ends {distance:.3f} m from "
                f"its centre (within {radius:.3f} m passes)"
            )
        above = float(self.tcp[2] - self.tcp_height)
        allowed = success.pregrasp_margin - shrink
        if abs(above) > allowed:
            side = "above" if above > 0 else "below"
            return (
                f"the target is not in the gripper's pre-grasp region: the tcp ends {abs(above):.3f} m "
                f"{side} grasp height (within {allowed:.3f} m passes)"
            )
        return None


__all__ = ["ReachEnd", "SuccessConfig", "half_extent"]
