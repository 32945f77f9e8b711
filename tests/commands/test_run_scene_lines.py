"""What ``python -m hlp_drake.run_scene`` prints: nothing before a bad input's one error line, what runs
once, counts in the singular for one, and how long MeshCat serves after the run (``--meshcat-wait``)."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import pytest
from conftest import run_module


@pytest.mark.parametrize(
    "args, problem",
    [
        (["--robot", "nosuch"], "robot 'nosuch': not a shipped robot"),
        (["--uncertainty", "-1"], "argument --uncertainty: must be between 0 and"),  # the flag, not the field
        (["--kind", "gen1", "--robot", "nosuch"], "robot 'nosuch'"),
        (["--meshcat-wait", "0"], "give --meshcat too"),
        (["--meshcat", "--meshcat-wait", "-1"], "argument --meshcat-wait: must be between 0"),
    ],
)
def test_bad_input_is_refused_before_any_line_is_printed(args, problem):
    result = run_module("hlp_drake.run_scene", *args)
    assert result.returncode == 2 and result.stdout == "", result.stdout
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and problem in lines[0], result.stderr


def test_meshcat_serves_until_ctrl_c_or_as_long_as_meshcat_wait_says():
    from hlp_drake.commands.run_scene import serve

    slept = []

    def sleep(seconds):
        slept.append(seconds)
        if len(slept) == 3:
            raise KeyboardInterrupt  # Ctrl-C ends the wait, quietly

    serve(0, 1.0, sleep=sleep)
    assert slept == []
    serve(2.5, 1.0, sleep=sleep)
    assert slept == [2.5]
    slept.clear()
    serve(None, 1.0, sleep=sleep)  # until Ctrl-C
    assert slept == [1.0, 1.0, 1.0]


def test_meshcat_wait_0_ends_the_run_at_once():
    args = ["--meshcat", "--meshcat-wait", "0", "--world", "model", "--workers", "1", "--quiet"]
    result = subprocess.run(
        [sys.executable, "-m", "hlp_drake.run_scene", *args],
        capture_output=True,
        text=True,
        env={**os.environ, "DRAKE_ALLOW_NETWORK": "meshcat"},
        timeout=300,  # serving until Ctrl-C would time out
        check=False,
    )
    if "MeshCat" in result.stderr and result.returncode == 2:
        pytest.skip(f"MeshCat did not start here: {result.stderr}")
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0].startswith("scene default") and lines[0].endswith(": 6 obstacles"), result.stdout
    assert sum(line.startswith(("run: ", "ran: ")) for line in lines) == 1  # what runs, said once
    assert not re.search(r"\b1 (rollouts|iterations|obstacles)\b", result.stdout), result.stdout
    assert lines[-1].endswith("MeshCat stops now (--meshcat-wait 0)"), result.stdout


def test_counts_are_said_in_the_singular_for_one():
    from types import SimpleNamespace

    from hlp_drake.commands.progress import ProgressListener
    from hlp_drake.runtime.terminal import counted

    assert [counted(n, "obstacle") for n in (0, 1, 6)] == ["0 obstacles", "1 obstacle", "6 obstacles"]
    lines = []
    listener = ProgressListener(quiet=True)
    listener._line = lines.append
    listener.optimising("sto")
    listener.optimised(
        SimpleNamespace(success=True, failure_reason=None, iterations=1, rollouts=1, optimise_s=0.5)
    )
    assert lines == ["optimise: success after 1 iteration, 1 rollout (0.5 s)"]
