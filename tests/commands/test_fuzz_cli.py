"""Fuzzing the command lines and the scenario loader.

Checked on every example: the exit status is 0 or 2 (a run that fails is 1, not reached here),
stderr is ``error:`` lines of at most 300 characters of message, a refused command leaves no file
(not even a temporary one), and no traceback ever reaches the user (run as real processes too).
"""

from __future__ import annotations

import contextlib
import io
import tempfile
from pathlib import Path

import pytest
import yaml
from conftest import run_module
from fuzz_support import PROFILES, STATS, check_error, mutate, run, scene_file, scene_texts
from hypothesis import strategies as st

from hlp_drake.commands.parsing import run_cli
from hlp_drake.commands.scene import main as scene_main
from hlp_drake.errors import MAX_LINE, HlpError

_INTEGERS = st.one_of(
    st.integers(-5, 200).map(str), st.sampled_from(["-1", "1" * 400, "2.5", "x", "", "4294967296"])
)
_OUTS = st.sampled_from(
    ["out/scene.yaml", "scene.json", "scene.txt", "afile/scene.yaml", "adir", "deep/er/s.yml"]
)


def _run_scene_cli(argv: list[str]) -> tuple[int, str]:
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = run_cli(scene_main, argv)
    return code, err.getvalue()


def _check_lines(code: int, stderr: str) -> None:
    assert code in (0, 2), (code, stderr)
    lines = stderr.splitlines()
    assert (code == 2) == bool(lines), stderr
    assert all(line.startswith("error: ") and len(line) <= MAX_LINE + 7 for line in lines), stderr
    assert "Traceback" not in stderr


@st.composite
def _generate_arguments(draw) -> list[str]:
    argv = ["generate", "--kind", draw(st.sampled_from(["vr", "gen1", "gen2", "unstructured", "gen3"]))]
    argv += ["--seed", draw(_INTEGERS)]
    if draw(st.booleans()):
        argv += ["--objects", draw(_INTEGERS)]
    return [*argv, "--out", draw(_OUTS)]


def _check_generate(argv: list[str]) -> None:
    STATS["command lines"] += 1
    with tempfile.TemporaryDirectory() as folder:
        root = Path(folder)
        (root / "afile").write_text("a file, not a folder")
        (root / "adir").mkdir()
        argv = [str(root / a) if a == argv[-1] else a for a in argv]
        before = sorted(root.rglob("*"))
        code, stderr = _run_scene_cli(argv)
        _check_lines(code, stderr)
        if code == 2:
            assert sorted(root.rglob("*")) == before  # nothing written, no temporary file left
            STATS["command lines refused"] += 1


@pytest.mark.parametrize("profile", PROFILES)
def test_scene_generate_arguments_succeed_or_are_one_line_errors(profile):
    run(profile, (30, 500), _generate_arguments(), _check_generate)


def _check_validate(case: tuple[str, str]) -> None:
    STATS["command lines"] += 1
    with scene_file(case) as path:
        _check_lines(*_run_scene_cli(["validate", str(path)]))


@pytest.mark.parametrize("profile", PROFILES)
def test_scene_validate_answers_every_file_in_one_line_per_problem(profile):
    run(profile, (40, 1000), scene_texts(), _check_validate)


_BASE_SCENARIO = None


def _scenario_document() -> dict:
    global _BASE_SCENARIO
    if _BASE_SCENARIO is None:
        from hlp_drake.systems.scenario import Scenario

        _BASE_SCENARIO = yaml.safe_load(Scenario().yaml)
    return yaml.safe_load(yaml.safe_dump(_BASE_SCENARIO))  # a copy


@st.composite
def _scenario_texts(draw) -> str:
    document = mutate(_scenario_document(), draw, most=4)
    text = yaml.safe_dump(document)
    return text[: draw(st.integers(0, len(text)))] if draw(st.integers(0, 9)) == 0 else text


def _check_scenario(text: str) -> None:
    """Refused in one line per problem, or loaded and then usable: its cameras build (Drake's
    checks of the intrinsics and depth range pass) and its model error can be drawn."""
    from hlp_drake.systems.perception.cameras import camera_pose, render_cameras
    from hlp_drake.systems.scenario import load_scenario
    from hlp_drake.systems.world.uncertainty import sample_perturbation

    STATS["scenario files"] += 1
    try:
        scenario = load_scenario(data=text, where="fuzz.yaml")
    except HlpError as error:
        check_error(error)
        STATS["scenario files refused"] += 1
        return
    for camera in scenario.perception.cameras:
        camera_pose(camera, scenario.scene)
        render_cameras(camera)
    sample_perturbation(scenario.uncertainty, scenario.scene)


@pytest.mark.parametrize("profile", PROFILES)
def test_scenarios_load_or_are_refused_one_line_per_problem(profile):
    run(profile, (25, 1000), _scenario_texts(), _check_scenario)


_PROCESS_CASES = [
    ("scene", "validate", "{deep}"),
    ("scene", "validate", "{laughs}"),
    ("run_scene", "--config", "{number}"),
    ("run_scene", "--config", "{samples}"),
    ("run_scene", "--seed", "-1"),
    ("run_scene", "--seed", "4"),  # without --kind: not silently the default scene
    ("run_scene", "--objects", "4"),
    ("scene", "generate", "--kind", "gen2", "--seed", "1", "--out", "{afile}/x.yaml"),
]


@pytest.mark.parametrize("case", _PROCESS_CASES, ids=lambda c: " ".join(c[:2]))
def test_hostile_input_never_shows_a_traceback_to_the_user(tmp_path, case):
    files = {
        "deep": "start: " + "[" * 100_000 + "]" * 100_000,
        "laughs": "a: &a [x, x, x, x, x, x, x, x, x]\nb: &b [*a, *a, *a, *a, *a, *a, *a, *a, *a]\nstart: [*b, *b]\n",
        "number": "plant: {time_step: " + "9" * 400 + "}\n",
        "samples": "planner: {low_level: {samples: " + "1" * 401 + "}}\n",
        "afile": "a file, not a folder",
    }
    paths = {}
    for name, text in files.items():
        paths[name] = tmp_path / (name if name == "afile" else f"{name}.yaml")
        paths[name].write_text(text)
    module, *arguments = case
    result = run_module(f"hlp_drake.{module}", *(a.format(**paths) for a in arguments))
    lines = result.stderr.strip().splitlines()
    assert result.returncode == 2 and "Traceback" not in result.stderr, result.stderr
    assert len(lines) == 1 and lines[0].startswith("error: ") and len(lines[0]) <= MAX_LINE + 7, result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(p.name for p in paths.values())
