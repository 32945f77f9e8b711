"""Row-choice features and free-space routes on constructed scenes (no dataset)."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from hlp_drake.features.row_choice import (
    CONTEXT_FEATURES,
    ROUTE_OBSTACLES,
    ROW_CHOICE_FEATURES,
    ROW_CONTEXT_FEATURES,
    RowChoiceScene,
)
from hlp_drake.features.training import row_choice_rows
from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.model import Scene, SceneObject, Table
from hlp_drake.segmentation.demonstration import RowDecision
from hlp_drake.taskspace import TaskSpace
from hlp_drake.taskspace.routes import FreeRoutes, segment_hits, segment_inside

COLUMN = {name: k for k, name in enumerate(ROW_CHOICE_FEATURES)}


def _wall_scene(gap_left: float, gap_right: float) -> Scene:
    """A 1 m table with one row of two boxes at x = 0.5 leaving a gap between y = gap_right and
    y = gap_left, the start and the target on the centre line."""
    table = Table(1.0, 1.0, 0.7)
    left = SceneObject("left", "box", 0.5, (gap_left + 0.5) / 2.0, (0.05, 0.5 - gap_left, 0.1))
    right = SceneObject("right", "box", 0.5, (gap_right - 0.5) / 2.0, (0.05, gap_right + 0.5, 0.1))
    return Scene(
        table, (0.1, 0.0), SceneObject("Target", "cylinder", 0.9, 0.0, (0.05, 0.05, 0.1)), (left, right)
    )


def _scaled(scene: Scene, s: float) -> Scene:
    def obj(o: SceneObject) -> SceneObject:
        return replace(o, x=o.x * s, y=o.y * s, size=(o.size[0] * s, o.size[1] * s, o.size[2]))

    return Scene(
        Table(scene.table.length * s, scene.table.width * s, scene.table.height),
        (scene.start[0] * s, scene.start[1] * s),
        obj(scene.target),
        tuple(obj(o) for o in scene.obstacles),
    )


def test_segments_through_rectangles():
    rects = np.array([[0.0, 0.0, 1.0, 1.0]])
    starts, ends = (
        np.array([[-1.0, 0.5], [-1.0, 1.0], [0.5, 0.5]]),
        np.array([[2.0, 0.5], [2.0, 1.0], [0.5, 2.0]]),
    )
    assert segment_hits(starts, ends, rects)[:, 0].tolist() == [True, False, True]  # along an edge: no hit
    assert segment_inside(starts, ends, rects)[:, 0] == pytest.approx([1.0, 0.0, 0.5])


def test_segment_hits_agree_with_the_clipped_length_on_a_grid():
    """The separating-axis test says "hit" exactly where the clipped length inside is more than
    1e-9 of the way, on a grid of 1/64 m (exact in binary: ways along edges, through corners, from
    a side)."""
    rng = np.random.default_rng(3)
    low = rng.integers(0, 26, (12, 2)) / 64.0
    rects = np.hstack([low, low + rng.integers(1, 10, (12, 2)) / 64.0])
    starts, ends = rng.integers(-3, 40, (3000, 2)) / 64.0, rng.integers(-3, 40, (3000, 2)) / 64.0
    ends[:50] = starts[:50]  # points: inside a rectangle or not
    length = np.linalg.norm(ends - starts, axis=1)[:, None]
    clipped = segment_inside(starts, ends, rects) > 1e-9 * length
    points = length[:, 0] == 0.0
    inside = (starts[points, None, 0] > rects[None, :, 0]) & (starts[points, None, 0] < rects[None, :, 2])
    inside &= (starts[points, None, 1] > rects[None, :, 1]) & (starts[points, None, 1] < rects[None, :, 3])
    clipped[points] = inside
    hits = segment_hits(starts, ends, rects)
    assert np.array_equal(hits, clipped)
    assert 0 < hits.sum() < hits.size


def test_routes_go_round_the_obstacles_or_through_a_gap():
    # A wall across the table with a gap 0.2 m wide on the left; the hand 0.05 m wide.
    scene = _wall_scene(gap_left=0.3, gap_right=0.1)
    space = TaskSpace(scene)
    goal = np.array(space.target.center)
    routes = FreeRoutes(space.obstacle_bounds, np.arange(2), scene.table.bounds, 0.05, goal)
    start = np.array(scene.start)
    sight = routes.sight(start)
    # Round the right box grown by half the hand's width (x 0.45-0.55, y up to 0.125).
    corner_front, corner_back = np.array([0.45, 0.125]), np.array([0.55, 0.125])
    expected = np.linalg.norm(corner_front - start) + 0.1 + np.linalg.norm(goal - corner_back)
    assert routes.to_goal(sight, np.array([0]), frozenset())[0] == pytest.approx(expected, abs=1e-5)
    # With the blocking box moved away the way is straight.
    assert routes.to_goal(sight, np.array([0]), frozenset({1}))[0] == pytest.approx(
        np.linalg.norm(goal - start)
    )
    # A gap narrower than the hand closes the way: no route at all.
    closed = _wall_scene(gap_left=0.12, gap_right=0.1)
    space = TaskSpace(closed)
    routes = FreeRoutes(space.obstacle_bounds, np.arange(2), closed.table.bounds, 0.05, goal)
    assert not np.isfinite(routes.to_goal(routes.sight(start), np.array([0]), frozenset())[0])


def test_candidates_of_a_row_and_their_features():
    scene = _wall_scene(gap_left=0.3, gap_right=0.1)
    features = RowChoiceScene(TaskSpace(scene), 0.05)
    (candidates,) = features.candidates(1, np.array(scene.start))
    assert candidates.kinds == ("gap", "object", "object")  # the one gap, then the boxes from left to right
    X = candidates.X
    middle = 0
    assert candidates.points[middle] == pytest.approx([0.5, 0.125])  # nearest the line where the hand fits
    assert X[middle, COLUMN["size"]] == pytest.approx(4.0)  # 0.2 m in hand widths
    assert X[middle, COLUMN["offset"]] == pytest.approx(2.5)  # 0.125 m off the line
    assert X[1:, COLUMN["is_object"]].tolist() == [1.0, 1.0]
    right = 2
    assert candidates.obstacles[right] == 1 and X[right, COLUMN["corridor_overlap"]] == pytest.approx(1.0)
    assert (
        X[right, COLUMN["route_gain"]] > 0.0 and X[1, COLUMN["route_gain"]] == 0.0
    )  # only the one in the way
    assert X[middle, COLUMN["route_via"]] == pytest.approx(1.0)  # the shortest route passes through it
    assert X[:, COLUMN["row_best_offset"]] == pytest.approx(2.5)


def test_features_mean_the_same_on_any_table():
    """Scaling a scene and the hand's width alike leaves every feature unchanged."""
    scene = generate_scene("unstructured", 4)
    for s in (0.5, 1.7):
        a, b = RowChoiceScene(TaskSpace(scene), 0.05), RowChoiceScene(TaskSpace(_scaled(scene, s)), 0.05 * s)
        for row in range(1, len(TaskSpace(scene).rows) + 1):
            hand = np.array(scene.start)
            (x,), (y,) = a.candidates(row, hand), b.candidates(row, hand * s)
            assert x.kinds == y.kinds
            np.testing.assert_allclose(x.X, y.X, atol=1e-7)


def test_one_call_for_several_hands_equals_one_call_each():
    scene = generate_scene("gen2", 5, 9)
    features = RowChoiceScene(TaskSpace(scene), 0.08)
    hands = np.array([scene.start, (0.2, 0.1), (0.3, -0.2)])
    removed = [frozenset(), frozenset({0}), frozenset({1, 2})]
    together = features.candidates(2, hands, removed, limit=3)
    for hand, gone, batch in zip(hands, removed, together):
        (alone,) = features.candidates(2, hand, [gone], limit=3)
        assert alone.kinds == batch.kinds
        np.testing.assert_allclose(alone.X, batch.X)
        np.testing.assert_allclose(alone.points, batch.points)


def test_the_route_graph_holds_the_obstacles_nearest_the_reach_on_any_table():
    """Its size does not grow with the object count: on a crowded table it holds the
    ``ROUTE_OBSTACLES`` obstacles nearest the start-target line, on a VR-sized one all of them."""
    crowded = generate_scene("gen2", 3, 25)
    space = TaskSpace(crowded)
    routes = RowChoiceScene(space, 0.08).routes
    start, goal = np.array(crowded.start), np.array(space.target.center)
    span = (goal - start) / np.linalg.norm(goal - start)
    d = space.obstacle_centres - start
    offset = np.abs(span[0] * d[:, 1] - span[1] * d[:, 0])
    assert len(routes.ids) == ROUTE_OBSTACLES < len(crowded.obstacles)
    assert offset[routes.ids].max() <= np.sort(offset)[ROUTE_OBSTACLES - 1] + 1e-12
    vr_sized = generate_scene("gen2", 3, 6)  # six obstacles, as in every VR scene
    assert len(RowChoiceScene(TaskSpace(vr_sized), 0.08).routes.ids) == len(vr_sized.obstacles) == 6


def _two_rows() -> Scene:
    """Two rows of two boxes each (x = 0.35 and 0.65), a gap in the middle of each; the start and
    the target on the centre line."""
    table = Table(1.0, 1.0, 0.7)
    boxes = (
        SceneObject("a", "box", 0.35, 0.25, (0.05, 0.4, 0.1)),
        SceneObject("b", "box", 0.35, -0.25, (0.05, 0.4, 0.1)),
        SceneObject("c", "box", 0.65, 0.3, (0.05, 0.3, 0.1)),
        SceneObject("d", "box", 0.65, -0.2, (0.05, 0.5, 0.1)),
    )
    return Scene(table, (0.1, 0.0), SceneObject("Target", "cylinder", 0.9, 0.0, (0.05, 0.05, 0.1)), boxes)


def test_the_context_reads_the_way_the_hand_came():
    """Where the hand came from: by a release or a gap (or from the start), after how many moves,
    and how far it turns to each candidate from its heading."""
    scene = _two_rows()
    features = RowChoiceScene(TaskSpace(scene), 0.05)
    hands = np.array([[0.1, 0.0], [0.35, 0.0], [0.4, 0.2]])
    previous = np.array([[0.1, 0.0], [0.1, 0.0], [0.35, 0.3]])  # the last heads along -y
    came_by = ["start", "gap", "release"]
    X = [c.X for c in features.candidates(2, hands, [(), (), {0}], previous=previous, came_by=came_by)]
    column = {name: k for k, name in enumerate(ROW_CONTEXT_FEATURES)}
    move, gap, moves, turn = (column[n] for n in CONTEXT_FEATURES)
    assert [x[0, move] for x in X] == [0.0, 0.0, 1.0] and [x[0, gap] for x in X] == [0.0, 1.0, 0.0]
    assert [x[0, moves] for x in X] == [0.0, 0.0, 1.0]
    # From the start the heading is the target's way; headed along +x, the turn to a candidate is
    # its angle off the x axis, seen from the hand.
    (start,) = features.candidates(2, hands[:1])
    points = start.points - hands[0]
    assert X[0][:, turn] == pytest.approx(np.abs(np.arctan2(points[:, 1], points[:, 0])))
    np.testing.assert_allclose(X[0][:, : len(ROW_CHOICE_FEATURES)], start.X[:, : len(ROW_CHOICE_FEATURES)])
    assert X[0][:, move].tolist() == start.X[:, move].tolist()  # the start, unsaid
    # Heading from (0.35, 0.3) to (0.4, 0.2): the turn is the angle between that and the way on.
    heading = hands[2] - previous[2]
    ways = features.candidates(2, hands[2:], [{0}])[0].points - hands[2]
    cosine = ways @ heading / (np.linalg.norm(ways, axis=1) * np.linalg.norm(heading))
    assert X[2][:, turn] == pytest.approx(np.arccos(np.clip(cosine, -1.0, 1.0)))


def test_the_training_rows_read_the_previous_rows_decision():
    """The second row's examples say how the person left the first: through its gap, or by moving
    an obstacle (then one move before, the hand at the release, heading the way it pushed)."""
    scene = _two_rows()
    space = TaskSpace(scene)
    column = {name: k for k, name in enumerate(ROW_CONTEXT_FEATURES)}

    def second_row(first: RowDecision):
        demo = SimpleNamespace(
            scene=scene, left_handed=False, decisions=(first, RowDecision(2, "gap", gap=1))
        )
        rows = row_choice_rows(demo, space)
        assert len(rows) == 2
        return rows[1][0]

    through = second_row(RowDecision(1, "gap", gap=1))
    assert np.all(through[:, column["came_by_gap"]] == 1.0) and np.all(
        through[:, column["came_by_move"]] == 0.0
    )
    assert np.all(through[:, column["moves_before"]] == 0.0)
    moved = second_row(RowDecision(1, "object", obstacle="b", direction="RR"))
    assert np.all(moved[:, column["came_by_move"]] == 1.0) and np.all(moved[:, column["came_by_gap"]] == 0.0)
    assert np.all(moved[:, column["moves_before"]] == 1.0)
    first = row_choice_rows(
        SimpleNamespace(scene=scene, left_handed=False, decisions=(RowDecision(1, "gap", gap=1),)), space
    )[0][0]
    assert np.all(first[:, column["came_by_gap"]] == 0.0) and np.all(first[:, column["came_by_move"]] == 0.0)
