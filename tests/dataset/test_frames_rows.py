"""The Unity -> world conversion and row clustering."""

from __future__ import annotations

import math

import numpy as np
import pytest

from hlp_drake.dataset.frames import unity_to_world, unity_yaw_to_world
from hlp_drake.scene import Scene, SceneObject, Table, find_rows


def test_unity_axes_map_to_physical_directions():
    front = -0.35
    origin = unity_to_world([0.0, 0.0, front], table_front_z=front)
    np.testing.assert_allclose(origin, [0, 0, 0])
    # Unity +x is the participant's right; world +y is the left.
    np.testing.assert_allclose(unity_to_world([1.0, 0, front], table_front_z=front), [0, -1, 0])
    np.testing.assert_allclose(unity_to_world([0, 1.0, front], table_front_z=front), [0, 0, 1])  # up
    np.testing.assert_allclose(unity_to_world([0, 0, front + 1], table_front_z=front), [1, 0, 0])  # away
    batch = unity_to_world(np.zeros((4, 2, 3)), table_front_z=front, table_center_x=0.1)
    assert batch.shape == (4, 2, 3) and np.allclose(batch[..., 1], 0.1)
    with pytest.raises(ValueError):
        unity_to_world(np.zeros(2), table_front_z=0.0)


def test_unity_yaw_is_clockwise_degrees():
    assert unity_yaw_to_world(90.0) == pytest.approx(-math.pi / 2)  # turn to the right
    assert unity_yaw_to_world(270.0) == pytest.approx(math.pi / 2)
    assert unity_yaw_to_world(180.0) == pytest.approx(math.pi)
    assert unity_yaw_to_world(-180.0) == pytest.approx(math.pi)


def scene_with(xs_ys) -> Scene:
    obstacles = tuple(SceneObject(f"o{i}", "box", x, y, (0.05, 0.06, 0.1)) for i, (x, y) in enumerate(xs_ys))
    target = SceneObject("Target", "cylinder", 0.9, 0.0, (0.05, 0.05, 0.1))
    return Scene(Table(1.0, 1.2, 0.7), (0.1, 0.0), target, obstacles)


def test_rows_cluster_rough_alignment_and_order_members_left_to_right():
    rows = find_rows(scene_with([(0.3, -0.2), (0.31, 0.2), (0.29, 0.0), (0.6, 0.1), (0.61, -0.3)]))
    assert [r.index for r in rows] == [1, 2]
    assert rows[0].members == ("o1", "o2", "o0")  # +y (left) first
    assert rows[0].x == pytest.approx(0.3) and rows[1].x == pytest.approx(0.605)
    assert rows[0].x_min == pytest.approx(0.265) and rows[0].x_max == pytest.approx(0.335)


def test_rows_one_many_none():
    assert len(find_rows(scene_with([(0.3, 0.0)]))) == 1
    assert len(find_rows(scene_with([(0.2 + 0.1 * i, 0.0) for i in range(6)]))) == 6
    assert find_rows(scene_with([])) == []
    assert len(find_rows(scene_with([(0.3, -0.2), (0.33, 0.2)]), tolerance=0.05)) == 1
