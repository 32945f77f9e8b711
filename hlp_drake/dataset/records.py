"""What a VR trial holds once loaded: tracks and interactions in the world frame, and its Scene."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from hlp_drake.scene.model import Scene

PRACTICE, STRUCTURED, UNSTRUCTURED = "practice", "structured", "unstructured"
CATEGORIES = (PRACTICE, STRUCTURED, UNSTRUCTURED)
SUCCESS = "Success"

# Tracker files -> names used here. The "ShoulderTracker" is strapped to the upper arm.
TRACKERS = {
    "HandTracker": "hand",
    "WristTracker": "wrist",
    "ElbowTracker": "elbow",
    "ShoulderTracker": "upper_arm",
}

ARM_PARTS = ("Hand", "HandToWrist", "WristToElbow")
"""The arm's parts an interaction log names as the acting body (besides the scene's objects)."""
INTERACTION_KINDS = ("LeftGate", "RightGate", "PickedUp", "Pushed")
"""The interaction log's kinds: the hand passing left or right of an obstacle, a pick-up, a push."""


def category_of(trial: int) -> str:
    """Practice T001-T009, structured T010-T099, unstructured T100-T129."""
    if 1 <= trial <= 9:
        return PRACTICE
    if 10 <= trial <= 99:
        return STRUCTURED
    if 100 <= trial <= 129:
        return UNSTRUCTURED
    raise ValueError(f"trial number {trial} is outside T001-T129")


def trial_key(subject: str, trial: int) -> str:
    """``"sub_01/T050"``."""
    return f"{subject}/T{trial:03d}"


@dataclass(frozen=True)
class Track:
    """One tracked body sampled at 90 Hz.

    Attributes:
        name: "hand", "wrist", "elbow", "upper_arm", or an object's dataset name.
        time: (N,) seconds, the study's clock (shared with trial_results.csv times).
        position: (N, 3) world-frame positions, m.
        yaw: (N,) rotation about world z, radians.
        rotation_unity_deg: (N, 3) the recorded Unity Euler angles (x, y, z), degrees, unconverted.
    """

    name: str
    time: np.ndarray
    position: np.ndarray
    yaw: np.ndarray
    rotation_unity_deg: np.ndarray

    def __len__(self) -> int:
        return len(self.time)


@dataclass(frozen=True)
class Interaction:
    """A row of the interaction log: ``dominant`` acted on ``non_dominant`` (PickedUp, Pushed, ...)."""

    start_time: float
    end_time: float | None  # None: still active when the trial ended
    dominant: str
    non_dominant: str
    kind: str


@dataclass(frozen=True)
class TrialRecord:
    """A trial's metadata from ``trial_results.csv`` and ``participant_list.csv`` (no tracks)."""

    subject: str
    trial: int
    category: str
    outcome: str
    handedness: str  # "right", "left" or "unknown"
    trial_name: str
    start_time: float | None
    end_time: float | None
    start_moved_time: float | None
    target_reached_time: float | None

    @property
    def key(self) -> str:
        return trial_key(self.subject, self.trial)

    @property
    def success(self) -> bool:
        return self.outcome == SUCCESS


@dataclass(frozen=True)
class Trial:
    """A loaded trial: its record, its Scene, its tracks and its interaction log."""

    record: TrialRecord
    scene: Scene
    trackers: Mapping[str, Track]  # keys of TRACKERS' values
    objects: Mapping[str, Track]  # "Target" and obstacle dataset names
    interactions: tuple[Interaction, ...]

    @property
    def key(self) -> str:
        return self.record.key

    @property
    def subject(self) -> str:
        return self.record.subject

    @property
    def trial(self) -> int:
        return self.record.trial

    @property
    def success(self) -> bool:
        return self.record.success
