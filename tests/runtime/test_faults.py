"""Faults of the machine, injected: a worker process killed, a full disk, damaged model and dataset
files. Each run survives with the same result, or ends with one line and no traceback."""

from __future__ import annotations

import errno
import hashlib
import io
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
)
from job_support import cheap_job, settings
from sto_support import on, short, spec
from synthetic_dataset import write_dataset

from hlp_drake import experiments
from hlp_drake.commands.experiments import main as experiments_main
from hlp_drake.commands.parsing import run_cli
from hlp_drake.errors import ModelError
from hlp_drake.experiments.executors import RETRIES
from hlp_drake.files import atomic
from hlp_drake.learners.bundled import BUNDLED_DIRECTORY
from hlp_drake.learners.models import VERSION, DecisionModels
from hlp_drake.systems import resolve_study
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.sto import pool as pool_module
from hlp_drake.systems.low_level.sto.optimiser import optimise, sample_base_noise
from hlp_drake.systems.low_level.sto.pool import MAX_DEATHS, RolloutPool

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
    base = short(ControlSequence.from_trajectory(trajectories["line"], 0.5), 1.0)
    config = on(scene)
    noise = sample_base_noise(np.random.default_rng(0), base, config.low_level.noise, 3)
    sequences = [base.with_base_velocity(v) for v in noise]
    with RolloutPool(2) as pool:
        undisturbed = pool.rollouts(spec(config), sequences)
        assert warnings(capsys.readouterr().err) == []
        victim = next(iter(pool._executor._processes.values()))
        os.kill(victim.pid, signal.SIGKILL)  # as the out-of-memory killer would
        disturbed = pool.rollouts(spec(config), sequences)
        again = pool.rollouts(spec(config), sequences)  # the replaced workers go on serving
    assert [comparable(o) for o in disturbed] == [comparable(o) for o in undisturbed]
    assert [comparable(o) for o in again] == [comparable(o) for o in undisturbed]
    (line,) = warnings(capsys.readouterr().err)
    assert WARNING.match(line) and "(signal 9)" in line, line


def test_workers_dying_again_and_again_end_the_optimisation_as_a_failure(
    scene, trajectories, capsys, monkeypatch
):
    monkeypatch.setattr(pool_module, "_rollout_task", rollout_exiting)
    config = on(scene, "planner: {low_level: {samples: 2, max_iterations: 3}}")
    initial = short(ControlSequence.from_trajectory(trajectories["line"], 0.5), 1.0)  # fails: too short
    with RolloutPool(2) as pool:
        result = optimise(
            spec(config), initial, pool
        )  # the initial rollout here, the iterations' on the workers
        with pytest.raises(pool_module.WorkersLost):  # the pool stays given up
            pool.rollouts(spec(config), [initial, initial])
    assert not result.success and result.iterations == 0 and result.rollouts == 1
    assert result.failure_reason == f"the rollout workers died {MAX_DEATHS} times in a row (exit status 3)"
    lines = warnings(capsys.readouterr().err)
    assert len(lines) == MAX_DEATHS - 1 and all(WARNING.match(line) for line in lines), lines
    assert all("(exit status 3)" in line for line in lines)


def run_scene_json(tmp_path, name: str, capsys) -> tuple[int, dict, str]:
    """``run_scene --planner sto`` on 2 workers, in this process: its exit status, JSON and stderr."""
    from hlp_drake.commands.run_scene import main

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
    return run_cli(lambda args: experiments_main(args, job=job, resolve=resolve_study), argv)


@pytest.fixture(scope="module")
def reference(tmp_path_factory) -> str:
    """The experiment's ``results.csv``, run undisturbed in this process."""
    out = tmp_path_factory.mktemp("reference")
    assert run_experiments([*GEN1, "--workers", "1", "--out", str(out)], cheap_job) == 0
    return (out / "results.csv").read_text()


def rows_of(text: str) -> dict[tuple[str, str], str]:
    lines = text.splitlines()
    return {tuple(line.split(",")[0:3:2]): line for line in lines[1:]}


def rows_but_the_victims_as(path, reference: str) -> dict:
    """``path``'s rows, after checking they are the ``reference`` run's rows, ``VICTIM``'s aside (the
    same jobs, every other row the same)."""
    rows, expected = rows_of(path.read_text()), rows_of(reference)
    assert set(rows) == set(expected)
    assert {k: r for k, r in rows.items() if k != VICTIM} == {
        k: r for k, r in expected.items() if k != VICTIM
    }
    return rows


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
    rows = rows_but_the_victims_as(tmp_path / "results.csv", reference)
    assert f"crashed: its worker process died {RETRIES + 1} times (signal 9)" in rows[VICTIM]
    assert ",false," in rows[VICTIM] and ",nan," in rows[VICTIM]
    summary = experiments.run_experiment(  # resumed: every row is there, nothing runs again
        settings(workers=2),
        tmp_path,
        job=job_killing_its_worker,
        resolve=resolve_study,
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
    rows = rows_but_the_victims_as(tmp_path / "results.csv", reference)
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
        status = run_experiments(argv, cheap_job)
    err = capsys.readouterr().err
    assert status == 1 and "Traceback" not in err
    assert err.splitlines() == [f"error: {tmp_path / 'results.csv'}: cannot write: No space left on device"]
    kept = (tmp_path / "results.csv").read_text().splitlines()
    assert len(kept) == 1 + 2 and set(kept) <= set(reference.splitlines())
    assert (
        no_temporary_files(tmp_path)
        and json.loads((tmp_path / "run.json").read_text())["status"] == "running"
    )
    assert run_experiments(argv, cheap_job) == 0  # given space again, the same command completes the table
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
        return cheap_job(job)

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
    assert run_experiments(argv, cheap_job) == 0 and (tmp_path / "results.csv").read_text() == reference


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


# --- Model files ---------------------------------------------------------------------------------


def models_copy(folder: pathlib.Path, *, meta=None, arrays=None) -> pathlib.Path:
    """The bundled models copied to ``folder``, ``meta`` (models.json's dict) and ``arrays`` (the
    npz's dict) changed in place by the given functions, the checksum recomputed to match."""
    described = json.loads((BUNDLED_DIRECTORY / "models.json").read_text())
    with np.load(BUNDLED_DIRECTORY / "models.npz") as npz:
        stored = {name: npz[name] for name in npz.files}
    if arrays is not None:
        arrays(stored)
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **stored)
    folder.mkdir()
    (folder / "models.npz").write_bytes(buffer.getvalue())
    described["sha256"] = hashlib.sha256(buffer.getvalue()).hexdigest()
    if meta is not None:
        meta(described)
    (folder / "models.json").write_text(json.dumps(described))
    return folder


def test_models_of_a_newer_format_are_refused_in_one_line(tmp_path, capsys):
    from hlp_drake.commands.run_scene import main

    newer = models_copy(tmp_path / "newer", meta=lambda m: m.update(version=VERSION + 1))
    expected = f"{newer / 'models.json'}: written by a newer hlp_drake: format {VERSION + 1}, this release reads {VERSION}"
    with pytest.raises(ModelError) as refused:
        DecisionModels.load(newer)
    assert refused.value.problems == (expected,)
    config = tmp_path / "scenario.yaml"
    config.write_text(f"planner: {{models: {newer}}}\n")
    assert run_cli(main, ["--config", str(config), "--workers", "1", "--quiet"]) == 2
    assert capsys.readouterr().err == f"error: {expected}\n"


def fewer_trees(arrays: dict) -> None:
    for name in ("feature", "threshold", "left", "right", "value"):
        arrays[f"row.learner.{name}"] = arrays[f"row.learner.{name}"][:10]


def more_arm_samples(arrays: dict) -> None:
    arrays["arm.train"] = np.concatenate([arrays["arm.train"], arrays["arm.train"][:100]])
    arrays["arm.alpha"] = np.concatenate([arrays["arm.alpha"], arrays["arm.alpha"][:, :100]], axis=1)


@pytest.mark.parametrize(
    ("change", "reason"),
    [
        (fewer_trees, "array 'row.learner.feature' holds 10 trees, the settings declare n_estimators 150"),
        (
            more_arm_samples,
            "array 'arm.train' holds 1600 samples, more than its learner settings allow (1500)",
        ),
    ],
)
def test_arrays_that_disagree_with_the_declared_settings_are_refused(tmp_path, change, reason):
    damaged = models_copy(tmp_path / "damaged", arrays=change)  # each array's shape fits the format
    with pytest.raises(ModelError) as refused:
        DecisionModels.load(damaged)
    assert refused.value.problems == (f"{damaged / 'models.npz'}: {reason}",)


# --- Interaction logs ----------------------------------------------------------------------------


def log_of(folder: pathlib.Path, trial: int) -> pathlib.Path:
    """The synthetic dataset's interaction log of ``trial``."""
    return folder / "sub_01" / f"T{trial:03d}" / "movement" / f"interaction_log_T{trial:03d}.csv"


def damage_logs(folder: pathlib.Path) -> dict[pathlib.Path, str]:
    """Damage the interaction logs of the synthetic dataset's 3 trials: the expected reason by path."""
    text = log_of(folder, 5).read_text()
    log_of(folder, 5).write_text(text[: len(text) - 9])  # cut short in its last line
    log_of(folder, 10).write_text(text.replace(",FailOnTouchObstacleMed,", ",FailOnTouchObstacleHuge,"))
    log_of(folder, 11).write_text(text.replace("PickedUp\n", "Pick\n"))  # cut, then a line end added
    return {
        log_of(folder, 5): "truncated: the last line has no line end",
        log_of(
            folder, 10
        ): "line 2: names 'FailOnTouchObstacleHuge', which the scene does not have: trial skipped",
        log_of(
            folder, 11
        ): "line 3: unknown interaction 'Pick' (expected one of LeftGate, RightGate, PickedUp, "
        "Pushed; the file may be cut short)",
    }


def test_damaged_interaction_logs_are_reported_per_trial_and_left_out(tmp_path, monkeypatch, capsys):
    from hlp_drake.commands.dataset import main as dataset_main
    from hlp_drake.commands.segment import main as segment_main

    folder = write_dataset(tmp_path / "dataset")
    expected = damage_logs(folder)
    monkeypatch.setenv("HLP_CACHE", str(tmp_path / "cache"))
    summary_json = tmp_path / "summary.json"
    assert run_cli(dataset_main, ["summary", "--dataset", str(folder), "--json", str(summary_json)]) == 0
    assert sorted(warnings(capsys.readouterr().err)) == sorted(
        f"warning: {path}: {reason}" for path, reason in expected.items()
    )
    counts = json.loads(summary_json.read_text())["categories"]
    assert counts["structured"]["trials"] == counts["practice"]["trials"] == 0
    argv = ["--dataset", str(folder), "--out", str(tmp_path / "d.csv"), "--json", str(tmp_path / "d.json")]
    assert run_cli(segment_main, [*argv, "--quiet"]) == 0
    rejections = json.loads((tmp_path / "d.json").read_text())["rejections"]
    assert sorted(rejections, key=lambda r: r["trial"]) == [
        {"trial": f"sub_01/T{n:03d}", "reason": f"unreadable data: {expected[log_of(folder, n)]}"}
        for n in (10, 11)  # the structured ones
    ]
    trial = ["--dataset", str(folder), "--trial", "sub_01/T010", "--png", str(tmp_path / "t.png")]
    capsys.readouterr()
    assert run_cli(segment_main, trial) == 2
    assert capsys.readouterr().err == (
        f"error: sub_01/T010 was left out of the dataset: {log_of(folder, 10)}: {expected[log_of(folder, 10)]}\n"
    )
