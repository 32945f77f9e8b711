"""The task-space model: rows, gaps, walls, direction blocks, free space, directions, band measure."""

from __future__ import annotations

import math
from dataclasses import astuple

import numpy as np
import pytest

from hlp_drake.scene import generate_scene
from hlp_drake.taskspace import (
    DIRECTIONS,
    Rect,
    TaskSpace,
    band_collision,
    band_collision_sampled,
    direction_blocks,
    direction_of,
    free_fractions,
)


def test_vr_scene_has_two_rows_of_four_gaps_that_tile_the_table():
    space = TaskSpace(generate_scene("vr", 3))
    assert [len(g) for g in space.gaps] == [4, 4]
    for row, gaps in zip(space.rows, space.gaps):
        assert [g.index for g in gaps] == [1, 2, 3, 4]
        assert gaps[0].left is None and gaps[-1].right is None
        assert gaps[0].rect.y_max == pytest.approx(0.37)  # gap 1 starts at the left table edge
        assert gaps[-1].rect.y_min == pytest.approx(-0.37)
        obstacles = sum(space.rects[n].width for n in row.members)
        assert sum(g.width for g in gaps) + obstacles == pytest.approx(0.74)
        assert all(g.rect.x_min == row.x_min and g.rect.x_max == row.x_max for g in gaps)
        assert [g.right for g in gaps[:-1]] == list(row.members)  # left to right


def test_obstacle_at_the_table_edge_leaves_no_empty_gap():
    scene = generate_scene("vr", 3)
    from dataclasses import replace

    first = scene.obstacles[0]
    moved = replace(first, y=0.37 - first.size[1] / 2)
    space = TaskSpace(replace(scene, obstacles=(moved, *scene.obstacles[1:])))
    assert len(space.gaps[0]) == 3 and space.gaps[0][0].left == first.name


def test_direction_blocks_match_the_reference_layout():
    blocks = direction_blocks(Rect(0.0, 0.0, 0.1, 0.2), alpha=1.5)
    assert list(blocks) == list(DIRECTIONS)
    assert astuple(blocks["FF"]) == pytest.approx((0.1, 0.0, 0.25, 0.2))
    assert astuple(blocks["BB"]) == pytest.approx((-0.15, 0.0, 0.0, 0.2))
    assert astuple(blocks["LL"]) == pytest.approx((0.0, 0.2, 0.1, 0.5))  # left is +y
    assert astuple(blocks["RR"]) == pytest.approx((0.0, -0.3, 0.1, 0.0))
    assert astuple(blocks["FL"]) == pytest.approx((0.1, 0.2, 0.25, 0.5))
    assert astuple(blocks["BR"]) == pytest.approx((-0.15, -0.3, 0.0, 0.0))


def test_free_space_counts_neighbours_and_walls():
    from dataclasses import replace

    scene = generate_scene("vr", 3)
    space = TaskSpace(scene)
    for name in space.obstacle_names:
        free = space.free_space(name)
        assert free.shape == (8,) and np.all(free <= 1.0) and np.all(free >= 0.0)
    # push the first obstacle against the left table edge: the 5 cm left wall fills part of LL
    first = scene.obstacles[0]
    width = first.size[1]
    moved = replace(first, y=0.37 - width / 2)
    others = tuple(o for o in scene.obstacles[1:] if o.x != first.x)  # keep its row otherwise empty
    space = TaskSpace(replace(scene, obstacles=(moved, *others)))
    free = dict(zip(DIRECTIONS, space.free_space(first.name)))
    assert free["LL"] == pytest.approx(1.0 - 0.05 / (1.5 * width))
    assert free["RR"] == pytest.approx(1.0)
    assert free_fractions([[0, 0, 1, 1]], [[0.5, 0, 2, 1]]) == pytest.approx([0.5])
    # Overlaps are summed, not merged (the original's rule).
    assert free_fractions([[0, 0, 1, 1]], [[0.5, 0, 2, 1], [0.5, 0, 2, 1]]) == pytest.approx([0.0])


def test_connecting_space_lies_between_rows():
    space = TaskSpace(generate_scene("vr", 1))
    link = space.connecting_space(1)
    assert link.x_min == pytest.approx(0.27) and link.x_max == pytest.approx(0.38)
    assert link.width == pytest.approx(0.74)


@pytest.mark.parametrize(
    ("dx", "dy", "faithful", "expected"),
    [
        (1.0, 0.0, True, "FF"),
        (1.0, 0.001, True, "FL"),
        (1.0, 0.001, False, "FF"),
        (0.0, -1.0, False, "RR"),
        (-1.0, -1.0, False, "BR"),
        (-1.0, 0.9, False, "BL"),
        (0.2, 1.0, False, "LL"),
        (-0.5, 0.0, True, "BB"),
        (0.0, 0.0, True, None),
    ],
)
def test_discrete_direction(dx, dy, faithful, expected):
    assert direction_of(dx, dy, faithful=faithful) == expected


def test_exact_and_sampled_band_agree_on_simple_cases():
    box_ = Rect(0.4, -0.05, 0.45, 0.05)  # 5 cm deep, 10 cm wide
    # a 5 cm band straight through the middle covers half of it
    exact = band_collision((0.0, 0.0), (1.0, 0.0), [box_], half_width=0.025)
    sampled = band_collision_sampled(
        (0.0, 0.0), (1.0, 0.0), [box_], offset=(0.0, 1.0), s_minus=0.025, s_plus=0.025
    )
    assert exact == pytest.approx(0.5)
    assert sampled == pytest.approx(exact, rel=0.25)  # sampling resolves 1/49 of the length
    # missing the box: both zero; a second, untouched occluder halves the mean
    assert band_collision((0.0, 0.2), (1.0, 0.2), [box_], half_width=0.025) == 0.0
    far = Rect(0.9, 0.5, 1.0, 0.6)
    two = band_collision((0.0, 0.0), (1.0, 0.0), [box_, far], half_width=0.025)
    two_sampled = band_collision_sampled(
        (0.0, 0.0), (1.0, 0.0), [box_, far], offset=(0.0, 1.0), s_minus=0.025, s_plus=0.025
    )
    assert two == pytest.approx(0.25) and two_sampled == pytest.approx(two, rel=0.25)
    # a band wider than the box covers all of it
    assert band_collision((0.0, 0.0), (1.0, 0.0), [box_], half_width=0.2) == pytest.approx(1.0)


def test_diagonal_band_is_exact():
    square = Rect(0.0, 0.0, 1.0, 1.0)
    # diagonal band of half-width h through a unit square: area = sqrt(2) * 2h - 2h^2 (corner triangles)
    h = 0.1
    covered = band_collision((-1.0, -1.0), (2.0, 2.0), [square], half_width=h)
    assert covered == pytest.approx(math.sqrt(2) * 2 * h - 2 * h * h, rel=1e-9)
