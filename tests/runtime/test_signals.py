"""Ctrl-C to the whole process group (what a terminal sends) during ``run_scene`` with rollout workers.

Expected at any moment: exit status 130, stderr the one line "interrupted" (no worker's
KeyboardInterrupt traceback), no output file, and no process of the group left behind. A SIGTERM
to the command alone (``kill PID``, a scheduler's time limit): the same with 143 and "terminated".
"""

from __future__ import annotations

import os
import selectors
import signal
import subprocess
import sys
import time

import pytest

_STARTING = "rollout workers: 2"


def _interrupt(
    tmp_path,
    *,
    after: str | None,
    delay: float,
    signum: int = signal.SIGINT,
    group: bool = True,
    status: int = 130,
    message: str = "interrupted",
) -> None:
    out = tmp_path / "run.json"
    process = subprocess.Popen(
        # the straight line: several batches of rollouts on the workers (the HLP's one runs here)
        [sys.executable, "-m", "hlp_drake.run_scene", "--planner", "sto", "--workers", "2", "--quiet"]
        + ["--json", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        cwd=tmp_path,
    )
    seen = ""
    if after is not None:  # wait for the line, then for ``delay``
        selector = selectors.DefaultSelector()
        selector.register(process.stdout, selectors.EVENT_READ)
        deadline = time.monotonic() + 120
        while after not in seen and time.monotonic() < deadline and process.poll() is None:
            if selector.select(timeout=1.0):
                seen += process.stdout.readline()
        assert after in seen, seen
    time.sleep(delay)
    (os.killpg if group else os.kill)(process.pid, signum)
    stdout, stderr = process.communicate(timeout=120)
    assert process.returncode == status, (seen + stdout, stderr)
    assert stderr == f"{message}\n", stderr
    assert not out.exists() and not list(tmp_path.glob(".run.json.*"))
    deadline = time.monotonic() + 10  # the workers are gone too (reaped by init once the command exits)
    while _group_alive(process.pid) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not _group_alive(process.pid)


def _group_alive(group: int) -> bool:
    try:
        os.killpg(group, 0)
    except ProcessLookupError:
        return False
    return True


def test_ctrl_c_while_optimising_is_one_line_and_exit_130(tmp_path):
    _interrupt(tmp_path, after=_STARTING, delay=2.0)


def test_sigterm_to_the_command_alone_stops_its_workers_one_line_and_exit_143(tmp_path):
    _interrupt(
        tmp_path,
        after=_STARTING,
        delay=2.0,
        signum=signal.SIGTERM,
        group=False,
        status=143,
        message="terminated",
    )


@pytest.mark.slow
@pytest.mark.parametrize(
    ("after", "delay"),
    [
        (None, 0.3),
        (None, 1.5),
        (_STARTING, 0.0),
        (_STARTING, 0.5),
        (_STARTING, 1.5),
        (_STARTING, 3.0),
        (_STARTING, 4.5),
        (_STARTING, 6.0),
    ],
)
def test_ctrl_c_at_any_moment_is_one_line_and_exit_130(tmp_path, after, delay):
    _interrupt(tmp_path, after=after, delay=delay)
