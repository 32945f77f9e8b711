"""The human-like planner on generated scenes with the bundled models."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from hlp_drake.learners.bundled import default_models
from hlp_drake.planner import PlannerConfig, plan
from hlp_drake.scene.generators import generate_scene
from hlp_drake.taskspace import TaskSpace


@pytest.fixture(scope="module")
def models():
    return default_models()


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


def test_the_same_scene_gives_the_same_plan(models):
    scene = generate_scene("gen1", 8)
    assert plan(scene, models).to_dict()["keypoints"] == plan(scene, models).to_dict()["keypoints"]


def test_bad_scenes_give_a_reason_not_an_exception(models):
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
