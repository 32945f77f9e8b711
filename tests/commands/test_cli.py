"""The command lines share one style: plain help text, --version, --quiet, one-line usage errors."""

from __future__ import annotations

import importlib
import subprocess
import sys
from pathlib import Path

import pytest

from hlp_drake import __version__
from hlp_drake.__main__ import main
from hlp_drake.commands import COMMANDS, command_main
from hlp_drake.commands.parsing import run_cli

MODULES = sorted(f"hlp_drake.commands.{name}" for name in COMMANDS.values())


@pytest.mark.parametrize("module", MODULES)
def test_help_is_plain_text_and_every_command_has_a_version(module, capsys):
    entry = importlib.import_module(module).main
    with pytest.raises(SystemExit) as done:
        entry(["--help"])
    assert done.value.code == 0
    text = capsys.readouterr().out
    assert "``" not in text and "--version" in text
    with pytest.raises(SystemExit):
        entry(["--version"])
    assert __version__ in capsys.readouterr().out


SUBCOMMANDS = {"scene": ("generate", "show", "validate"), "dataset": ("summary",)}
WITH_CONFIG = ("run-scene", "experiments", "scene")
"""The commands that take a scenario (--config); the others read the VR dataset."""


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_every_command_takes_quiet_and_those_that_run_a_scenario_take_config(command, capsys):
    for sub in SUBCOMMANDS.get(command, ("",)):
        with pytest.raises(SystemExit):
            command_main(command)([sub, "--help"] if sub else ["--help"])
        text = capsys.readouterr().out
        assert "--quiet" in text, (command, sub)
        assert ("--config" in text) == (command in WITH_CONFIG), (command, sub)


def test_hlp_drake_dispatches_to_the_commands(capsys):
    assert main(["--version"]) == 0 and capsys.readouterr().out.strip() == f"hlp-drake {__version__}"
    assert main(["--help"]) == 0 and "run-scene" in capsys.readouterr().out
    # No command: a usage error as `scene` without its subcommand gives (stderr, exit status 2).
    assert main([]) == 2
    assert capsys.readouterr() == (
        "",
        "error: the following arguments are required: command (see hlp-drake --help)\n",
    )
    assert main(["fly"]) == 2 and "unknown command 'fly'" in capsys.readouterr().err
    assert main(["scene", "validate", "missing.yaml"]) == 2
    assert capsys.readouterr().err.strip() == "error: missing.yaml: no such file"
    assert main(["run-scene", "--planner", "astar"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: argument --planner: invalid choice") and "\n" not in err


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_help_and_version_name_the_command_as_typed_and_show_the_usage_once(command, capsys):
    python_m = f"python -m hlp_drake.{command.replace('-', '_')}"  # the module's own name
    for run, name in (
        (lambda argv: main([command, *argv]), f"hlp-drake {command}"),
        (command_main(command), python_m),
    ):
        with pytest.raises(SystemExit):
            run(["--help"])
        text = capsys.readouterr().out
        assert text.startswith(f"usage: {name} ") and text.count("usage:") == 1, text
        others = {f"hlp-drake {command}", python_m} - {name}
        assert not any(other in text for other in others), text  # named one way only
        # The docstring's own usage lines are left out of the epilog: argparse prints the usage.
        after = "\n\n".join(text.split("\n\n")[2:])  # after the usage and the description
        assert not any(line.strip().startswith(f"{name} ") for line in after.splitlines()), text
        with pytest.raises(SystemExit):
            run(["--version"])
        assert capsys.readouterr().out == f"{name} {__version__}\n"


def test_typed_names_through_the_console_script_and_python_m():
    script = Path(sys.executable).with_name("hlp-drake")
    runs = [([sys.executable, "-m", "hlp_drake", "run-scene"], "python -m hlp_drake run-scene")]
    if script.exists():
        runs.append(([str(script), "run-scene"], "hlp-drake run-scene"))
    for argv, name in runs:
        result = subprocess.run([*argv, "--version"], capture_output=True, text=True, timeout=60, check=False)
        assert result.returncode == 0 and result.stdout == f"{name} {__version__}\n"
        result = subprocess.run(
            [*argv, "--workers", "0"], capture_output=True, text=True, timeout=60, check=False
        )
        assert result.returncode == 2 and result.stderr.rstrip().endswith(f"(see {name} --help)")


def test_the_console_script_is_installed():
    script = Path(sys.executable).with_name("hlp-drake")
    if not script.exists():
        pytest.skip(f"{script} is not installed (pip install -e . installs it)")
    result = subprocess.run(
        [str(script), "--version"], capture_output=True, text=True, timeout=60, check=False
    )
    assert result.returncode == 0 and result.stdout.strip() == f"hlp-drake {__version__}"


def test_outputs_that_cannot_be_written_are_refused_before_any_work(tmp_path):
    from hlp_drake.errors import HlpError
    from hlp_drake.files.atomic import check_writable

    a_file = tmp_path / "a_file"
    a_file.write_text("x")
    with pytest.raises(HlpError, match="the folder .*new/er does not exist"):  # never made
        check_writable(None, tmp_path / "new" / "er" / "out.json")
    assert sorted(tmp_path.rglob("*")) == [a_file]
    with pytest.raises(HlpError) as info:
        check_writable(tmp_path, a_file / "out.json", tmp_path / "fine.json", a_file / "out.npz")
    assert info.value.problems == (
        f"{tmp_path}: cannot write: it is a directory",
        f"{a_file / 'out.json'}: cannot write: {a_file} is not a directory",
    )  # once for the folder that cannot take out.json and out.npz
    assert sorted(tmp_path.rglob("*")) == [a_file]  # the probe left nothing


@pytest.mark.parametrize(
    "command, args",
    [
        ("run-scene", ["--json", "{dir}", "--html", "{dir}/x.html"]),
        ("evaluate", ["--json", "{dir}/r.json", "--csv", "{dir}"]),
        ("train", ["--out", "{file}"]),
        ("segment", ["--out", "{dir}"]),
    ],
)
def test_each_command_refuses_an_unwritable_output_first(tmp_path, capsys, command, args):
    (a_file := tmp_path / "a_file").write_text("x")
    argv = [a.format(dir=tmp_path, file=a_file) for a in args]
    assert run_cli(command_main(command), argv) == 2
    out, err = capsys.readouterr()
    assert (
        out == "" and err.startswith("error: ") and "cannot write" in err
    )  # before the dataset or the scene
    assert sorted(tmp_path.rglob("*")) == [a_file]
