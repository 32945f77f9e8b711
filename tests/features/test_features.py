"""Feature vectors Xg, Xo, Xd, Xc, Xa on hand-checkable scenes, and the exact band clipping."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

from hlp_drake.features import (
    arm_features,
    direction_features,
    gap_features,
    object_features,
    paper_angle,
    segment_feature_matrix,
    segment_features,
    table_diagonal,
)
from hlp_drake.scene.generators import generate_scene
from hlp_drake.taskspace import DIRECTIONS, TaskSpace
from hlp_drake.taskspace.band import convex_rect_overlap

VR_DIAGONAL = 0.95268


@pytest.fixture
def space() -> TaskSpace:
    return TaskSpace(generate_scene("vr", 4))


def test_angles_follow_the_original_convention():
    # Straight ahead is pi/2, the start's right (-y) is 0, its left is pi.
    assert paper_angle(np.array([1.0, 0.0])) == pytest.approx(math.pi / 2)
    assert paper_angle(np.array([0.0, -1.0])) == pytest.approx(0.0)
    assert paper_angle(np.array([0.0, 1.0])) == pytest.approx(math.pi)


def test_gap_features_by_hand(space):
    assert table_diagonal(space.scene.table) == pytest.approx(VR_DIAGONAL, abs=1e-4)
    features = gap_features(space)
    gaps = [g for row in space.gaps for g in row]
    assert features.shape == (len(gaps), 5)
    gap = gaps[5]
    c, start, target = np.array(gap.center), np.array(space.scene.start), np.array(space.target.center)
    d = table_diagonal(space.scene.table)
    expected = [
        np.linalg.norm(c - start) / d,
        np.linalg.norm(c - target) / d,
        math.hypot(gap.width, 0.05) / d,
        math.atan2(c[0] - start[0], -(c[1] - start[1])),
        math.atan2(c[0] - target[0], -(c[1] - target[1])),
    ]
    assert features[5] == pytest.approx(expected)


def test_object_features_free_space_and_target_overlap(space):
    features = object_features(space)
    assert features.shape == (6, 7)
    assert np.all((features[:, 5] > 0) & (features[:, 5] <= 1))
    for name, row in zip(space.obstacle_names, features):
        rect, target = space.rects[name], space.target
        overlap = max(0.0, min(rect.y_max, target.y_max) - max(rect.y_min, target.y_min))
        assert row[6] == pytest.approx(overlap / table_diagonal(space.scene.table))
        assert row[5] == pytest.approx(space.free_space(name).mean())


def test_direction_features_modes_differ_as_the_original(space):
    name = space.obstacle_names[0]
    hand = space.scene.start
    fixed = direction_features(space, name, hand=hand, mode="fixed")
    assert fixed.shape == (10,)
    centre = np.array(space.rects[name].center)
    assert DIRECTIONS[int(fixed[8])] in {"FF", "FL", "FR"}  # the obstacle is ahead of the start
    faithful_train = direction_features(
        space, name, hand=hand, mode="faithful", training=True, hand_to_object="BL"
    )
    assert DIRECTIONS[int(faithful_train[8])] == "BL"  # the demonstration's own label is used (B6)
    faithful_plan = direction_features(space, name, hand=hand, mode="faithful")
    assert centre[0] > hand[0] and DIRECTIONS[int(faithful_plan[8])][0] == "F"


def test_segment_features_normaliser_bug_b1(space):
    a, b = space.nodes(1)[0], space.nodes(2)[-1]
    train = segment_features(space, a, b, mode="faithful", training=True)
    plan = segment_features(space, a, b, mode="faithful")
    width, diagonal = space.scene.table.width, table_diagonal(space.scene.table)
    assert train[0] * width == pytest.approx(plan[0] * diagonal)
    assert train[0] == pytest.approx(abs(b.center[1] - a.center[1]) / width)
    fixed_train = segment_features(space, a, b, mode="fixed", training=True)
    assert fixed_train == pytest.approx(segment_features(space, a, b, mode="fixed"))  # no train/plan mismatch


def test_segment_matrix_matches_single_pairs_and_excludes_own_obstacles(space):
    near, far = space.nodes(1), space.nodes(2)
    matrix = segment_feature_matrix(space, near, far, mode="fixed")
    assert matrix.shape == (len(near) * len(far), 4)
    assert matrix[len(far) + 2] == pytest.approx(segment_features(space, near[1], far[2], mode="fixed"))
    # A segment from an obstacle to the gap right behind it does not collide with that obstacle.
    obstacle = next(n for n in near if n.kind == "object")
    i = near.index(obstacle)
    assert np.all(matrix[i * len(far) : (i + 1) * len(far), 2] < 0.5)


def test_arm_features_mirror_a_left_arm():
    right = arm_features((1.2, 2.8), (0.3, 0.1), "FL")
    left = arm_features((1.2, 2.8), (0.3, 0.1), "FL", mirror=True)
    assert right[:4] == pytest.approx([1.2, 2.8, 0.3, 0.1])
    assert left[:4] == pytest.approx([1.2, 2.8, 0.3, -0.1])
    assert DIRECTIONS[int(right[4])] == "FL" and DIRECTIONS[int(left[4])] == "FR"


def test_exact_band_clipping_matches_shapely():
    rng = np.random.default_rng(7)
    for _ in range(200):
        angle = rng.uniform(0, np.pi)
        rotation = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]])
        w, h = rng.uniform(0.05, 1.0, 2)
        quad = (np.array([[-w, -h], [w, -h], [w, h], [-w, h]]) / 2) @ rotation.T + rng.uniform(-1, 1, 2)
        x, y = np.sort(rng.uniform(-1, 1, 2)), np.sort(rng.uniform(-1, 1, 2))
        rect = np.array([x[0], y[0], x[1], y[1]])
        expected = shapely.Polygon(quad).intersection(shapely.box(*rect)).area
        assert convex_rect_overlap(quad[None], rect[None])[0, 0] == pytest.approx(expected, abs=1e-12)
