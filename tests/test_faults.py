"""Faults of the machine, injected: a worker process killed, a full disk, damaged model and dataset
files. Each run survives with the same result, or ends with one line and no traceback."""

from __future__ import annotations

import errno
import json
import os
import pathlib
import re
import signal
import stat
import tempfile

import numpy as np
import pytest
from fault_support import (
    FAULTS,
    VICTIM,
    job_killing_its_worker,
    job_killing_its_worker_once,
    rollout_exiting,
    rollout_killing_its_worker_once,
    steady_job,
)
from sto_support import on, short

from hlp_drake import atomic, experiments
from hlp_drake.cli import run_cli
from hlp_drake.experiments import ExperimentSettings
from hlp_drake.experiments.cli import main as experiments_main
from hlp_drake.experiments.executors import RETRIES
from hlp_drake.systems import scenario_yamls
from hlp_drake.systems.optimiser import pool as pool_module
from hlp_drake.systems.optimiser.control_sequence import ControlSequence
from hlp_drake.systems.optimiser.optimiser import optimise, sample_base_noise
from hlp_drake.systems.optimiser.pool import MAX_DEATHS, RolloutPool

WARNING = re.compile(
    r"warning: a rollout worker died \((signal \d+|exit status \d+)\); restarted the workers"
)


@pytest.fixture
def faults(tmp_path, monkeypatch):
    """The folder of the once-only faults' markers, named to the workers started from here on."""
    folder = tmp_path / "faults"
    folder.mkdir()
    monkeypatch.setenv(FAULTS, str(folder))
    return folder


def comparable(outcome) -> tuple:
    """A rollout's outcome without its wall-clock time."""
    return (
        outcome.cost,
        outcome.terms,
        outcome.success,
        outcome.failure_reason,
        outcome.target_distance,
        outcome.fallen,
        outcome.simulated_s,
        outcome.asleep,
        outcome.switches,
    )


def warnings(text: str) -> list[str]:
    return [line for line in text.splitlines() if line.startswith("warning:")]


# --- The rollout pool ------------------------------------------------------------------------------


def test_a_killed_rollout_worker_is_replaced_and_its_rollouts_run_again(scene, trajectories, capsys):
    base = short(ControlSequence.from_trajectory(trajectories["sto"], 0.5), 1.0)
    config = on(scene)
    noise = sample_base_noise(np.random.default_rng(0), base, config.optimiser.noise, 3)
    sequences = [base.with_base_velocity(v) for v in noise]
    with RolloutPool(2) as pool:
        undisturbed = pool.rollouts(config, sequences)
        assert warnings(capsys.readouterr().err) == []
        victim = next(iter(pool._executor._processes.values()))
        os.kill(victim.pid, signal.SIGKILL)  # as the out-of-memory killer would
        disturbed = pool.rollouts(config, sequences)
        again = pool.rollouts(config, sequences)  # the replaced workers go on serving
    assert [comparable(o) for o in disturbed] == [comparable(o) for o in undisturbed]
    assert [comparable(o) for o in again] == [comparable(o) for o in undisturbed]
    (line,) = warnings(capsys.readouterr().err)
    assert WARNING.match(line) and "(signal 9)" in line, line


def test_workers_dying_again_and_again_end_the_optimisation_as_a_failure(
    scene, trajectories, capsys, monkeypatch
):
    monkeypatch.setattr(pool_module, "_rollout_task", rollout_exiting)
    config = on(scene, "optimiser: {samples: 2, max_iterations: 3}")
    initial = short(ControlSequence.from_trajectory(trajectories["sto"], 0.5), 1.0)  # fails: too short
    with RolloutPool(2) as pool:
        result = optimise(config, initial, pool)  # the initial rollout here, the iterations' on the workers
        with pytest.raises(pool_module.WorkersLost):  # the pool stays given up
            pool.rollouts(config, [initial, initial])
    assert not result.success and result.iterations == 0 and result.rollouts == 1
    assert result.failure_reason == f"the rollout workers died {MAX_DEATHS} times in a row (exit status 3)"
    lines = warnings(capsys.readouterr().err)
    assert len(lines) == MAX_DEATHS - 1 and all(WARNING.match(line) for line in lines), lines
    assert all("(exit status 3)" in line for line in lines)


def run_scene_json(tmp_path, name: str, capsys) -> tuple[int, dict, str]:
    """``run_scene --planner sto`` on 2 workers, in this process: its exit status, JSON and stderr."""
    from hlp_drake.run_scene import main

    out = tmp_path / f"{name}.json"
    status = run_cli(main, ["--planner", "sto", "--workers", "2", "--quiet", "--json", str(out)])
    return status, json.loads(out.read_text()), capsys.readouterr().err


def without_times(report: dict) -> dict:
    """A run's JSON without its wall-clock times."""
    report = {**report, "timings": None}
    report["optimisation"] = {k: v for k, v in report["optimisation"].items() if not k.endswith("_s")}
    return report


def test_run_scene_with_a_rollout_worker_killed_mid_optimisation_gives_the_same_result(
    tmp_path, capsys, monkeypatch, faults
):
    status, undisturbed, err = run_scene_json(tmp_path, "undisturbed", capsys)
    assert status == 0 and undisturbed["iterations"] >= 1 and warnings(err) == []
    monkeypatch.setattr(pool_module, "_rollout_task", rollout_killing_its_worker_once)
    status, disturbed, err = run_scene_json(tmp_path, "disturbed", capsys)
    assert (faults / "rollout").exists()  # a worker did die
    assert status == 0 and "Traceback" not in err
    (line,) = warnings(err)
    assert WARNING.match(line) and "(signal 9)" in line, line
    assert without_times(disturbed) == without_times(undisturbed)


# --- Experiments -----------------------------------------------------------------------------------

GEN1 = ["gen1", "--scenes", "3", "--seed", "10", "--quiet"]  # scenes gen1-10 to gen1-12, both planners


def run_experiments(argv: list[str], job) -> int:
    """``python -m hlp_drake.experiments`` in this process, with ``job`` for the real planners."""
    return run_cli(lambda args: experiments_main(args, job=job, scenario=scenario_yamls), argv)


@pytest.fixture(scope="module")
def reference(tmp_path_factory) -> str:
    """The experiment's ``results.csv``, run undisturbed in this process."""
    out = tmp_path_factory.mktemp("reference")
    assert run_experiments([*GEN1, "--workers", "1", "--out", str(out)], steady_job) == 0
    return (out / "results.csv").read_text()


def rows_of(text: str) -> dict[tuple[str, str], str]:
    lines = text.splitlines()
    return {tuple(line.split(",")[0:3:2]): line for line in lines[1:]}


def test_an_experiment_job_whose_worker_dies_runs_again(tmp_path, capsys, faults, reference):
    status = run_experiments([*GEN1, "--workers", "2", "--out", str(tmp_path)], job_killing_its_worker_once)
    err = capsys.readouterr().err
    assert status == 0 and (faults / "job").exists() and "Traceback" not in err
    assert warnings(err) == [
        "warning: the worker running gen1-11 sto died (signal 9); running that job again"
    ]
    assert (tmp_path / "results.csv").read_text() == reference


def test_an_experiment_job_whose_worker_keeps_dying_gets_a_failure_row(tmp_path, capsys, reference):
    status = run_experiments([*GEN1, "--workers", "2", "--out", str(tmp_path)], job_killing_its_worker)
    err = capsys.readouterr().err
    assert status == 0 and "Traceback" not in err
    assert warnings(err) == [
        "warning: the worker running gen1-11 sto died (signal 9); running that job again",
        "warning: the worker running gen1-11 sto died (signal 9) again; that job is recorded as a failure",
    ]
    rows, expected = rows_of((tmp_path / "results.csv").read_text()), rows_of(reference)
    assert set(rows) == set(expected)
    assert {key: row for key, row in rows.items() if key != VICTIM} == {
        key: row for key, row in expected.items() if key != VICTIM
    }
    assert f"crashed: its worker process died {RETRIES + 1} times (signal 9)" in rows[VICTIM]
    assert ",false," in rows[VICTIM] and ",nan," in rows[VICTIM]
    summary = experiments.run_experiment(  # resumed: every row is there, nothing runs again
        ExperimentSettings(kind="gen1", scenes=3, seed=10, workers=2, progress=False),
        tmp_path,
        job=job_killing_its_worker,
        scenario=scenario_yamls,
    )
    assert summary["conditions"] and rows_of((tmp_path / "results.csv").read_text()) == rows


def test_a_lost_dask_worker_gets_its_job_rescheduled(tmp_path, capsys, faults, reference):
    pytest.importorskip("distributed")
    argv = [*GEN1, "--workers", "2", "--executor", "dask", "--out", str(tmp_path)]
    status = run_experiments(argv, job_killing_its_worker_once)
    err = capsys.readouterr().err
    assert status == 0 and (faults / "job").exists() and "Traceback" not in err
    assert warnings(err) == ["warning: a dask worker died running gen1-11 sto; running that job again"]
    assert (tmp_path / "results.csv").read_text() == reference


def test_a_dask_job_whose_workers_keep_dying_gets_a_failure_row(tmp_path, capsys, reference):
    pytest.importorskip("distributed")
    argv = [*GEN1, "--workers", "2", "--executor", "dask", "--out", str(tmp_path)]
    status = run_experiments(argv, job_killing_its_worker)
    err = capsys.readouterr().err
    assert status == 0 and "Traceback" not in err
    assert warnings(err) == [
        "warning: a dask worker died running gen1-11 sto; running that job again",
        "warning: the dask workers running gen1-11 sto died 2 times; that job is recorded as a failure",
    ]
    rows, expected = rows_of((tmp_path / "results.csv").read_text()), rows_of(reference)
    assert {key: row for key, row in rows.items() if key != VICTIM} == {
        key: row for key, row in expected.items() if key != VICTIM
    }
    assert f"crashed: its dask worker died {RETRIES + 1} times (KilledWorker)" in rows[VICTIM]


# --- Storage -------------------------------------------------------------------------------------


class Disk:
    """The disk under ``folder`` fills up after ``room`` more durable writes (an fsync of a file
    there): from then on every write of a file there fails with ENOSPC."""

    def __init__(self, monkeypatch, folder: pathlib.Path, room: int) -> None:
        self.folder, self.room = folder.resolve(), room
        fsync, write_text = os.fsync, pathlib.Path.write_text

        def fsync_here(fd: int) -> None:
            if stat.S_ISREG(os.fstat(fd).st_mode) and self.here(os.readlink(f"/proc/self/fd/{fd}")):
                if self.room <= 0:
                    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
                self.room -= 1
            fsync(fd)

        def write_text_here(path: pathlib.Path, *args, **kwargs):
            if self.here(path) and self.room <= 0:
                raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
            return write_text(path, *args, **kwargs)

        monkeypatch.setattr(os, "fsync", fsync_here)
        monkeypatch.setattr(pathlib.Path, "write_text", write_text_here)

    def here(self, path) -> bool:
        return pathlib.Path(path).resolve().is_relative_to(self.folder)


def no_temporary_files(folder: pathlib.Path) -> bool:
    return not list(folder.glob(".*.tmp"))


def test_a_full_disk_ends_the_experiment_with_one_line_keeps_its_rows_and_resumes(
    tmp_path, monkeypatch, capsys, reference
):
    argv = [*GEN1, "--workers", "1", "--out", str(tmp_path)]
    with monkeypatch.context() as patched:
        Disk(patched, tmp_path, room=3)  # results.csv's first writes: no row, then 2 rows
        status = run_experiments(argv, steady_job)
    err = capsys.readouterr().err
    assert status == 1 and "Traceback" not in err
    assert err.splitlines() == [f"error: {tmp_path / 'results.csv'}: cannot write: No space left on device"]
    kept = (tmp_path / "results.csv").read_text().splitlines()
    assert len(kept) == 1 + 2 and set(kept) <= set(reference.splitlines())
    assert (
        no_temporary_files(tmp_path)
        and json.loads((tmp_path / "run.json").read_text())["status"] == "running"
    )
    assert run_experiments(argv, steady_job) == 0  # given space again, the same command completes the table
    assert (tmp_path / "results.csv").read_text() == reference
    assert json.loads((tmp_path / "run.json").read_text())["jobs"]["kept"] == 2


def test_an_output_folder_that_becomes_unwritable_ends_the_run_with_one_line(
    tmp_path, monkeypatch, capsys, reference
):
    argv = [*GEN1, "--workers", "1", "--out", str(tmp_path)]
    made, ran = tempfile.mkstemp, []

    def mkstemp(*args, **kwargs):  # as a folder whose permission was taken away (root ignores chmod)
        if len(ran) >= 2 and pathlib.Path(kwargs["dir"]) == tmp_path:
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(tmp_path))
        return made(*args, **kwargs)

    def job(job):  # in this process (--workers 1): the folder is taken away during the second job
        ran.append(job.key)
        return steady_job(job)

    with monkeypatch.context() as patched:
        patched.setattr(tempfile, "mkstemp", mkstemp)
        status = run_experiments(argv, job)
    err = capsys.readouterr().err
    assert status == 1 and "Traceback" not in err
    (line,) = err.splitlines()
    assert line.startswith(f"error: {tmp_path}/") and line.endswith(
        f"cannot write: Permission denied ({tmp_path})"
    )
    rows = (tmp_path / "results.csv").read_text().splitlines()
    assert len(rows) > 1 and set(rows) <= set(reference.splitlines()) and no_temporary_files(tmp_path)
    assert run_experiments(argv, steady_job) == 0 and (tmp_path / "results.csv").read_text() == reference


def test_a_command_whose_output_hits_a_full_disk_exits_1_with_one_line_and_the_old_file(
    tmp_path, monkeypatch, capsys
):
    target = tmp_path / "run.json"
    target.write_text("old\n")

    def write(argv) -> int:
        atomic.write_text_atomic(target, "new\n")
        return 0

    Disk(monkeypatch, tmp_path, room=0)
    assert run_cli(write, []) == 1
    assert capsys.readouterr().err == f"error: {target}: cannot write: No space left on device\n"
    assert target.read_text() == "old\n" and no_temporary_files(tmp_path)
