"""What the commands do with their output paths: a device, a named pipe, a missing folder (one line,
exit 2, before any work, left untouched), a symbolic link (written through, kept), ``-`` (standard
output for a file, refused for a folder)."""

from __future__ import annotations

import json
import os
import stat

import pytest
from conftest import run_module
from job_support import OUTPUTS, cheap_job, never_called

from hlp_drake.commands import command_main
from hlp_drake.commands.experiments import main as experiments_main
from hlp_drake.commands.parsing import run_cli

OUTPUT_FLAGS = {
    "run-scene --json": (command_main("run-scene"), ["--quiet", "--json"]),
    "run-scene --html": (command_main("run-scene"), ["--quiet", "--html"]),
    "experiments --out": (
        lambda argv: experiments_main(argv, job=never_called),
        ["gen1", "--quiet", "--out"],
    ),
}


@pytest.mark.parametrize("flag", OUTPUT_FLAGS)
@pytest.mark.parametrize("kind", ["device", "fifo", "missing folder"])
def test_a_bad_output_path_is_one_line_and_exit_2_before_any_work(tmp_path, capsys, char_device, flag, kind):
    main, args = OUTPUT_FLAGS[flag]
    os.mkfifo(fifo := tmp_path / "fifo")  # never opened: the test would block if it were
    path, message = {
        "device": (str(char_device), f"{char_device}: cannot write: it is a character device"),
        "fifo": (str(fifo), f"{fifo}: cannot write: it is a named pipe"),
        "missing folder": (
            str(tmp_path / "nonexistent" / "dir" / "r"),
            f"{tmp_path / 'nonexistent' / 'dir' / 'r'}: the folder {tmp_path / 'nonexistent' / 'dir'} does not exist",
        ),
    }[kind]
    assert run_cli(main, [*args, path]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and err.startswith(f"error: {message}")  # before the scene
    assert stat.S_ISCHR(os.stat(char_device).st_mode) and stat.S_ISFIFO(os.lstat(fifo).st_mode)
    assert set(tmp_path.iterdir()) <= {fifo, char_device}


def test_standard_output_takes_one_output(capsys):
    assert run_cli(command_main("run-scene"), ["--json", "-", "--html", "-"]) == 2
    assert capsys.readouterr() == ("", "error: -: only one output can be standard output\n")


def test_experiments_refuse_dash_and_write_through_a_link_to_a_folder(tmp_path, capsys):
    assert run_cli(OUTPUT_FLAGS["experiments --out"][0], ["gen1", "--out", "-"]) == 2
    assert capsys.readouterr().err == "error: -: an output folder cannot be standard output; name a folder\n"
    (folder := tmp_path / "runs").mkdir()
    (link := tmp_path / "link").symlink_to(folder)
    argv = ["gen1", "--scenes", "1", "--workers", "1", "--quiet", "--out", str(link)]
    assert run_cli(lambda a: experiments_main(a, job=cheap_job), argv) == 0
    assert link.is_symlink() and sorted(p.name for p in folder.iterdir()) == sorted(OUTPUTS)


def test_run_scene_writes_json_to_dash_and_html_through_a_link(tmp_path):
    (link := tmp_path / "link.html").symlink_to(page := tmp_path / "page.html")
    args = ("--workers", "1", "--quiet", "--json", "-", "--html", str(link))
    result = run_module("hlp_drake.run_scene", *args, env={"DRAKE_ALLOW_NETWORK": "meshcat"})
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["planner"] == "hlp"  # standard output holds the JSON alone
    assert "verdict: reach success" in result.stderr and f"wrote {link}" in result.stderr
    assert link.is_symlink() and "<html" in page.read_text().lower()


def test_run_scene_writes_html_to_dash_and_json_through_a_link(tmp_path):
    (link := tmp_path / "link.json").symlink_to(report := tmp_path / "report.json")
    args = ("--workers", "1", "--quiet", "--html", "-", "--json", str(link))
    result = run_module("hlp_drake.run_scene", *args, env={"DRAKE_ALLOW_NETWORK": "meshcat"})
    assert result.returncode == 0, result.stderr
    page = result.stdout.strip().lower()
    assert page.startswith("<!doctype html>") and page.endswith("</html>")  # the page alone
    assert link.is_symlink() and json.loads(report.read_text())["planner"] == "hlp"
