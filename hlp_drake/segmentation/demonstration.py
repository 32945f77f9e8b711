"""What segmentation makes of a demonstration: per-row decisions and keypoints with arm angles."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hlp_drake.scene.model import Scene
from hlp_drake.segmentation.arm import LinkLengths
from hlp_drake.segmentation.modes import Mode

GAP, OBJECT, NONE = "gap", "object", "none"  # NONE: a row the hand never crossed


@dataclass(frozen=True)
class RowDecision:
    """What the person did at a row: went through gap ``gap`` or moved ``obstacle`` towards ``direction``
    (or nothing: a row beside the target that the hand never crossed).

    Attributes:
        row: 1 = nearest the start.
        decision: "gap", "object" or "none".
        gap: the gap's index in its row from 1, counted from the left (gap decisions only).
        obstacle: the moved obstacle's name (object decisions only).
        direction: the moved obstacle's direction class (FF, FL, ...; object decisions only).
    """

    row: int
    decision: str
    gap: int | None = None
    obstacle: str | None = None
    direction: str | None = None

    @property
    def element(self) -> str:
        """The obstacle name, the gap index as text, or "" for a row with no decision."""
        if self.decision == NONE:
            return ""
        return self.obstacle if self.decision == OBJECT else str(self.gap)


@dataclass(frozen=True)
class Keypoint:
    """A hand keypoint of a demonstration.

    Attributes:
        kind: "start", "gap", "approach" (reached the moved obstacle), "release", "target".
        row: the row it belongs to (None for start and target).
        frame: index into the trial's tracks.
        position: the hand's planar world position (x, y), m.
        direction: direction class of the hand's motion that led here (None for the start).
        arm: (q1, q2) shoulder and elbow angles, radians.
        displacement: hand displacement from the previous keypoint divided by the arm length
            (the original's "distance_moved"; (0, 0) for the start).
    """

    kind: str
    row: int | None
    frame: int
    position: tuple[float, float]
    direction: str | None
    arm: tuple[float, float]
    displacement: tuple[float, float]


@dataclass(frozen=True)
class Demonstration:
    """A segmented successful trial.

    Attributes:
        key: "sub_01/T050".
        mode: "fixed" or "faithful".
        scene: the trial's scene (initial poses).
        left_handed: the demonstrator's handedness.
        decisions: one per row, nearest row first ("none" for a row the hand never crossed).
        keypoints: start, then per row a gap keypoint or approach + release, then the target.
        gap_flags: per row, per gap (left to right), whether the go path passed through it.
        link_lengths: the demonstrator's mean upper-arm and forearm lengths.
        goal_frame: last frame of the go part (closest approach of the hand to the target).
        hand_path: (goal_frame + 1, 2) planar hand positions of the go part.
    """

    key: str
    mode: Mode
    scene: Scene
    left_handed: bool
    decisions: tuple[RowDecision, ...]
    keypoints: tuple[Keypoint, ...]
    gap_flags: tuple[tuple[bool, ...], ...]
    link_lengths: LinkLengths
    goal_frame: int
    hand_path: np.ndarray

    @property
    def subject(self) -> str:
        return self.key.split("/")[0]

    @property
    def trial(self) -> int:
        return int(self.key.split("/T")[1])

    @property
    def flags(self) -> tuple[int, ...]:
        """Per row 1 if an object was moved, else 0 (the original's interaction_flag)."""
        return tuple(int(d.decision == OBJECT) for d in self.decisions)


@dataclass(frozen=True)
class Rejection:
    """A trial segmentation left out, and why."""

    key: str
    reason: str
