"""Per-obstacle geometry computed on demand, sparse segment tests and validation on bounding boxes first
give the eager answers exactly."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from hlp_drake.features.direction import DirectionTable
from hlp_drake.features.row_geometry import free_space
from hlp_drake.planner import PlanKeypoint
from hlp_drake.planner.row_plan import plans_segment_collisions, segment_collisions
from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.lazy import LazyRows
from hlp_drake.scene.validation import scene_problems
from hlp_drake.taskspace import TaskSpace, block_array, free_fractions, rect_array
from hlp_drake.taskspace.model import table_walls
from hlp_drake.taskspace.relocation import relocated_array
from hlp_drake.taskspace.routes import _clip, segment_inside


def test_lazy_rows_compute_each_row_once_in_batches():
    calls = []

    def square(index):
        calls.append(index.tolist())
        return np.column_stack([index, index**2]).astype(float)

    rows = LazyRows(6, square)
    assert rows[[4, 1, 4]].tolist() == [[4, 16], [1, 1], [4, 16]]
    assert rows[3].tolist() == [3, 9]
    assert rows[np.array([[1, 3], [5, 4]])][..., 1].tolist() == [[1, 9], [25, 16]]
    assert calls == [[1, 4], [3], [5]]  # the missing rows only, once each, in increasing order
    assert rows[[]].shape[0] == 0 and len(rows) == 6


@pytest.fixture(scope="module")
def space():
    return TaskSpace(generate_scene("gen2", 4, 25))


def test_lazy_free_space_and_relocation_equal_the_whole_table(space):
    walls = rect_array(list(table_walls(space.scene.table.bounds, space.scene.table.diagonal).values()))
    occluders = np.vstack([space.obstacle_bounds, rect_array([space.target]), walls])
    eager = free_fractions(block_array(space.obstacle_bounds, space.alpha), occluders)
    lazy, order = free_space(space), np.random.default_rng(0).permutation(len(eager))
    for part in np.array_split(order, 4):  # asked for in pieces, in any order
        assert np.array_equal(lazy[part], eager[part])
    regions = relocated_array(space.obstacle_bounds, space.alpha)
    assert np.array_equal(space.relocated[order[::-1]], regions[order[::-1]])


def test_lazy_direction_table_equals_one_built_for_each_obstacle(space):
    names = space.obstacle_names
    table = DirectionTable(space, names, mode="fixed")
    hands = [(0.1, 0.0), (0.5, 0.3), (0.9, -0.2)]
    picked = [7, 2, 7]
    directions = table.hand_directions(picked, hands)
    for k, hand, direction in zip(picked, hands, directions):
        alone = DirectionTable(space, [names[k]], mode="fixed")
        assert direction == alone.hand_direction(0, hand)
        assert np.array_equal(table.features(k, 3), alone.features(0, 3))


def test_sparse_segment_inside_equals_clipping_every_rectangle(space):
    rng = np.random.default_rng(1)
    p0 = rng.uniform(-0.3, 0.3, (5, 2)) + (0.5, 0.0)
    p1 = p0 + rng.uniform(-0.2, 0.2, (5, 2))
    grown = space.obstacle_bounds + np.array([-0.02, -0.02, 0.02, 0.02])
    low, high = _clip(p0, p1, grown)
    dense = np.maximum(high - low, 0.0) * np.linalg.norm(p1 - p0, axis=1)[:, None]
    sparse = segment_inside(p0, p1, grown)
    assert np.array_equal(sparse, dense) and (dense > 0).any() and (dense == 0).any()


def test_segment_collisions_of_several_plans_equal_each_plan_alone(space):
    scene = space.scene
    start, target = PlanKeypoint("start", scene.start), PlanKeypoint("target", space.target.center)
    box = scene.obstacles[3]
    plans = [
        (start, PlanKeypoint("gap", (box.x + 0.05, box.y), 1, "1"), target),
        (
            start,
            PlanKeypoint("move", (box.x, box.y), 1, box.name, "LL"),
            PlanKeypoint("release", (box.x, box.y + 0.1), 1, box.name, "LL"),
            target,
        ),
        (start,),
    ]
    batched = plans_segment_collisions(space, plans, 0.05)
    assert batched == [segment_collisions(space, p, 0.05) for p in plans]
    assert batched[0] and batched[2] == []


def test_start_inside_a_footprint_not_only_inside_its_bounding_box():
    scene = generate_scene("vr", 0)
    box = replace(scene.obstacles[0], x=0.3, y=0.0, yaw=float(np.pi / 4))  # a diamond seen from above
    far = replace(scene.obstacles[1], x=0.3, y=0.3)  # out of the way of the diamond
    corner = 0.999 * max(box.size[:2]) / 2.0  # inside the bounding box, outside the diamond
    for start, inside in (((0.3, 0.0), True), ((0.3 - corner, -corner), False)):
        problems = scene_problems(replace(scene, start=start, obstacles=(box, far, *scene.obstacles[2:])))
        assert (f"start point lies inside obstacle {box.name!r}" in problems) == inside
