"""Scene files: round trips, and one clear message per problem."""

from __future__ import annotations

import math
from dataclasses import replace

import pytest
import yaml

from hlp_drake.errors import SceneError
from hlp_drake.scene import (
    Scene,
    SceneObject,
    Table,
    generate_scene,
    load_scene,
    save_scene,
    scene_problems,
    scene_to_dict,
)


def small_scene(**changes) -> Scene:
    scene = Scene(
        table=Table(length=0.8, width=1.0, height=0.75),
        start=(0.1, 0.0),
        target=SceneObject("Target", "cylinder", 0.7, 0.0, (0.06, 0.06, 0.12)),
        obstacles=(
            SceneObject("box_a", "box", 0.4, 0.2, (0.05, 0.15, 0.12)),
            SceneObject("can_b", "cylinder", 0.4, -0.2, (0.08, 0.08, 0.15)),
        ),
        name="small",
    )
    return replace(scene, **changes)


def with_obstacle(index: int, **changes) -> Scene:
    scene = small_scene()
    obstacles = list(scene.obstacles)
    obstacles[index] = replace(obstacles[index], **changes)
    return replace(scene, obstacles=tuple(obstacles))


@pytest.mark.parametrize("suffix", [".yaml", ".json"])
@pytest.mark.parametrize("kind", ["vr", "gen1", "gen2", "unstructured"])
def test_round_trip_is_exact(tmp_path, suffix, kind):
    scene = generate_scene(kind, seed=11)
    first = tmp_path / f"a{suffix}"
    second = tmp_path / f"b{suffix}"
    save_scene(scene, first)
    loaded = load_scene(first)
    assert loaded == scene
    save_scene(loaded, second)
    assert first.read_text() == second.read_text()


def test_valid_scene_has_no_problems():
    assert scene_problems(small_scene()) == []


@pytest.mark.parametrize(
    ("scene", "message"),
    [
        (with_obstacle(0, y=0.47), "obstacle 'box_a' is off the table (0.045 m past the left edge)"),
        (with_obstacle(1, x=0.79), "obstacle 'can_b' is off the table (0.030 m past the back edge)"),
        (with_obstacle(1, y=0.15), "obstacle 'box_a' and obstacle 'can_b' overlap"),
        (with_obstacle(0, size=(0.05, -0.15, 0.12)), "obstacle 'box_a': size must be positive"),
        (with_obstacle(0, size=(0.05, 0.0, 0.12)), "obstacle 'box_a': size must be positive"),
        (with_obstacle(0, x=math.nan), "obstacle 'box_a': x must be a finite number, got nan"),
        (with_obstacle(0, size=(0.05, math.inf, 0.12)), "obstacle 'box_a': size must be 3 finite numbers"),
        (with_obstacle(0, shape="pyramid"), "obstacle 'box_a': unknown shape 'pyramid'"),
        (with_obstacle(1, size=(0.08, 0.05, 0.15)), "a cylinder's first two sizes are its diameter"),
        (with_obstacle(1, name="box_a"), "two objects are named 'box_a'"),
        (small_scene(start=(-0.2, 0.0)), "start point (-0.200, 0.000) is off the table"),
        (small_scene(start=(0.4, 0.2)), "start point lies inside obstacle 'box_a'"),
        (small_scene(start=(math.nan, 0.0)), "start must be 2 finite numbers"),
        (small_scene(table=Table(0.8, 0.0, 0.75)), "table: width must be a positive number"),
        (
            small_scene(target=SceneObject("Target", "box", 0.7, 0.0, (0.06, 0.06, 0.12))),
            "must be a cylinder",
        ),
        (  # one line for one problem, not "unknown shape" too
            small_scene(target=SceneObject("Target", "sphere", 0.7, 0.0, (0.06, 0.06, 0.12))),
            "target 'Target' must be a cylinder, got 'sphere'",
        ),
        (small_scene(target=None), "scene has no target"),
    ],
)
def test_each_problem_is_named(scene, message):
    problems = scene_problems(scene)
    assert len(problems) == 1, problems
    assert message in problems[0]


def test_touching_objects_are_allowed_and_rotation_counts():
    touching = with_obstacle(1, shape="box", y=0.05, size=(0.05, 0.15, 0.12))  # edges meet at y = 0.125
    assert scene_problems(touching) == []
    rotated = with_obstacle(0, yaw=math.pi / 2)  # now 0.15 deep along x, 0.05 wide: still fits
    assert scene_problems(rotated) == []
    corner = with_obstacle(0, y=0.43, yaw=math.pi / 4)  # 45 deg: its corners reach further out
    assert "off the table" in scene_problems(corner)[0]


def test_all_problems_are_listed_together():
    scene = replace(with_obstacle(0, x=math.nan), start=(5.0, 0.0))
    with pytest.raises(SceneError) as info:
        from hlp_drake.scene import validate_scene

        validate_scene(scene)
    assert len(info.value.problems) == 2


def write_yaml(tmp_path, data) -> str:
    path = tmp_path / "scene.yaml"
    path.write_text(data if isinstance(data, str) else yaml.safe_dump(data))
    return str(path)


@pytest.mark.parametrize(
    ("mutate", "message"),
    [
        (lambda d: d.pop("target"), "scene: missing field 'target'"),
        (lambda d: d.update(colour="red"), "scene: unknown field 'colour'"),
        (lambda d: d["obstacles"][0].update(size=[1, 2]), "obstacles[0].size: expected a list of 3 numbers"),
        (lambda d: d["obstacles"][0].update(x="left"), "obstacles[0].x: expected a number, got 'left'"),
        (lambda d: d["table"].pop("height"), "table: missing field 'height'"),
        (lambda d: d.update(obstacles={"a": 1}), "obstacles: expected a list"),
        (lambda d: d["obstacles"][1].update(x=0.4, y=0.2), "overlap"),
        (lambda d: d["obstacles"][1].update(x=".nan"), "expected a number"),
    ],
)
def test_malformed_files_name_the_field(tmp_path, mutate, message):
    data = scene_to_dict(small_scene())
    mutate(data)
    with pytest.raises(SceneError) as info:
        load_scene(write_yaml(tmp_path, data))
    assert any(message in p for p in info.value.problems), info.value.problems
    assert all(p.startswith(str(tmp_path)) for p in info.value.problems)


def test_nan_in_yaml_is_rejected(tmp_path):
    text = yaml.safe_dump(scene_to_dict(small_scene())).replace("x: 0.4\n", "x: .nan\n", 1)
    with pytest.raises(SceneError, match=r"obstacles\[0\]\.x: expected a finite number, got nan"):
        load_scene(write_yaml(tmp_path, text))


def test_unreadable_files(tmp_path):
    with pytest.raises(SceneError, match="no such file"):
        load_scene(tmp_path / "missing.yaml")
    with pytest.raises(SceneError, match="not valid YAML at line 2"):
        load_scene(write_yaml(tmp_path, "table: {length: 1\nstart: [0, 0]\n"))
    with pytest.raises(SceneError, match="expected a mapping"):
        load_scene(write_yaml(tmp_path, "- just\n- a list\n"))
    for empty in ("", "# nothing yet\n"):
        path = write_yaml(tmp_path, empty)
        with pytest.raises(SceneError) as info:
            load_scene(path)
        assert info.value.problems == (
            f"{path}: the file is empty; a scene gives its table, start, target and obstacles",
        )
    (tmp_path / "s.json").write_text("{not json")
    with pytest.raises(SceneError, match="not valid JSON"):
        load_scene(tmp_path / "s.json")
    with pytest.raises(SceneError, match="unknown scene file type"):
        load_scene(tmp_path / "scene.txt")


def test_saving_an_invalid_scene_writes_nothing(tmp_path):
    path = tmp_path / "bad.yaml"
    with pytest.raises(SceneError):
        save_scene(with_obstacle(0, x=math.nan), path)
    assert list(tmp_path.iterdir()) == []
