"""The paper's planner (Algorithm 1, paper-preset models) on generated scenes; bad scenes for both planners."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from hlp_drake.learners.bundled import default_models
from hlp_drake.planner import PlannerConfig, plan
from hlp_drake.scene.generators import generate_scene
from hlp_drake.taskspace import TaskSpace


@pytest.fixture(scope="module")
def models(paper_models):
    return paper_models


@pytest.mark.dataset
@pytest.mark.parametrize("kind", ["vr", "gen1", "gen2"])
def test_plans_pass_every_row_and_end_at_the_target(models, kind):
    scene = generate_scene(kind, 3)
    result = plan(scene, models)
    assert result.ok, result.reason
    actions = [k.action for k in result.keypoints]
    assert actions[0] == "start" and actions[-1] == "target"
    rows = {k.row for k in result.keypoints if k.action in ("gap", "move")}
    assert rows == {row.index for row in TaskSpace(scene).rows}
    for k, following in zip(result.keypoints, result.keypoints[1:]):
        if k.action == "move":  # an obstacle to move is followed by where it is released
            assert following.action == "release" and following.element == k.element and following.direction
    assert all(k.arm is not None and 0 <= k.arm[0] <= np.pi for k in result.keypoints)
    assert result.waypoints.shape == (len(result.keypoints), 2)
    assert result.expected_collision >= 0
    assert all(result.expected_collision <= c.expected_collision for c in result.alternatives)


@pytest.mark.dataset
def test_the_same_scene_gives_the_same_plan(models):
    scene = generate_scene("gen1", 8)
    assert plan(scene, models).to_dict()["keypoints"] == plan(scene, models).to_dict()["keypoints"]


@pytest.mark.parametrize("planner", ["rows", "paper"])
def test_bad_scenes_give_a_reason_not_an_exception(planner, request):
    models = default_models() if planner == "rows" else request.getfixturevalue("paper_models")
    scene = generate_scene("vr", 1)
    off = replace(scene, obstacles=(replace(scene.obstacles[0], y=5.0), *scene.obstacles[1:]))
    result = plan(off, models)
    assert not result.ok and "invalid scene" in result.reason and "off the table" in result.reason
    empty = plan(replace(scene, obstacles=()), models)  # no rows: straight to the target
    assert empty.ok and [k.action for k in empty.keypoints] == ["start", "target"]
    one = plan(replace(scene, obstacles=scene.obstacles[:1]), models)
    assert one.ok and len({k.row for k in one.keypoints if k.row}) == 1
    mismatch = plan(scene, models, PlannerConfig(mode="faithful"))
    assert not mismatch.ok and "fixed mode" in mismatch.reason


@pytest.mark.dataset
def test_rows_the_classifiers_know_nothing_about_keep_what_lies_nearest_the_reach(models):
    """Gen II scenes lie outside the demonstrations: Cg and Co score (almost) every candidate with
    their intercept. Such a row keeps the gap and the obstacle nearest the start-target line, not
    the first in order, so the plan moves the one obstacle the straight reach would hit."""
    from hlp_drake.planner.candidates import informed, line_offsets

    scene = generate_scene("gen2", 0, 5)
    space = TaskSpace(scene)
    result = plan(scene, models)
    gap_scores = np.array(list(result.details["gap_scores"].values()))
    object_scores = np.array(list(result.details["object_scores"].values()))
    config = PlannerConfig()
    assert not informed(gap_scores, models.gap.intercept_, config.min_evidence).any()
    assert not informed(object_scores, models.object.intercept_, config.min_evidence).any()
    start, target = np.asarray(scene.start), np.asarray(space.target.center)
    offsets = dict(zip(space.obstacle_names, line_offsets(space.obstacle_centres, start, target)))
    for row, names in result.details["candidates"].items():
        kept = [n for n in names if n in offsets]
        in_row = [n for n, r in zip(space.obstacle_names, space.obstacle_rows.tolist()) if str(r) == row]
        assert kept == [min(in_row, key=offsets.get)]
    moved = [k.element for k in result.keypoints if k.action == "move"]
    assert moved == ["obstacle_5"]  # the only obstacle within 10 cm of the line
    assert offsets["obstacle_5"] < 0.1 and sorted(offsets.values())[1] > 0.2


def test_candidates_with_evidence_still_follow_the_classifiers():
    from hlp_drake.planner.candidates import _accepted, enumerate_paths

    offsets = [0.3, 0.0, 0.1]
    assert _accepted([-0.5, -0.5, -0.5], [False] * 3, offsets, 2) == [1]  # no evidence: nearest the line
    assert _accepted([-0.2, -0.5, -0.5], [True, False, False], offsets, 2) == [0]  # the best-scored
    assert _accepted([0.4, -0.5, 0.2], [True, False, True], offsets, 1) == [0]  # the accepted ones, capped
    block = np.array([[-0.5, -0.5], [-0.5, -0.5]])
    two_best = enumerate_paths([2, 2], [block], 10)
    assert len(two_best) == 3  # the original's rule: the two best pairs, and node 1 along its best
    every = enumerate_paths([2, 2], [block], 10, [np.zeros((2, 2), bool)])
    assert sorted(nodes for nodes, _ in every) == [(0, 0), (0, 1), (1, 0), (1, 1)]
