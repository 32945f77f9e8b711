"""Segmentation and training sets on the real VR dataset, against the reference figures (section 9.2, 4.7)."""

from __future__ import annotations

from collections import Counter
from dataclasses import replace

import numpy as np
import pytest

from hlp_drake.features import training_data
from hlp_drake.segmentation import Rejected, segment_dataset, segment_trial
from hlp_drake.segmentation.batch import log_agreement

pytestmark = pytest.mark.dataset


@pytest.fixture(scope="module")
def faithful(dataset):
    return segment_dataset(dataset, mode="faithful")


@pytest.fixture(scope="module")
def fixed(dataset):
    return segment_dataset(dataset, mode="fixed")


def test_faithful_mode_reproduces_the_reference_counts(faithful):
    assert len(faithful.demonstrations) == 1752
    assert faithful.flag_counts() == {(0, 0): 247, (1, 0): 323, (0, 1): 212, (1, 1): 970}
    reasons = faithful.reasons()
    assert reasons["N rows with a moved obstacle but only N objects moved (incl. target)"] == 38
    assert reasons["the target never moved"] == 11
    assert reasons["an obstacle was picked up or pushed but did not move"] == 4
    # Every gap row has exactly one flagged gap; keypoints per demo 4 / 5 / 6.
    for demo in faithful.demonstrations:
        for decision, flags in zip(demo.decisions, demo.gap_flags):
            if decision.decision == "gap":
                assert sum(flags) == 1
    assert Counter(len(d.keypoints) for d in faithful.demonstrations) == {4: 247, 5: 535, 6: 970}


def test_faithful_moving_directions_include_the_forward_default(faithful):
    labels = Counter(d.direction for demo in faithful.demonstrations for d in demo.decisions if d.direction)
    # Reference 3.7: real labels plus 494 obstacles outside every block labelled FF (bug B9).
    assert labels == {
        "BL": 678,
        "RR": 363,
        "BR": 328,
        "LL": 232,
        "FR": 184,
        "BB": 105,
        "FL": 58,
        "FF": 33 + 494,
    }


def test_fixed_mode_labels_directions_from_the_displacement(fixed):
    labels = Counter(d.direction for demo in fixed.demonstrations for d in demo.decisions if d.direction)
    assert labels["FF"] < 100  # no default class swallowing a fifth of the labels
    assert len(fixed.demonstrations) >= 1790  # keeps depth-wise object motion the original misses


def test_decisions_agree_with_the_interaction_log(dataset, faithful, fixed):
    assert log_agreement(dataset, faithful) >= 0.97
    assert log_agreement(dataset, fixed) >= 0.97


def test_left_handers_are_mirrored_in_fixed_mode(fixed, faithful):
    def start_q1(result, left):
        return np.median([d.keypoints[0].arm[0] for d in result.demonstrations if d.left_handed == left])

    # The fixed mode measures q1 from the body-centre side, so a left arm's angle is the mirror of
    # the original's (which measures from +y for everybody): they sum to pi.
    left_fixed, left_faithful = start_q1(fixed, True), start_q1(faithful, True)
    assert left_fixed + left_faithful == pytest.approx(np.pi, abs=0.05)
    # Right arms: both modes measure the same angles.
    original = {d.key: d.keypoints[0].arm for d in faithful.demonstrations if not d.left_handed}
    same = [
        d.keypoints[0].arm == pytest.approx(original[d.key])
        for d in fixed.demonstrations
        if d.key in original
    ]
    assert len(same) > 1500 and all(same)


def test_faithful_training_sets_have_the_reference_sizes(faithful):
    data = training_data(faithful.demonstrations, mode="faithful")
    gap, obj = data.gap.original_rows(), data.object.original_rows()
    assert gap.X.shape == (6256, 5) and gap.y.sum() == 1029
    assert obj.X.shape == (9030, 7) and obj.y.sum() == 2475
    assert len(data.gap) == 8 * 1752 and len(data.object) == 6 * 1752  # every trial, for other presets
    assert data.direction.X.shape == (2475, 10)
    assert data.segment.X.shape == (85848, 4) and data.segment.y.sum() == 1752
    assert data.arm.X.shape == (7731, 5) and data.arm.y.shape == (7731, 2)
    assert np.all(np.isfinite(data.segment.X))
    assert set(data.gap.subjects) == {
        faithful.demonstrations[i].subject for i in range(len(faithful.demonstrations))
    }


def test_bad_tracks_are_rejected_with_a_reason(dataset):
    trial = dataset.trial("sub_01/T050")
    hand = trial.trackers["hand"]
    nan_position = hand.position.copy()
    nan_position[10, 0] = np.nan
    with pytest.raises(Rejected, match="hand track contains NaN"):
        segment_trial(
            replace(trial, trackers={**trial.trackers, "hand": replace(hand, position=nan_position)})
        )
    short = replace(hand, time=hand.time[:50], position=hand.position[:50], yaw=hand.yaw[:50])
    with pytest.raises(Rejected, match="frames, hand track 50"):
        segment_trial(replace(trial, trackers={**trial.trackers, "hand": short}))
    without = {k: v for k, v in trial.trackers.items() if k != "elbow"}
    with pytest.raises(Rejected, match="no elbow track"):
        segment_trial(replace(trial, trackers=without))


def test_a_known_trial(dataset):
    demo = segment_trial(dataset.trial("sub_01/T050"))
    assert [(d.decision, d.element) for d in demo.decisions] == [
        ("gap", "2"),
        ("object", "FailOnTouchObstacleLong-1"),
    ]
    assert [k.kind for k in demo.keypoints] == ["start", "gap", "approach", "release", "target"]
    frames = [k.frame for k in demo.keypoints]
    assert frames == sorted(frames) and frames[-1] <= demo.goal_frame
    assert 0.1 < demo.link_lengths.upper_arm < 0.3 and 0.2 < demo.link_lengths.forearm < 0.32
