"""The planar arm of a demonstration: link lengths and the (shoulder, elbow) angles (reference 3.2, 3.6).

All in the table plane (world x, y). "Shoulder" is the upper-arm tracker. The neck is not tracked: it
is placed beside the shoulder on the body-centre side, so q1 is the angle of the upper arm from the
shoulder-to-neck direction and q2 the elbow's inner angle; both are unsigned (0..pi).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class LinkLengths:
    """Mean planar shoulder-elbow and elbow-hand distances over a whole trial, m."""

    upper_arm: float
    forearm: float

    @property
    def total(self) -> float:
        return self.upper_arm + self.forearm


def link_lengths(shoulder: np.ndarray, elbow: np.ndarray, hand: np.ndarray) -> LinkLengths:
    """Mean link lengths from (N, 2) planar tracks."""
    return LinkLengths(
        upper_arm=float(np.mean(np.linalg.norm(shoulder - elbow, axis=1))),
        forearm=float(np.mean(np.linalg.norm(elbow - hand, axis=1))),
    )


def _angle_between(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    cos = np.sum(u * v, axis=-1) / (np.linalg.norm(u, axis=-1) * np.linalg.norm(v, axis=-1))
    return np.arccos(np.clip(cos, -1.0, 1.0))


def medial_direction(left_handed: bool, *, faithful: bool) -> np.ndarray:
    """Unit vector from the shoulder towards the neck in the world plane.

    The original puts the neck on the participant's left (+y) for everybody (bug B11); the fixed
    mode puts it on the body-centre side of the tracked arm: +y for a right arm, -y for a left arm,
    so the angles of left- and right-handers mean the same (mirror images of each other).
    """
    side = -1.0 if (left_handed and not faithful) else 1.0
    return np.array([0.0, side])


def arm_angles(shoulder: np.ndarray, elbow: np.ndarray, hand: np.ndarray, medial: np.ndarray) -> np.ndarray:
    """(..., 2) array of (q1, q2): upper arm from the medial direction, and the elbow's inner angle."""
    q1 = _angle_between(np.broadcast_to(medial, np.shape(elbow)), elbow - shoulder)
    q2 = _angle_between(shoulder - elbow, hand - elbow)
    return np.stack([q1, q2], axis=-1)
