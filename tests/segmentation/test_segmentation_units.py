"""Segmentation building blocks on synthetic data: motion periods, moved obstacles, arm angles."""

from __future__ import annotations

import numpy as np
import pytest

from hlp_drake.dataset.records import Interaction
from hlp_drake.errors import HlpError
from hlp_drake.segmentation import arm_angles, check_mode, link_lengths, medial_direction
from hlp_drake.segmentation.motion import first_moved_per_row, motion_period


def _track(steps: list[tuple[float, float]]) -> np.ndarray:
    return np.cumsum(np.array([(0.0, 0.0), *steps]), axis=0)


def test_motion_period_faithful_sees_lateral_motion_only():
    depth_only = _track([(0.0, 0.0)] * 5 + [(0.01, 0.0)] * 3 + [(0.0, 0.0)] * 5)
    assert motion_period(depth_only, faithful=True) is None
    assert motion_period(depth_only, faithful=False) == (4, 8)  # one frame either side, as the original
    lateral = _track([(0.0, 0.0)] * 5 + [(0.0, 0.002)] * 3 + [(0.0, 0.0)] * 5)
    assert motion_period(lateral, faithful=True) == (4, 8)
    assert motion_period(_track([(0.0, 0.0005)] * 10), faithful=False) is None  # below 1 mm per frame


def test_first_moved_obstacle_per_row():
    row_of = {"A": 1, "B": 1, "C": 2}
    log = [
        Interaction(1.0, 2.0, "Hand", "A", "LeftGate"),
        Interaction(2.0, 3.0, "A", "C", "Pushed"),  # an obstacle pushing another
        Interaction(3.0, 4.0, "Hand", "B", "PickedUp"),
        Interaction(4.0, 5.0, "Hand", "A", "PickedUp"),
        Interaction(5.0, 6.0, "Hand", "C", "PickedUp"),
        Interaction(6.0, None, "Hand", "Target", "PickedUp"),
    ]
    assert first_moved_per_row(log, row_of, faithful=True) == {1: "B", 2: "C"}
    assert first_moved_per_row(log[:2], row_of, faithful=True) == {2: "C"}
    assert first_moved_per_row(log[:2], row_of, faithful=False) == {}  # not an arm decision


def test_arm_angles_and_medial_side():
    shoulder, elbow, hand = np.array([0.0, 0.0]), np.array([0.2, 0.0]), np.array([0.2, 0.25])
    q = arm_angles(shoulder, elbow, hand, medial_direction(False, faithful=True))
    assert q == pytest.approx([np.pi / 2, np.pi / 2])
    # A left arm measured from the body-centre side in fixed mode, from +y in faithful mode.
    assert medial_direction(True, faithful=False) == pytest.approx([0.0, -1.0])
    assert medial_direction(True, faithful=True) == pytest.approx([0.0, 1.0])
    lengths = link_lengths(np.zeros((3, 2)), np.tile(elbow, (3, 1)), np.tile(hand, (3, 1)))
    assert (lengths.upper_arm, lengths.forearm, lengths.total) == pytest.approx((0.2, 0.25, 0.45))


def test_unknown_mode_is_a_user_error():
    with pytest.raises(HlpError, match="unknown mode 'exact'"):
        check_mode("exact")
