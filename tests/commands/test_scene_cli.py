"""``python -m hlp_drake.scene`` end to end: generate, validate, show, and user errors."""

from __future__ import annotations

import pytest
from conftest import run_module

from hlp_drake.scene import generate_scene, load_scene

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def assert_one_line_error(result, text: str) -> None:
    assert result.returncode == 2, result.stdout
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and text in lines[0], result.stderr
    assert "Traceback" not in result.stderr


@pytest.mark.parametrize(
    ("kind", "objects"), [("vr", None), ("gen1", None), ("gen2", 9), ("unstructured", 6)]
)
def test_generate_validate_show(tmp_path, kind, objects):
    out = tmp_path / f"{kind}.yaml"
    args = ["generate", "--kind", kind, "--seed", "4", "--out", str(out)]
    if objects:
        args += ["--objects", str(objects)]
    result = run_module("hlp_drake.scene", *args)
    assert result.returncode == 0, result.stderr
    assert load_scene(out) == generate_scene(kind, 4, objects)
    result = run_module("hlp_drake.scene", "validate", str(out))
    assert result.returncode == 0 and "valid" in result.stdout
    png = tmp_path / f"{kind}.png"
    result = run_module("hlp_drake.scene", "show", str(out), "--png", str(png))
    assert result.returncode == 0, result.stderr
    data = png.read_bytes()
    assert data.startswith(PNG_SIGNATURE) and len(data) > 10_000


def test_invalid_scene_is_one_line_per_problem(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text(
        "table: {length: 0.6, width: 0.74, height: 0.73}\n"
        "start: [0.1, 0.0]\n"
        "target: {name: Target, shape: cylinder, x: 0.525, y: 0.0, size: [0.05, 0.05, 0.08]}\n"
        "obstacles:\n"
        "- {name: a, shape: box, x: 0.3, y: 0.5, size: [0.05, 0.1, 0.1]}\n"
    )
    result = run_module("hlp_drake.scene", "validate", str(path))
    assert_one_line_error(result, "obstacle 'a' is off the table")
    png = tmp_path / "bad.png"
    result = run_module("hlp_drake.scene", "show", str(path), "--png", str(png))
    assert_one_line_error(result, "off the table")
    assert not png.exists()


def test_malformed_and_missing_files(tmp_path):
    path = tmp_path / "broken.yaml"
    path.write_text("table: [unclosed\n")
    assert_one_line_error(run_module("hlp_drake.scene", "validate", str(path)), "not valid YAML")
    assert_one_line_error(run_module("hlp_drake.scene", "validate", str(tmp_path / "x.yaml")), "no such file")


def test_failed_generation_writes_no_file(tmp_path):
    out = tmp_path / "crowded.yaml"
    result = run_module(
        "hlp_drake.scene", "generate", "--kind", "gen2", "--objects", "100", "--seed", "1", "--out", str(out)
    )
    assert_one_line_error(result, "could not place")
    assert list(tmp_path.iterdir()) == []


def test_show_draws_the_named_robots_plan_and_refuses_an_unknown_robot(tmp_path):
    """The iiwa's wider palm and longer wrist push elsewhere than the mobile UR5's (gen1 seed 6 on
    the Panda's tables): the drawn robot plans differ."""
    scene = tmp_path / "scene.yaml"
    args = ["generate", "--kind", "gen1", "--seed", "6", "--robot", "panda", "--out", str(scene)]
    assert run_module("hlp_drake.scene", *args).returncode == 0
    drawn = {}
    for robot in ("mobile_ur5", "iiwa14"):
        png = tmp_path / f"{robot}.png"
        result = run_module(
            "hlp_drake.scene", "show", str(scene), "--png", str(png), "--plan", "--robot", robot
        )
        assert result.returncode == 0, result.stderr
        assert "robot plan: start -> move -> release -> move -> release -> target" in result.stdout
        drawn[robot] = png.read_bytes()
    assert drawn["mobile_ur5"] != drawn["iiwa14"]
    png = tmp_path / "r2d2.png"
    result = run_module("hlp_drake.scene", "show", str(scene), "--png", str(png), "--robot", "r2d2")
    assert_one_line_error(result, "robot 'r2d2': not a shipped robot")
    assert not png.exists()


def test_every_subcommand_takes_config_and_quiet(tmp_path):
    """--config's robot (here the Panda) is what --robot would give: generate fits its reach."""
    from textwrap import indent

    from hlp_drake.systems.world.robot_description import load_robot, robot_file

    config = tmp_path / "panda.yaml"
    config.write_text("robot:\n" + indent(robot_file("panda").read_text(), "  "))
    out, png = tmp_path / "scene.yaml", tmp_path / "scene.png"
    args = ["generate", "--kind", "gen1", "--seed", "5", "--out", str(out)]
    result = run_module("hlp_drake.scene", *args, "--config", str(config), "--quiet")
    assert result.returncode == 0 and result.stderr == "", result.stderr
    assert load_scene(out) == generate_scene("gen1", 5, workspace=load_robot("panda").workspace)
    assert load_scene(out) != generate_scene("gen1", 5)  # the mobile UR5's table
    for args in (["validate", str(out)], ["show", str(out), "--png", str(png), "--plan"]):
        result = run_module("hlp_drake.scene", *args, "--config", str(config), "--quiet")
        assert result.returncode == 0 and result.stderr == "", result.stderr
    assert png.read_bytes().startswith(PNG_SIGNATURE)
    result = run_module(
        "hlp_drake.scene", "validate", str(out), "--config", str(out)
    )  # a scene, not a scenario
    assert_one_line_error(result, "this is a scene")
