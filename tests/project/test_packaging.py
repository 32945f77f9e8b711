"""Project wiring: the Drake model package, the systems package, and README/CI agreement."""

from __future__ import annotations

import re
from pathlib import Path

from conftest import REPO


def test_model_package_resolves_through_drake():
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    from hlp_drake.systems import MODELS_PACKAGE, configure_parser, models_directory

    plant = MultibodyPlant(time_step=0.0)
    parser = configure_parser(Parser(plant))
    assert Path(parser.package_map().GetPath(MODELS_PACKAGE)) == models_directory()
    configure_parser(parser)  # idempotent
    assert (models_directory() / "package.xml").is_file()


def test_nothing_can_use_the_remote_drake_models_package():
    import pytest
    from pydrake.multibody.parsing import Parser
    from pydrake.multibody.plant import MultibodyPlant

    sdf = """<?xml version="1.0"?><sdf version="1.7"><model name="m"><include>
        <uri>package://drake_models/ycb/003_cracker_box.sdf</uri></include></model></sdf>"""
    plant = MultibodyPlant(time_step=0.0)
    with pytest.raises(RuntimeError, match=r"Unable to find uri\[package://drake_models/"):
        Parser(plant).AddModelsFromString(sdf, "sdf")


def readme_block(heading: str) -> str:
    text = (REPO / "README.md").read_text()
    section = text.split(heading, 1)[1]
    return re.search(r"```(?:bash|sh)?\n(.+?)\n```", section, re.DOTALL).group(1).strip()


def test_ci_runs_the_readme_test_command():
    command = readme_block("## Run the tests")
    assert "pytest" in command and "\n" not in command
    assert command in (REPO / ".ci" / "run").read_text()


def test_readme_main_command_is_one_line():
    command = readme_block("## Quick start")
    assert "\n" not in command and "pip install" in command and "python -m hlp_drake." in command
