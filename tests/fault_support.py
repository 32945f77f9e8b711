"""Faults the tests inject into worker processes: module-level functions, so spawned workers (and
dask's) can unpickle them. A fault that should happen once claims a marker file in the folder
``FAULTS`` names (set before the workers start: they inherit the environment): ``fault_markers``
(a test module's fixture). ``warnings``: the warning lines of a command's stderr."""

from __future__ import annotations

import os
import signal
from pathlib import Path

from job_support import cheap_job

FAULTS = "HLP_TEST_FAULTS"
"""The environment variable naming the folder of the once-only faults' marker files."""


def fault_markers(tmp_path, monkeypatch):
    """The folder of the once-only faults' markers, named to the workers started from here on (the
    ``faults`` fixture of the modules that inject them: ``pytest.fixture(fault_markers, name="faults")``)."""
    folder = tmp_path / "faults"
    folder.mkdir()
    monkeypatch.setenv(FAULTS, str(folder))
    return folder


def warnings(text: str) -> list[str]:
    return [line for line in text.splitlines() if line.startswith("warning:")]


def first_time(name: str) -> bool:
    """True for the first caller (in any process) to claim the marker ``name``, False after."""
    try:
        os.close(os.open(Path(os.environ[FAULTS]) / name, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
    except FileExistsError:
        return False
    return True


def die() -> None:
    """Kill this process as the out-of-memory killer would (SIGKILL: no cleanup, no exception)."""
    os.kill(os.getpid(), signal.SIGKILL)


def rollout_killing_its_worker_once(*args):
    """The rollout task, whose first call (in any worker) kills its worker process."""
    from hlp_drake.systems.low_level.sto import pool

    if first_time("rollout"):
        die()
    return pool._rollout_task(*args)


def rollout_exiting(*args):
    """A rollout task that always ends its worker process (exit status 3)."""
    os._exit(3)


VICTIM = ("gen1-11", "sto")
"""The experiment job whose worker the job faults kill."""


def job_killing_its_worker_once(job):
    """``cheap_job``, whose ``VICTIM``'s first run kills its worker process."""
    if (job.scene, job.planner) == VICTIM and first_time("job"):
        die()
    return cheap_job(job)


def job_killing_its_worker(job):
    """``cheap_job``, whose ``VICTIM`` kills its worker process every time."""
    if (job.scene, job.planner) == VICTIM:
        die()
    return cheap_job(job)
