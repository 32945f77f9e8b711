"""Fuzzing the scene boundary: scene files (YAML, JSON) through ``load_scene``, Scene objects built
directly and generated layouts moved about, all through ``plan()``.

The promise checked on every example: a file either loads or is refused with a ``SceneError`` of at
most 21 lines of at most 300 characters; ``plan()`` returns a plan or a "no plan" with a reason for
anything it is given, and never raises.
"""

from __future__ import annotations

from dataclasses import replace

import pytest
from fuzz_support import PROFILES, STATS, check_error, generated, junk, numbers, run, scene_file, scene_texts
from hypothesis import given, settings
from hypothesis import strategies as st

from hlp_drake.errors import SceneError
from hlp_drake.learners.bundled import default_models
from hlp_drake.planner import plan
from hlp_drake.planner.plan import HighLevelPlan
from hlp_drake.scene.generators import KINDS
from hlp_drake.scene.io import load_scene
from hlp_drake.scene.model import SHAPES, Scene, SceneObject, Table
from hlp_drake.scene.validation import (
    SIZE_RANGE,
    YAW_LIMIT,
    _object_problems,
    _plainly_sound,
    scene_problems,
)


def _check_plan(scene: object) -> None:
    result = plan(scene, default_models())
    assert isinstance(result, HighLevelPlan) and (result.ok or result.reason)
    STATS["plans" if result.ok else "no plans (with a reason)"] += 1


def _check_scene_file(case: tuple[str, str]) -> None:
    STATS["scene files"] += 1
    with scene_file(case) as path:
        try:
            scene = load_scene(path)
        except SceneError as error:
            check_error(error)
            STATS["scene files refused"] += 1
            return
    STATS["scene files loaded"] += 1
    _check_plan(scene)


@pytest.mark.parametrize("profile", PROFILES)
def test_scene_files_load_or_are_refused_and_every_loaded_scene_plans(profile):
    run(profile, (150, 4000), scene_texts(), _check_scene_file)


def _maybe(strategy):
    return st.one_of(strategy, strategy, strategy, junk)


_objects = st.builds(
    SceneObject,
    name=_maybe(st.text(min_size=1, max_size=6)),
    shape=_maybe(st.sampled_from(SHAPES)),
    x=_maybe(st.floats(0.0, 1.3)),
    y=_maybe(st.floats(-0.5, 0.5)),
    size=_maybe(st.tuples(*[st.floats(0.004, 0.3)] * 3)),
    yaw=_maybe(st.floats(-7.0, 7.0)),
)
_scenes = st.builds(
    Scene,
    table=_maybe(
        st.builds(
            Table,
            length=_maybe(st.floats(0.1, 6.0)),
            width=_maybe(st.floats(0.1, 6.0)),
            height=_maybe(st.floats(0.1, 6.0)),
        )
    ),
    start=_maybe(st.tuples(st.floats(0.0, 0.3), st.floats(-0.4, 0.4))),
    target=_maybe(_objects),
    obstacles=_maybe(st.lists(_objects, max_size=8).map(tuple)),
    start_yaw=_maybe(numbers),
    name=_maybe(st.text(max_size=10)),
)


def _check_direct(scene: object) -> None:
    STATS["scenes built directly"] += 1
    problems = scene_problems(scene)
    assert isinstance(problems, list) and all(isinstance(p, str) for p in problems)
    _check_plan(scene)


@pytest.mark.parametrize("profile", PROFILES)
def test_plan_never_raises_on_scenes_built_directly(profile):
    run(profile, (200, 4000), st.one_of(_scenes, junk), _check_direct)


@st.composite
def _moved_layouts(draw) -> Scene:
    """A generated scene with its table resized and some objects moved, resized or dropped."""
    scene = generated(draw(st.sampled_from(KINDS)), draw(st.integers(0, 200)))
    scale = draw(st.floats(0.8, 1.25))
    table = replace(
        scene.table, length=scene.table.length * scale, width=scene.table.width * draw(st.floats(0.8, 1.25))
    )
    obstacles = []
    for obstacle in scene.obstacles:
        action = draw(st.sampled_from(["keep", "keep", "move", "resize", "drop"]))
        if action == "move":
            obstacle = obstacle.moved(
                obstacle.x + draw(st.floats(-0.15, 0.15)),
                obstacle.y + draw(st.floats(-0.2, 0.2)),
                draw(st.floats(-3.2, 3.2)),
            )
        elif action == "resize":
            obstacle = replace(obstacle, size=tuple(v * draw(st.floats(0.5, 2.0)) for v in obstacle.size))
        if action != "drop":
            obstacles.append(obstacle)
    return replace(scene, table=table, obstacles=tuple(obstacles), name=f"{scene.name} moved")


def _check_layout(scene: Scene) -> None:
    STATS["layouts moved"] += 1
    STATS["layouts moved and valid"] += not scene_problems(scene)
    _check_plan(scene)


@pytest.mark.parametrize("profile", PROFILES)
def test_plan_answers_every_moved_layout(profile):
    run(profile, (100, 3000), _moved_layouts(), _check_layout)


_edge_floats = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([SIZE_RANGE[0], SIZE_RANGE[1], YAW_LIMIT, -YAW_LIMIT, 0.0, -0.0, 1e-9]),
    st.floats(SIZE_RANGE[0] * 0.99, SIZE_RANGE[1] * 1.01),
)
_objects = st.builds(
    SceneObject,
    name=st.one_of(st.text(max_size=3), st.text(min_size=99, max_size=102), junk),
    shape=st.one_of(st.sampled_from(SHAPES), junk),
    x=st.one_of(_edge_floats, junk),
    y=_edge_floats,
    size=st.one_of(
        st.tuples(_edge_floats, _edge_floats, _edge_floats),
        st.floats(0.01, 0.5).map(lambda d: (d, d * (1 + 1e-7), 0.1)),  # a cylinder's nearly equal diameters
        junk,
    ),
    yaw=_edge_floats,
)


@given(st.lists(_objects, max_size=6))
@settings(max_examples=400, deadline=None)
def test_objects_checked_in_bulk_are_the_ones_found_sound_one_by_one(objects):
    """The bulk check of plain objects agrees with the one-by-one check on every object it passes
    (and a plain object of floats the one-by-one check finds sound is passed in bulk)."""
    bulk = _plainly_sound(objects)
    for k, obj in enumerate(objects):
        alone = _object_problems(obj, "obstacle", k)
        if bulk[k]:
            assert alone == []
        elif alone == [] and all(type(v) is float for v in (obj.x, obj.y, obj.yaw)):
            assert type(obj.size) is not tuple or not all(type(v) is float for v in obj.size)
