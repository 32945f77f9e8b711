"""The row-by-row planner with the bundled models: any number of rows, order, evidence, collisions."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from hlp_drake.evaluation import nearest_gap_plan
from hlp_drake.features.row_choice import RowChoiceScene
from hlp_drake.learners.bundled import default_models
from hlp_drake.planner import PlanKeypoint, plan
from hlp_drake.planner.row_plan import FALLBACK_SCALE, _fallback, planned_rows, segment_collisions
from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.model import Scene, SceneObject, Table
from hlp_drake.taskspace import TaskSpace


@pytest.fixture(scope="module")
def models():
    return default_models()


def _rows_in_order(result) -> list[int]:
    return [k.row for k in result.keypoints if k.action in ("gap", "move")]


@pytest.mark.parametrize(
    ("kind", "objects", "seed"), [("gen2", 9, 3), ("gen2", 7, 11), ("unstructured", 6, 2), ("vr", None, 5)]
)
def test_every_row_on_the_way_once_and_in_order(models, kind, objects, seed):
    scene = generate_scene(kind, seed, objects)
    result = plan(scene, models)
    assert result.ok, result.reason
    assert result.keypoints[0].action == "start" and result.keypoints[-1].action == "target"
    width = 0.05 * scene.table.diagonal / 0.9526  # the default: the VR hand scaled with the table
    expected = [row.index for row in planned_rows(TaskSpace(scene), width)]
    assert _rows_in_order(result) == expected  # each planned row once, nearest the start first
    for move, release in zip(result.keypoints, result.keypoints[1:]):
        if move.action == "move":
            assert release.action == "release" and release.element == move.element and release.direction
    assert all(k.arm is not None for k in result.keypoints)
    assert all(result.details["evidence"].values())
    assert len(result.alternatives) >= 1 and all(
        a.keypoints[-1].action == "target" for a in result.alternatives
    )


def test_rows_beside_or_behind_the_target_are_not_planned(models):
    table = Table(1.0, 1.0, 0.75)
    target = SceneObject("Target", "cylinder", 0.8, 0.0, (0.06, 0.06, 0.1))
    obstacles = (
        SceneObject("near", "box", 0.4, 0.05, (0.05, 0.2, 0.1)),
        SceneObject("beside", "box", 0.79, 0.25, (0.05, 0.1, 0.1)),  # level with the target
        SceneObject("behind", "box", 0.92, -0.2, (0.05, 0.1, 0.1)),
    )
    scene = Scene(table, (0.1, 0.0), target, obstacles)
    result = plan(scene, models)
    assert result.ok and _rows_in_order(result) == [1]
    assert [r.index for r in planned_rows(TaskSpace(scene), 0.05)] == [1]


def test_the_same_scene_gives_the_same_plan(models):
    scene = generate_scene("gen2", 21, 9)
    first, second = plan(scene, models), plan(scene, models)
    assert first.keypoints == second.keypoints and first.alternatives == second.alternatives


def test_a_case_outside_the_demonstrations_falls_back_to_the_nearest_gap(models):
    # Models whose demonstrations' range is a point: every case lies outside it, so each row takes
    # the gap nearest the hand's line to the target, which from the start is the nearest-gap rule.
    narrow = copy.deepcopy(models)
    narrow.row.novelty_["threshold"] = np.array(1e-12)
    scene = generate_scene("vr", 4)
    assert all(plan(scene, models).details["evidence"].values())
    result = plan(scene, narrow)
    assert result.ok and not any(result.details["evidence"].values())
    rule = nearest_gap_plan(scene)
    first_row = [k for k in result.keypoints if k.row == 1]
    assert [(k.action, k.element) for k in first_row] == [
        (k.action, k.element) for k in rule.keypoints if k.row == 1
    ]


def test_the_one_line_rule_follows_the_nearest_gap_and_keeps_the_about_as_near_ones():
    # The line from the start to the target meets the box 0.2 mm off its middle: the two gaps
    # beside it are about equally near, the nearer gets the larger share, the obstacle none.
    scene = Scene(
        name="tie",
        table=Table(length=0.8, width=0.9, height=0.75),
        start=(0.0, 0.0),
        target=SceneObject("Target", "cylinder", 0.6, 0.0, (0.066, 0.066, 0.12)),
        obstacles=(SceneObject("box", "box", 0.3, 0.0002, (0.06, 0.10, 0.10)),),
    )
    width = 0.05
    candidates = RowChoiceScene(TaskSpace(scene), width).candidates(1, np.array([scene.start]))[0]
    p = _fallback(candidates)
    assert candidates.kinds == ("gap", "gap", "object")
    assert p.sum() == pytest.approx(1.0) and p[2] == 0.0
    assert p[1] > p[0] > 0.45  # gap 2 (right, -y) is 0.4 mm nearer
    offsets = candidates.X[:2, 3]
    assert p[0] / p[1] == pytest.approx(np.exp(-(offsets[0] - offsets[1]) / FALLBACK_SCALE))


def test_ways_through_obstacles_are_reported():
    scene = generate_scene("vr", 0)
    space = TaskSpace(scene)
    target = PlanKeypoint("target", space.target.center, None, "Target")
    box = scene.obstacles[0]
    start = PlanKeypoint("start", scene.start)
    through = segment_collisions(
        space, (start, PlanKeypoint("gap", (box.x + 0.05, box.y), 1, "1"), target), 0.05
    )
    assert [c["obstacle"] for c in through if c["segment"] == 0] == [box.name]
    way = np.hypot(box.x + 0.05 - scene.start[0], box.y - scene.start[1])
    assert 0.0 < through[0]["depth"] < way  # the part of the way inside the grown obstacle, m
    # Moving the obstacle: the ways to it and with it are not collisions with it.
    moved = (
        start,
        PlanKeypoint("move", (box.x, box.y), 1, box.name, "LL"),
        PlanKeypoint("release", (box.x, box.y + 0.1), 1, box.name, "LL"),
        target,
    )
    assert not [
        c for c in segment_collisions(space, moved, 0.01) if c["obstacle"] == box.name and c["segment"] < 2
    ]


def test_planning_from_any_number_of_rows_with_fifty_boxes(models):
    rng = np.random.default_rng(0)
    obstacles = tuple(
        SceneObject(
            f"b{i}",
            "box",
            0.2 + 0.1 * (i // 5),
            -0.4 + 0.2 * (i % 5) + rng.uniform(-0.02, 0.02),
            (0.04, 0.06, 0.1),
        )
        for i in range(50)
    )
    scene = Scene(
        Table(1.3, 1.1, 0.75),
        (0.05, 0.0),
        SceneObject("Target", "cylinder", 1.25, 0.1, (0.05, 0.05, 0.1)),
        obstacles,
    )
    result = plan(scene, models)
    assert result.ok and len(_rows_in_order(result)) == 10
