"""object_matching: scenes compared object by object by position, whatever the objects' names."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hlp_drake.systems.perception.accuracy import largest_displacement, match_obstacles

EXPECTED = np.array([[0.6, 0.0], [0.3, -0.2], [0.3, 0.2], [0.45, 0.0]])  # the target, then obstacles


def test_obstacles_pair_by_least_total_distance_whatever_their_order():
    observed = EXPECTED[[0, 3, 1, 2]] + [0.002, -0.001]
    rows, cols, distances = match_obstacles(EXPECTED[1:], observed[1:])
    assert dict(zip(rows.tolist(), cols.tolist())) == {0: 1, 1: 2, 2: 0}
    np.testing.assert_allclose(distances, math.hypot(0.002, 0.001))
    assert [len(x) for x in match_obstacles(EXPECTED[1:], np.zeros((0, 2)))] == [0, 0, 0]


def test_swapped_obstacles_have_not_moved_and_a_pushed_one_has():
    swapped = EXPECTED[[0, 2, 1, 3]]
    assert largest_displacement(EXPECTED, swapped) == pytest.approx(0.0)
    pushed = swapped.copy()
    pushed[3] += [0.0, 0.07]
    assert largest_displacement(EXPECTED, pushed) == pytest.approx(0.07)
    target_moved = EXPECTED.copy()
    target_moved[0] += [0.03, 0.04]
    assert largest_displacement(EXPECTED, target_moved) == pytest.approx(0.05)


def test_an_object_that_appeared_or_went_is_an_infinite_displacement():
    assert largest_displacement(EXPECTED, EXPECTED[:3]) == math.inf
    assert largest_displacement(EXPECTED[:1], EXPECTED[:1]) == 0.0  # the target alone
