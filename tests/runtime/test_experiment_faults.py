"""An experiment's faults, injected: its jobs' workers killed, a full disk, its output folder taken away."""

from __future__ import annotations

import errno
import json
import os
import pathlib
import stat
import tempfile

import pytest
from fault_support import VICTIM, fault_markers, job_killing_its_worker, job_killing_its_worker_once, warnings
from job_support import cheap_job, settings

from hlp_drake import experiments
from hlp_drake.commands.experiments import main as experiments_main
from hlp_drake.commands.parsing import run_cli
from hlp_drake.experiments.executors import RETRIES
from hlp_drake.files import atomic
from hlp_drake.systems import resolve_study

faults = pytest.fixture(fault_markers, name="faults")

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
