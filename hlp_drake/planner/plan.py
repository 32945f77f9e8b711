"""``HighLevelPlan``: the planner's output and the contract with the Drake side (waypoints + actions)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

ACTIONS = ("start", "gap", "move", "release", "target")


@dataclass(frozen=True)
class PlanKeypoint:
    """One hand waypoint of a plan, on the table plane (world frame).

    Attributes:
        action: "start"; "gap" (pass through a gap); "move" (reach an obstacle and push/carry it);
            "release" (where the moved obstacle is left); "target" (reach the target). A robot's
            plan (``planner.transfer.robot_plan``) adds "transit": a waypoint lifted clear of the
            objects, and "approach": the waypoint the gripper slides onto the target from.
        position: (x, y) of the hand, m.
        row: the row the keypoint belongs to (None for start and target).
        element: the obstacle's name for "move"/"release", the gap's index (from the left, as text)
            for "gap", the target's name for "target", None for the start.
        direction: the direction class the obstacle is moved towards ("move"/"release" only).
        arm: the predicted human-like (shoulder, elbow) angles at this keypoint, radians.
        height: the hand's height above the table top, m, where it differs from the robot's usual
            keypoint height (``IkConfig.height``); None otherwise.
    """

    action: str
    position: tuple[float, float]
    row: int | None = None
    element: str | None = None
    direction: str | None = None
    arm: tuple[float, float] | None = None
    height: float | None = None

    def to_dict(self) -> dict[str, Any]:
        return {
            "action": self.action,
            "x": self.position[0],
            "y": self.position[1],
            "row": self.row,
            "element": self.element,
            "direction": self.direction,
            "arm": None if self.arm is None else list(self.arm),
            "height": self.height,
        }


@dataclass(frozen=True)
class PlanCandidate:
    """A candidate path the planner considered and its expected arm collision."""

    keypoints: tuple[PlanKeypoint, ...]
    expected_collision: float

    @property
    def elements(self) -> tuple[str, ...]:
        """Per row, the element used: ``"gap 2"`` or ``"move <name>"``."""
        return tuple(f"{k.action} {k.element}" for k in self.keypoints if k.action in ("gap", "move"))


@dataclass(frozen=True)
class HighLevelPlan:
    """What the human-like planner proposes for a scene.

    Attributes:
        scene: the scene's name.
        keypoints: the chosen path's keypoints, start first, target last; empty if no plan.
        expected_collision: the chosen path's expected arm collision (lower is better).
        alternatives: the other candidate paths considered, best first.
        planning_time_s: wall-clock time the planner took.
        reason: why there is no plan (None when there is one).
    """

    scene: str
    keypoints: tuple[PlanKeypoint, ...]
    expected_collision: float = 0.0
    alternatives: tuple[PlanCandidate, ...] = ()
    planning_time_s: float = 0.0
    reason: str | None = None
    details: dict[str, Any] = field(default_factory=dict, compare=False)

    @property
    def ok(self) -> bool:
        return self.reason is None and len(self.keypoints) >= 2

    @property
    def waypoints(self) -> np.ndarray:
        """(n, 2) hand positions in order."""
        return np.array([k.position for k in self.keypoints], dtype=float).reshape(-1, 2)

    def to_dict(self) -> dict[str, Any]:
        return {
            "scene": self.scene,
            "ok": self.ok,
            "reason": self.reason,
            "keypoints": [k.to_dict() for k in self.keypoints],
            "expected_collision": self.expected_collision,
            "alternatives": [
                {"elements": list(c.elements), "expected_collision": c.expected_collision}
                for c in self.alternatives
            ],
            "planning_time_s": self.planning_time_s,
        }
