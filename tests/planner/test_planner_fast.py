"""The planner's fast paths agree with the plain computations they replace."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import shapely
from threadpoolctl import ThreadpoolController

from hlp_drake.features import (
    direction_features,
    direction_index,
    gap_features,
    object_features,
    segment_feature_matrix,
)
from hlp_drake.features.direction import DirectionTable
from hlp_drake.features.segment import pair_features
from hlp_drake.learners.bundled import default_models
from hlp_drake.learners.direction import CATEGORICAL
from hlp_drake.learners.encoding import expand_directions
from hlp_drake.planner.blas import single_blas_thread
from hlp_drake.planner.candidates import nearest_per_row
from hlp_drake.planner.human_arm import sweep_collision
from hlp_drake.planner.plan import PlanKeypoint
from hlp_drake.planner.rollout import PrefixTree
from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.geometry import footprint
from hlp_drake.scene.validation import AREA_TOLERANCE, scene_problems
from hlp_drake.taskspace import DIRECTIONS, Rect, TaskSpace
from hlp_drake.taskspace.band import convex_rect_overlap
from hlp_drake.taskspace.relocation import relocated, relocated_array


@pytest.fixture(scope="module")
def models():
    return default_models()


def test_validation_rejects_the_same_overlaps_as_checking_every_pair():
    rng = np.random.default_rng(1)
    for seed in range(40):
        scene = generate_scene(("vr", "gen1", "gen2")[seed % 3], seed)
        obstacles = list(scene.obstacles)
        i, j = rng.integers(len(obstacles), size=2)
        obstacles[i] = replace(
            obstacles[i],
            x=obstacles[j].x + rng.normal(0, 0.04),
            y=obstacles[j].y + rng.normal(0, 0.04),
            yaw=float(rng.uniform(0, np.pi)),
        )
        scene = replace(scene, obstacles=tuple(obstacles))
        objects = [(scene.target, "target")] + [(o, "obstacle") for o in scene.obstacles]
        expected = []
        for k, (a, role_a) in enumerate(objects):
            for b, role_b in objects[k + 1 :]:
                area = footprint(a).intersection(footprint(b)).area
                if area > AREA_TOLERANCE:
                    expected.append(
                        f"{role_a} {a.name!r} and {role_b} {b.name!r} overlap ({area * 1e4:.2f} cm^2)"
                    )
        assert [p for p in scene_problems(scene) if " overlap (" in p] == expected


def test_polygon_box_overlap_is_exact_and_exactly_zero_or_full_at_the_extremes():
    rng = np.random.default_rng(2)
    box = np.array([[0.0, 0.0, 1.0, 0.5]])
    for _ in range(300):
        corners = rng.uniform(-1.0, 2.0, (3, 2))
        triangle = np.vstack([corners, corners[-1:]])  # the sweep's triangles repeat a corner
        expected = shapely.Polygon(corners).intersection(shapely.box(*box[0])).area
        assert convex_rect_overlap(triangle[None], box)[0, 0] == pytest.approx(expected, abs=1e-12)
    apart = np.array(
        [[[1.2, 0.1], [1.9, 0.8], [1.1, 1.4], [1.1, 1.4]]]
    )  # beside the box's corner, bounding boxes meet
    assert convex_rect_overlap(apart, box)[0, 0] == 0.0
    around = np.array([[[-0.3, -0.1], [1.7, -0.2], [1.1, 0.9], [-0.2, 0.8]]])
    assert convex_rect_overlap(around, box)[0, 0] == 0.5


def test_arm_sweep_matches_the_sum_of_its_two_triangles():
    rng = np.random.default_rng(3)
    occluders = np.array([[0.3, -0.1, 0.4, 0.05], [0.5, 0.1, 0.6, 0.2]])
    band = 0.02
    inflated = [shapely.box(*(o + [-band, -band, band, band])) for o in occluders]
    for _ in range(50):
        before, after = rng.uniform(0.0, 0.8, (1, 4, 2)), rng.uniform(0.0, 0.8, (1, 4, 2))
        expected = 0.0
        for link in range(3):
            a0, b0, a1, b1 = before[0, link], before[0, link + 1], after[0, link], after[0, link + 1]
            triangles = [shapely.Polygon([a0, b0, b1]), shapely.Polygon([a0, b1, a1])]
            expected += np.mean(
                [min(sum(t.intersection(o).area for t in triangles) / o.area, 1.0) for o in inflated]
            )
        got = sweep_collision(before, after, occluders, np.ones((1, 2), bool), band=band, faithful=False)[0]
        assert got == pytest.approx(expected, abs=1e-12)
    # A forearm sweeping right across an occluder covers all of it, exactly.
    before = np.array([[[0.0, -0.5], [0.0, -0.4], [0.0, -0.3], [0.9, -0.3]]])
    after = before + np.array([0.0, 0.6])
    assert (
        sweep_collision(before, after, occluders[:1], np.ones((1, 1), bool), band=band, faithful=False)[0]
        == 1.0
    )


@pytest.mark.parametrize("kind", ["vr", "gen2"])
def test_batched_features_match_the_per_candidate_ones(kind):
    space = TaskSpace(generate_scene(kind, 5))
    table = space.gap_table
    gaps = [g for row in space.gaps for g in row]
    assert [(g.row, g.index, g.left, g.right) for g in gaps] == list(
        zip(table.row, table.index, table.left, table.right)
    )
    assert [g.center for g in gaps] == [tuple(c) for c in table.centers.tolist()]
    some = np.arange(0, len(gaps), 2)
    assert np.array_equal(gap_features(space, some), gap_features(space)[some])
    some = np.arange(1, len(space.obstacle_names), 2)
    assert np.array_equal(object_features(space, some), object_features(space)[some])
    # All row pairs in one call equal one call per row pair.
    blocks = [
        segment_feature_matrix(space, space.nodes(r), space.nodes(r + 1), mode="fixed")
        for r in range(1, len(space.rows))
    ]
    pa, pb, own_a, own_b = [], [], [], []
    for r in range(1, len(space.rows)):
        for a in space.nodes(r):
            for b in space.nodes(r + 1):
                pa.append(a.center), pb.append(b.center)
                own_a.append(-1 if a.obstacle is None else space.obstacle_index[a.obstacle])
                own_b.append(-1 if b.obstacle is None else space.obstacle_index[b.obstacle])
    batched = pair_features(space, np.array(pa), np.array(pb), np.array(own_a), np.array(own_b), mode="fixed")
    assert np.array_equal(batched, np.vstack(blocks))


@pytest.mark.parametrize("mode", ["fixed", "faithful"])
def test_direction_table_and_relocation_match_single_obstacles(mode):
    space = TaskSpace(generate_scene("vr", 6))
    names = space.obstacle_names
    table = DirectionTable(space, names, mode=mode)
    for k, name in enumerate(names):
        for hand in [(0.1, 0.0), (0.5, 0.3), space.rects[name].center]:
            expected = direction_features(space, name, hand=hand, mode=mode)
            assert np.array_equal(table.features(k, direction_index(table.hand_direction(k, hand))), expected)
    regions = relocated_array(space.obstacle_bounds, space.alpha)
    for k, name in enumerate(names):
        for d, direction in enumerate(DIRECTIONS):
            assert Rect(*regions[k, d].tolist()) == relocated(space.rects[name], direction, space.alpha)


def test_nearest_per_row_keeps_the_nearest_of_each_row_in_order():
    rows = np.array([1, 1, 1, 2, 2, 1, 2])
    centres = np.array(
        [[0.3, 0.4], [0.3, -0.15], [0.3, 0.1], [0.6, 0.0], [0.6, 0.5], [0.3, -0.1], [0.6, -0.2]]
    )
    kept = nearest_per_row(rows, centres, np.array([0.0, 0.0]), np.array([1.0, 0.0]), 2)
    assert kept.tolist() == [2, 3, 5, 6]  # row 1: 0.1 and -0.1 (a tie) beat -0.15; row 2: 0.0 and -0.2
    ties = nearest_per_row(
        np.array([1, 1, 1]),
        np.array([[0.3, 0.1], [0.3, -0.1], [0.3, 0.1]]),
        np.zeros(2),
        np.array([1.0, 0.0]),
        2,
    )
    assert ties.tolist() == [0, 1]  # equally near: the first ones


def test_arm_rollout_matches_predicting_one_depth_at_a_time(models):
    rng = np.random.default_rng(4)
    parent = [-1, 0, 0, 1, 1, 2, 4]
    moves = np.column_stack([rng.normal(0, 0.2, (7, 2)), rng.integers(-1, 8, 7)])
    start = np.array([1.3, 2.4])
    expected = np.zeros((7, 2))
    expected[0] = start
    for node in range(1, 7):  # parents come first
        X = np.concatenate([expected[parent[node]], moves[node]])[None]
        expected[node] = np.clip(models.arm.predict(X)[0], 0.0, np.pi)
    assert models.arm.rollout(start, parent, moves, limits=(0.0, np.pi)) == pytest.approx(expected, abs=1e-12)


def test_direction_votes_count_every_one_vs_one_pair(models):
    model = models.direction
    rng = np.random.default_rng(5)
    X = np.column_stack([rng.uniform(0, 1, (50, 8)), rng.integers(-1, 8, (50, 2))])
    scores = expand_directions(X, CATEGORICAL) @ model.coef_.T + model.intercept_
    votes = np.zeros((50, len(model.classes_)))
    pairs = [(i, j) for i in range(len(model.classes_)) for j in range(i + 1, len(model.classes_))]
    for k, (i, j) in enumerate(pairs):
        votes[:, i] += scores[:, k] > 0
        votes[:, j] += scores[:, k] <= 0
    assert np.array_equal(model.votes(X), votes)


def test_prefix_tree_shares_equal_prefixes():
    start, gap, move, target = (
        PlanKeypoint(a, (float(i), 0.0)) for i, a in enumerate(("start", "gap", "move", "target"))
    )
    paths = [[start, gap, target], [start, gap, move, target], [start, move, target]]
    tree = PrefixTree.of(paths)
    assert (
        len(tree.keypoints) == 7
    )  # start; gap and its target; gap's move and its target; move and its target
    assert [[tree.keypoints[n] for n in [0, *nodes]] for nodes in tree.paths] == paths
    assert all(tree.parent[n] < n for n in range(1, len(tree.parent)))


def test_single_blas_thread_nests_and_restores():
    controller = ThreadpoolController()
    before = [lib.num_threads for lib in controller.select(user_api="blas").lib_controllers]
    with single_blas_thread():
        with single_blas_thread():
            assert all(
                lib.num_threads == 1 for lib in ThreadpoolController().select(user_api="blas").lib_controllers
            )
        assert all(
            lib.num_threads == 1 for lib in ThreadpoolController().select(user_api="blas").lib_controllers
        )
    assert [
        lib.num_threads for lib in ThreadpoolController().select(user_api="blas").lib_controllers
    ] == before
