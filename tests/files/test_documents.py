"""Scene files read within limits (``hlp_drake.files.documents``): the issue's hostile classes, each
refused at its place in one line, and what YAML 1.1 would misread read as a user means it."""

from __future__ import annotations

import pytest

from hlp_drake.errors import MAX_PROBLEMS, SceneError
from hlp_drake.scene.io import load_scene

_BASE = (
    "name: s\n"
    "table: {length: 0.6, width: 0.74, height: 0.73}\n"
    "start: [0.1, 0.0]\n"
    "target: {name: T, shape: cylinder, x: 0.525, y: 0.0, size: [0.05, 0.05, 0.085]}\n"
)


def _problems(tmp_path, text: str, suffix: str = ".yaml") -> tuple[str, ...]:
    path = tmp_path / f"scene{suffix}"
    path.write_text(text)
    with pytest.raises(SceneError) as error:
        load_scene(path)
    assert all(line.startswith(f"{path}: ") for line in error.value.problems)
    return tuple(line.removeprefix(f"{path}: ") for line in error.value.problems)


@pytest.mark.parametrize(
    ("text", "suffix", "problem"),
    [
        (_BASE + "start: [0.2, 0.0]\n", ".yaml", "duplicate key 'start' at line 5, column 1"),
        ('{"name": "a", "name": "b"}', ".json", "duplicate key 'name'"),
        (_BASE + "x: &s [1, 2]\ny: *s\n", ".yaml", "aliases are not allowed (*s at line 6, column 4)"),
        (_BASE + "obstacles: !!python/object/apply:os.system [ls]\n", ".yaml", "is not allowed at line 5"),
        ("start: " + "[" * 40 + "]" * 40 + "\n", ".yaml", "nested deeper than 32 levels"),
        ("[" * 100_000 + "]" * 100_000, ".json", "nested deeper than 32 levels"),
        (_BASE + "---\nname: t\n", ".yaml", "more than one document at line 5"),
    ],
)
def test_structure_the_loader_refuses_is_one_line_at_its_place(tmp_path, text, suffix, problem):
    (line,) = _problems(tmp_path, text, suffix)
    assert problem in line


@pytest.mark.parametrize(
    ("replace", "problem"),
    [
        ("length: " + "9" * 400, "table.length: expected a finite number"),
        ("length: 1e160", "table: length must be between 0.2 and 5.0 m, got 1e+160"),
        ("length: .nan", "table.length: expected a finite number, got nan"),
        ("length: 0.1", "table: length must be between 0.2 and 5.0 m, got 0.1"),
    ],
)
def test_numbers_out_of_range_name_the_field(tmp_path, replace, problem):
    (line,) = _problems(tmp_path, _BASE.replace("length: 0.6", replace))
    assert line.startswith(problem)


def test_exponent_numbers_are_numbers_and_quoted_ones_text(tmp_path):
    path = tmp_path / "scene.yaml"
    path.write_text(_BASE.replace("length: 0.6", "length: 6e-1"))
    assert load_scene(path).table.length == 0.6  # YAML 1.1 reads 6e-1 as text; YAML 1.2 and Drake do not
    (line,) = _problems(tmp_path, _BASE.replace("length: 0.6", "length: '6e-1'"))
    assert line == "table.length: expected a number, got '6e-1'"


def test_a_pile_of_identical_obstacles_lists_the_first_pairs_and_says_more_overlap(tmp_path):
    pile = "".join(
        f"- {{name: o{i}, shape: box, x: 0.3, y: 0.2, yaw: 0.0, size: [0.05, 0.05, 0.1]}}\n"
        for i in range(1000)
    )
    problems = _problems(tmp_path, _BASE + "obstacles:\n" + pile)
    assert len(problems) == MAX_PROBLEMS
    assert problems[0] == "obstacle 'o0' and obstacle 'o1' overlap (25.00 cm^2)"
    assert problems[-1] == f"more objects overlap (the first {MAX_PROBLEMS - 1} pairs are listed)"
