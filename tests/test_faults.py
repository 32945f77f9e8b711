"""Faults of the machine, injected: a worker process killed, a full disk, damaged model and dataset
files. Each run survives with the same result, or ends with one line and no traceback."""

from __future__ import annotations

import json
import os
import re
import signal

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

from hlp_drake import experiments
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
