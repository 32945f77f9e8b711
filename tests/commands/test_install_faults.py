"""A damaged installation and a refusing environment through ``run_scene``, as a user meets them:
one ``error:`` line with a hint, exit 2 (not 1, a failed plan), no traceback, no output file."""

from __future__ import annotations

import shutil
import subprocess
import sys

import pytest
from conftest import run_module

from hlp_drake.errors import MAX_LINE
from hlp_drake.systems.world.robot_description import models_directory

# run_scene with its model package read from the folder argv[1] (a damaged copy of the installed one).
_WITH_PACKAGE = (
    "import sys, pathlib, hlp_drake.systems.world.robot as package; "
    "package.models_directory = lambda: pathlib.Path(sys.argv[1]); "
    "from hlp_drake.commands.parsing import run_cli; from hlp_drake.commands.run_scene import main; "
    "raise SystemExit(run_cli(main, sys.argv[2:]))"
)


def _one_error_line(result: subprocess.CompletedProcess) -> str:
    assert result.returncode == 2 and "Traceback" not in result.stderr, result.stderr
    (line,) = result.stderr.strip().splitlines()
    assert line.startswith("error: ") and len(line) <= MAX_LINE + len("error: ")
    return line


def _damage(package, how: str) -> None:
    if how == "truncated robot model":
        urdf = package / "robot" / "mobile_ur5.urdf"
        urdf.write_text(urdf.read_text()[:5000])
    else:
        (package / "package.xml").unlink()


@pytest.mark.parametrize(
    ("how", "names"),
    [
        ("truncated robot model", "the robot model cannot be parsed"),
        ("missing package.xml", "package.xml: the model package is missing or damaged"),
    ],
)
def test_a_damaged_model_package_is_one_line_with_a_hint_and_exit_2(tmp_path, how, names):
    package = tmp_path / "package"
    shutil.copytree(models_directory(), package)
    _damage(package, how)
    out = tmp_path / "run.json"
    result = subprocess.run(
        [sys.executable, "-c", _WITH_PACKAGE, str(package), "--workers", "1", "--quiet", "--json", str(out)],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    line = _one_error_line(result)
    assert names in line and "reinstall hlp_drake" in line
    assert not out.exists()


def test_meshcat_refused_by_the_network_policy_names_the_policy_and_the_value_that_allows_it(tmp_path):
    html = tmp_path / "run.html"
    result = run_module(
        "hlp_drake.run_scene", "--html", str(html), "--quiet", env={"DRAKE_ALLOW_NETWORK": "none"}
    )
    line = _one_error_line(result)
    assert "DRAKE_ALLOW_NETWORK=none refuses" in line and "DRAKE_ALLOW_NETWORK=meshcat" in line
    assert not html.exists()
