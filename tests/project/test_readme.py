"""Every code block of the README runs, verbatim: python and bash blocks, scenario and scene YAML.

Blocks in ``text`` are program output and pictures, not code. The test command (pytest) is the one
``.ci/run`` runs (``test_packaging``); install commands (venv, pip) are what CI itself does, so of a
quick-start line only the part after them runs, with this interpreter as ``.venv/bin/python``.
"""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import REPO

BLOCK = re.compile(r"^```(\w*)\n(.*?)^```", re.DOTALL | re.MULTILINE)


def readme_blocks() -> list[tuple[str, str]]:
    return [(language, code) for language, code in BLOCK.findall((REPO / "README.md").read_text())]


def blocks(language: str) -> list[str]:
    return [code for kind, code in readme_blocks() if kind == language]


def test_the_readme_has_only_runnable_blocks_and_output():
    kinds = {kind for kind, _ in readme_blocks()}
    assert kinds <= {"python", "bash", "yaml", "text"}, kinds
    assert blocks("python") and blocks("bash") and blocks("yaml")


def commands(block: str) -> list[str]:
    """The block's commands, one a line (comments dropped), install steps left out."""
    found = []
    for line in block.splitlines():
        line = line.split("  #")[0].strip()
        if not line or line.startswith("#"):
            continue
        steps = [s for s in line.split(" && ") if not (s.startswith("python3 -m venv") or "pip install" in s)]
        found += steps
    return found


def run(command: str, cwd: Path) -> subprocess.CompletedProcess:
    argv = shlex.split(command)
    if argv[0] in ("python", ".venv/bin/python"):
        argv[0] = sys.executable
    if len(argv) > 1 and argv[1].startswith("examples/"):  # the repository's example scripts
        argv[1] = str(REPO / argv[1])
    return subprocess.run(argv, cwd=cwd, capture_output=True, text=True, timeout=600, check=False)


def test_every_bash_block_runs(tmp_path):
    lines = [c for block in blocks("bash") for c in commands(block)]
    assert any("hlp_drake.run_scene" in c for c in lines) and any("hlp_drake.scene show" in c for c in lines)
    for command in lines:
        if "pytest" in command:
            assert command in (REPO / ".ci" / "run").read_text()  # the test command: what CI runs
            continue
        result = run(command, tmp_path)
        assert result.returncode == 0, (command, result.stdout, result.stderr)
        if "scene show" in command:
            assert "robot plan: start ->" in result.stdout and "human plan: start ->" in result.stdout
        if "own_planner" in command:  # your own low-level planner, registered by the example
            assert (
                "low-level planner smooth" in result.stdout and "verdict: reach success" in result.stdout
            ), result.stdout
        elif "--robot" in command:  # your own robot, written by the example beside it
            assert "run: robot arm6" in result.stdout and "verdict: reach success" in result.stdout, (
                result.stdout
            )
        elif "hlp_drake.run_scene" in command:  # the quick start: the default scene, planned and grasped
            for line in ("plan: start ->", "optimise: success", "verdict: reach success", "grasp held"):
                assert line in result.stdout, (line, result.stdout)
    assert (tmp_path / "scene.png").stat().st_size > 10_000


def test_the_python_block_is_the_example_file_and_runs(tmp_path):
    (code,) = blocks("python")
    assert code == (REPO / "examples" / "compose_diagram.py").read_text()
    result = subprocess.run(
        [sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=600, check=False
    )
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0].startswith("robot plan: start -> ") and lines[0].endswith(" -> target")
    assert lines[1] == "optimised: success True after 1 rollout(s)"
    assert re.fullmatch(r"after moving FailOnTouchObstacleShort: \d+ keypoints", lines[2])


def test_the_yaml_blocks_load_as_a_scenario_a_scene_and_a_study(tmp_path):
    from hlp_drake.experiments.study import load_study
    from hlp_drake.scene.io import load_scene
    from hlp_drake.systems.scenario import Scenario, load_scenario

    def kind(text: str) -> str:
        if "table:" in text:
            return "scene"
        return "study" if "generators:" in text else "scenario"

    found = {kind(text): text for text in blocks("yaml")}
    assert sorted(found) == ["scenario", "scene", "study"] and len(blocks("yaml")) == 3
    scenario = load_scenario(data=found["scenario"])
    assert scenario.planner.initial == "hlp" and scenario.low_level.samples == 8
    assert scenario.key == Scenario().key  # the README shows the defaults
    path = tmp_path / "example.yaml"
    path.write_text(found["scene"])
    scene = load_scene(path)
    assert scene.name == "example" and [o.name for o in scene.obstacles] == ["box1"]
    (tmp_path / "study.yaml").write_text(found["study"])
    study = load_study(str(tmp_path / "study.yaml"))
    assert study.robots == ("mobile_ur5", "panda", "iiwa14") and len(study.cells()) == 6
    assert study.scenes == 100 and study.seed == 0  # as its comment says


@pytest.mark.parametrize(
    "link", sorted(set(re.findall(r"\]\(((?:docs|examples)/[^)#]+)", (REPO / "README.md").read_text())))
)
def test_the_readmes_links_into_the_repository_exist(link):
    assert (REPO / link).exists(), link


def _docs_links() -> list[tuple[str, str]]:
    """(document, relative link target) of every link from docs/*.md into the repository."""
    found = set()
    for doc in sorted((REPO / "docs").glob("*.md")):
        for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", doc.read_text()):
            if not re.match(r"[a-z]+:", target):
                found.add((doc.name, target))
    return sorted(found)


@pytest.mark.parametrize(("doc", "link"), _docs_links())
def test_the_docs_links_into_the_repository_exist(doc, link):
    # the results and limits moved from the README to docs/: their links are checked here
    assert (REPO / "docs" / link).resolve().exists(), (doc, link)


def test_the_readme_lists_every_scenario_section():
    import dataclasses

    from hlp_drake.systems.scenario import Scenario

    text = " ".join((REPO / "README.md").read_text().split())
    start = text.index("Sections, each documented on its dataclass")
    listed = re.findall(r"`(\w+)`", text[start : text.index(". A scene, in metres", start)])
    assert listed == [field.name for field in dataclasses.fields(Scenario)]


def test_the_own_robot_examples_commands_are_the_readmes_and_what_they_write_is_ignored():
    """The example's docstring gives the README's commands (the README's run is the one run above);
    the folder they write is not for git."""
    usage = [
        line.strip()
        for line in (REPO / "examples" / "own_robot.py").read_text().split('"""')[1].splitlines()
        if line.strip().startswith("python ")
    ]
    readme = [c for block in blocks("bash") for c in commands(block)]
    assert len(usage) == 2 and all(line in readme for line in usage), (usage, readme)
    assert "--out my_robot" in usage[0] and "/my_robot/" in (REPO / ".gitignore").read_text().splitlines()


def test_the_readme_says_how_to_run_the_notebook_headless():
    """The command the README gives exists where the test extras are installed (nbclient's)."""
    command = "jupyter execute examples/tutorial.ipynb"
    assert command in (REPO / "README.md").read_text()
    jupyter = Path(sys.executable).with_name("jupyter")
    if not jupyter.exists():
        pytest.skip(f"{jupyter} is not installed (pip install -e '.[test]' installs it)")
    result = subprocess.run(
        [str(jupyter), "execute", "--help"], capture_output=True, text=True, timeout=120, check=False
    )
    assert result.returncode == 0 and "notebook" in result.stdout, result.stderr
