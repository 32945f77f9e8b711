"""Mirror augmentation of the row-choice examples: a mirrored scene's features are the mirrored features."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest

from hlp_drake.features.augment import (
    SIGNED_COLUMNS,
    mirror_features,
    mirror_scene,
    mirrored_rows,
    perturbed_scene,
    same_layout,
)
from hlp_drake.features.row_choice import ROW_CONTEXT_FEATURES, RowChoiceScene
from hlp_drake.features.training import row_choice_rows
from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.model import Scene, SceneObject, Table
from hlp_drake.segmentation.demonstration import RowDecision
from hlp_drake.taskspace import TaskSpace

COLUMN = {name: k for k, name in enumerate(ROW_CONTEXT_FEATURES)}


def _two_gaps() -> Scene:
    """One row of three boxes at x = 0.5 leaving a wide gap on the left (y 0.06 to 0.25) and a
    narrow one on the right (y -0.15 to -0.04, nearer the line); the start and the target on the
    centre line."""
    table = Table(1.0, 1.0, 0.7)
    boxes = (
        SceneObject("a", "box", 0.5, 0.375, (0.05, 0.25, 0.1)),
        SceneObject("b", "box", 0.5, 0.01, (0.05, 0.1, 0.1)),
        SceneObject("c", "box", 0.5, -0.325, (0.05, 0.35, 0.1)),
    )
    return Scene(table, (0.1, 0.0), SceneObject("Target", "cylinder", 0.9, 0.0, (0.05, 0.05, 0.1)), boxes)


def _by_point(candidates):
    """Candidate order by (kind, lateral position): the same element of a scene and its mirror
    image sorted alike once the mirror's lateral positions are negated."""
    return {
        (kind, round(float(p[1]), 9)): k
        for k, (kind, p) in enumerate(zip(candidates.kinds, candidates.points))
    }


def test_the_left_gap_maps_to_the_mirrored_right_gap():
    scene = _two_gaps()
    (seen,) = RowChoiceScene(TaskSpace(scene), 0.05).candidates(1, np.array(scene.start))
    (mirror,) = RowChoiceScene(TaskSpace(mirror_scene(scene)), 0.05).candidates(1, np.array([0.1, 0.0]))
    assert seen.kinds[:2] == mirror.kinds[:2] == ("gap", "gap")
    # Gaps run left to right: the wide left gap is the first here and the second in the mirror.
    assert seen.X[0, COLUMN["size"]] == pytest.approx(3.8) and seen.X[1, COLUMN["size"]] == pytest.approx(2.2)
    assert mirror.X[1, COLUMN["size"]] == pytest.approx(3.8)
    assert seen.X[0, COLUMN["signed_offset"]] > 0 > mirror.X[1, COLUMN["signed_offset"]]
    np.testing.assert_allclose(mirror.X[1], mirror_features(seen.X[:1])[0], atol=1e-9)
    np.testing.assert_allclose(mirror.X[0], mirror_features(seen.X[1:2])[0], atol=1e-9)


@pytest.mark.parametrize("seed", [4, 11])
def test_every_candidate_of_a_mirrored_scene_has_the_mirrored_features(seed):
    scene = generate_scene("unstructured", seed)
    space, mirrored = TaskSpace(scene), TaskSpace(mirror_scene(scene))
    a, b = RowChoiceScene(space, 0.05), RowChoiceScene(mirrored, 0.05)
    start = np.array(scene.start)
    for row in range(1, len(space.rows) + 1):
        (x,), (y,) = a.candidates(row, start), b.candidates(row, start * [1.0, -1.0])
        assert sorted(x.kinds) == sorted(y.kinds)
        left, right = _by_point(x), {(kind, -p): k for (kind, p), k in _by_point(y).items()}
        assert left.keys() == right.keys()
        order = [right[key] for key in left]
        np.testing.assert_allclose(y.X[order], mirror_features(x.X[list(left.values())]), atol=1e-7)


def test_mirror_features_negate_only_the_signed_columns_and_keep_the_labels():
    X = np.arange(2 * len(ROW_CONTEXT_FEATURES), dtype=float).reshape(2, -1) + 1.0
    mirrored = mirror_features(X)
    changed = np.flatnonzero(mirrored[0] != X[0]).tolist()
    assert changed == sorted(SIGNED_COLUMNS)
    assert mirrored[0, list(SIGNED_COLUMNS)] == pytest.approx(-X[0, list(SIGNED_COLUMNS)])
    X2, y2, groups = mirrored_rows(X, np.array([1.0, 0.0]), np.array(["s1", "s2"]))
    assert X2.shape == (4, X.shape[1]) and y2.tolist() == [1.0, 0.0, 1.0, 0.0]
    assert groups.tolist() == ["s1", "s2", "s1", "s2"]
    np.testing.assert_array_equal(mirror_features(X2[2:]), X)  # a mirror's mirror is the scene


def test_small_perturbations_keep_the_layout_and_the_persons_choice():
    # On a wider table the row leaves a gap at either edge too: 1 cm shifts keep all four.
    scene = replace(_two_gaps(), table=Table(1.0, 1.2, 0.7))
    rng = np.random.default_rng(0)
    space = TaskSpace(scene)
    for _ in range(5):
        moved = perturbed_scene(scene, rng, position=0.01, size=0.1)
        for before, after in zip(scene.obstacles, moved.obstacles):
            assert abs(after.x - before.x) <= 0.01 and abs(after.y - before.y) <= 0.01
            assert 0.9 <= after.size[1] / before.size[1] <= 1.1 and after.size[2] == before.size[2]
        assert moved.start == scene.start and moved.target == scene.target
        assert same_layout(space, TaskSpace(moved))
        demo = SimpleNamespace(scene=moved, left_handed=False, decisions=(RowDecision(1, "gap", gap=2),))
        ((X, y),) = row_choice_rows(demo, TaskSpace(moved))
        assert y.tolist() == [0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0]  # still the wide gap left of the line
        assert X[1, COLUMN["size"]] > X[2, COLUMN["size"]]


def test_a_perturbation_that_closes_a_gap_changes_the_layout():
    scene = _two_gaps()
    a, b, c = scene.obstacles
    closed = replace(scene, obstacles=(a, replace(b, size=(0.05, 0.4, 0.1)), c))  # b overlaps c
    assert not same_layout(TaskSpace(scene), TaskSpace(closed))
