"""``Keyframes``: the IK result of a plan (per keypoint the robot's positions, a flag, a message)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from hlp_drake.planner.plan import PlanKeypoint


@dataclass(frozen=True)
class Keyframes:
    """The IK result of a plan.

    Attributes:
        keypoints: the plan's keypoints.
        positions: (n, 11) robot positions per keypoint (for a failed keypoint: the solver's last
            iterate, not to be executed).
        success: per keypoint, whether its IK succeeded.
        messages: per keypoint, "" on success, else why it failed (naming the keypoint).
        tcp_positions: (n, 3) tcp positions of ``positions`` (forward kinematics).
        start: the robot's 11 start positions.
        problems: plan-level problems (no plan, wrong scene); empty normally.
        solve_time_s: wall-clock time of all the solves.
    """

    keypoints: tuple[PlanKeypoint, ...]
    positions: np.ndarray
    success: tuple[bool, ...]
    messages: tuple[str, ...]
    tcp_positions: np.ndarray
    start: np.ndarray
    problems: tuple[str, ...] = ()
    solve_time_s: float = 0.0
    details: dict = field(default_factory=dict, compare=False)

    @property
    def ok(self) -> bool:
        """True when there are keyframes, all succeeded, and the plan had no problem."""
        return not self.problems and len(self.success) > 0 and all(self.success)

    @property
    def failures(self) -> list[str]:
        """Every problem and failure message."""
        return [*self.problems, *(m for m, ok in zip(self.messages, self.success) if not ok)]

    @classmethod
    def empty(cls, start: np.ndarray, problem: str | None = None) -> Keyframes:
        n = len(start)
        return cls(
            keypoints=(),
            positions=np.zeros((0, n)),
            success=(),
            messages=(),
            tcp_positions=np.zeros((0, 3)),
            start=np.array(start, dtype=float),
            problems=() if problem is None else (problem,),
        )


def describe_keypoint(index: int, keypoint: PlanKeypoint) -> str:
    element = f" {keypoint.element}" if keypoint.element else ""
    x, y = keypoint.position
    return f"keypoint {index} ({keypoint.action}{element}) at ({x:.3f}, {y:.3f})"
