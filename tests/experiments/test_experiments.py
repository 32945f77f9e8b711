"""``python -m hlp_drake.experiments``: results.csv, resume after an interrupt, executors, damaged run
folders, the command line.

All but one test run a cheap deterministic job (``cheap_job``: a pure function of its ``Job``) instead
of the Drake planners; ``test_cli_end_to_end_with_the_real_planners`` runs the real ones on one scene.
"""

from __future__ import annotations

import json
import multiprocessing
import os
import random
import signal
import threading
import time

import pytest
from job_support import (
    OUTPUTS,
    REQUIRED_COLUMNS,
    assert_well_formed,
    cheap_job,
    never_called,
    one_job,
    read_rows,
    run_experiment,
    settings,
)

from hlp_drake.errors import StorageError
from hlp_drake.experiments import Job, make_row
from hlp_drake.experiments.results import COLUMNS, read_results, results_csv, write_durable
from hlp_drake.systems.world.robot_description import MOBILE_UR5


class RecordingJob:
    """``cheap_job`` that remembers which jobs it ran (in-process runs only: ``workers=1``)."""

    def __init__(self) -> None:
        self.ran: list[tuple[str, str]] = []

    def __call__(self, job: Job) -> dict:
        self.ran.append((job.scene, job.planner))
        return cheap_job(job)


class InterruptingJob(RecordingJob):
    """Raises KeyboardInterrupt on its ``n``-th call, as Ctrl-C during that job would."""

    def __init__(self, n: int) -> None:
        super().__init__()
        self.n = n

    def __call__(self, job: Job) -> dict:
        if len(self.ran) + 1 == self.n:
            raise KeyboardInterrupt
        return super().__call__(job)


def interrupt_on_gen1_11_hlp(job: Job) -> dict:
    """Picklable for the process pool: Ctrl-C during scene gen1-11's HLP job."""
    if (job.scene, job.planner) == ("gen1-11", "hlp"):
        raise KeyboardInterrupt
    return cheap_job(job)


def test_a_results_file_without_the_later_columns_still_reads(tmp_path):
    """A results.csv written before ``grasp_held`` and ``fallback``: its rows read with them unknown."""
    from hlp_drake.errors import HlpError
    from hlp_drake.experiments.results import COLUMNS, LATER_COLUMNS, read_results

    run_experiment(settings("gen1", scenes=1), tmp_path, job=cheap_job)
    path = tmp_path / "results.csv"
    lines = path.read_text().splitlines()
    keep = len(COLUMNS) - len(LATER_COLUMNS)
    path.write_text("\n".join(",".join(line.split(",")[:keep]) for line in lines) + "\n")
    rows = read_results(path)
    assert rows and all(r["grasp_held"] is None and r["fallback"] is False for r in rows)
    path.write_text(lines[0].rsplit(",", 1)[0] + "\n")  # one later column only: not a results file
    with pytest.raises(HlpError, match="unexpected columns"):
        read_results(path)


def test_csv_has_the_columns_one_row_per_scene_and_planner_sorted(tmp_path):
    summary = run_experiment(settings("gen2", scenes=2, objects=(4, 3)), tmp_path, job=cheap_job)
    rows = assert_well_formed(tmp_path / "results.csv")
    assert list(rows[0])[: len(REQUIRED_COLUMNS)] == REQUIRED_COLUMNS
    assert list(rows[0])[-3:] == ["world", "grasp_held", "fallback"]
    assert {(r["generator"], r["robot"], r["initial"], r["low_level"]) for r in rows} == {
        ("gen2", MOBILE_UR5.name, "hlp", "sto"),
        ("gen2", MOBILE_UR5.name, "line", "sto"),
    }
    assert [(r["scene"], r["objects"], r["seed"], r["planner"]) for r in rows] == [
        (f"gen2-{n}-{seed}", str(n), str(seed), planner)
        for n in (3, 4)
        for seed in (10, 11)
        for planner in ("hlp", "sto")
    ]
    for row in rows:
        assert row["success"] in ("true", "false")
        assert (row["failure_reason"] == "") == (row["success"] == "true")
        init, optimise = float(row["init_s"]), float(row["optimise_s"])
        assert float(row["total_s"]) == pytest.approx(init + optimise, abs=2e-6)
        assert int(row["objects_moved"]) <= int(row["objects"])
    assert [c["objects"] for c in summary["conditions"]] == [3, 4]
    assert all(name in {p.name for p in tmp_path.iterdir()} for name in OUTPUTS)


def test_gen1_ignores_objects_and_reports_the_scene_count(tmp_path):
    run_experiment(settings(objects=(3,)), tmp_path, job=cheap_job)
    rows = read_rows(tmp_path / "results.csv")
    assert {r["objects"] for r in rows} == {"6"}
    assert [r["scene"] for r in rows[::2]] == ["gen1-10", "gen1-11", "gen1-12"]


def test_interrupt_keeps_exactly_the_finished_rows_and_resume_runs_only_the_rest(tmp_path):
    reference = tmp_path / "reference"
    run_experiment(settings(), reference, job=cheap_job)
    out = tmp_path / "run"
    interrupting = InterruptingJob(5)
    with pytest.raises(KeyboardInterrupt):
        run_experiment(settings(), out, job=interrupting)
    rows = assert_well_formed(out / "results.csv")
    assert [(r["scene"], r["planner"]) for r in rows] == interrupting.ran and len(rows) == 4
    run = json.loads((out / "run.json").read_text())
    assert run["status"] == "interrupted" and run["jobs"]["rows"] == 4 and run["end_time"]
    assert not (out / "summary.json").exists()

    resumed = RecordingJob()
    run_experiment(settings(), out, job=resumed)
    assert resumed.ran == [("gen1-12", "hlp"), ("gen1-12", "sto")]
    assert (out / "results.csv").read_text() == (reference / "results.csv").read_text()
    run = json.loads((out / "run.json").read_text())
    assert run["status"] == "complete" and run["jobs"]["kept"] == 4 and len(run["earlier_runs"]) == 1


def test_interrupt_in_a_process_pool_then_resume(tmp_path):
    reference = tmp_path / "reference"
    run_experiment(settings(), reference, job=cheap_job)
    out = tmp_path / "run"
    with pytest.raises(KeyboardInterrupt):
        run_experiment(settings(workers=2), out, job=interrupt_on_gen1_11_hlp)
    rows = assert_well_formed(out / "results.csv")
    assert ("gen1-11", "hlp") not in {(r["scene"], r["planner"]) for r in rows} and len(rows) < 6
    run_experiment(settings(workers=2), out, job=cheap_job)
    assert (out / "results.csv").read_text() == (reference / "results.csv").read_text()


def test_all_rows_done_writes_the_summary_without_running_jobs(tmp_path):
    run_experiment(settings(), tmp_path, job=cheap_job)
    for name in ("summary.md", "summary.json", "success.png", "times.png"):
        (tmp_path / name).unlink()
    run_experiment(settings(), tmp_path, job=never_called)
    assert all((tmp_path / name).exists() for name in OUTPUTS)


def test_local_pool_gives_the_same_results_as_in_process(tmp_path):
    run_experiment(settings("gen2", scenes=2, objects=(3,)), tmp_path / "one", job=cheap_job)
    run_experiment(settings("gen2", scenes=2, objects=(3,), workers=2), tmp_path / "two", job=cheap_job)
    for name in ("results.csv", "summary.json"):
        one, two = ((tmp_path / d / name).read_text() for d in ("one", "two"))
        if name == "results.csv":
            assert one == two
        else:
            assert json.loads(one)["conditions"] == json.loads(two)["conditions"]


def test_dask_gives_the_same_results_as_local(tmp_path):
    distributed = pytest.importorskip(
        "distributed", reason='dask.distributed is not installed: pip install "hlp_drake[cluster]"'
    )
    run_experiment(settings(scenes=2), tmp_path / "local", job=cheap_job)
    run_experiment(settings(scenes=2, workers=2, executor="dask"), tmp_path / "dask", job=cheap_job)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, dashboard_address=None) as cluster:
        on_cluster = settings(scenes=2, executor="dask", scheduler=cluster.scheduler_address)
        run_experiment(on_cluster, tmp_path / "scheduler", job=cheap_job)
    expected = (tmp_path / "local" / "results.csv").read_text()
    for run in ("dask", "scheduler"):
        assert (tmp_path / run / "results.csv").read_text() == expected
        assert json.loads((tmp_path / run / "run.json").read_text())["executor"] == "dask"


def crash_gen2_5_11_sto(job: Job) -> dict:
    """``cheap_job``, but the straight line on gen2-5-11 crashes as ``run_job`` records a crash."""
    if (job.scene, job.planner) == ("gen2-5-11", "sto"):
        nan = float("nan")
        times = {"plan_s": nan, "ik_s": nan, "optimise_s": nan, "execute_s": nan, "verify_s": nan}
        return make_row(
            job,
            success=False,
            failure_reason="crashed: RuntimeError: x",
            rollouts=0,
            iterations=0,
            objects_moved=0,
            objects_dropped=0,
            **times,
        )
    return cheap_job(job)


def test_a_gen2_run_over_two_counts_with_a_crash_resumes_and_extends(tmp_path):
    run_experiment(settings("gen2", objects=(5, 7), scenes=2), tmp_path, job=crash_gen2_5_11_sto)
    rows = read_results(tmp_path / "results.csv", ("gen2",))
    assert len(rows) == 8 and sum(row["total_s"] != row["total_s"] for row in rows) == 1  # NaN
    resumed = RecordingJob()
    run_experiment(settings("gen2", objects=(5, 7), scenes=3), tmp_path, job=resumed)
    assert sorted(resumed.ran) == [
        ("gen2-5-12", "hlp"),
        ("gen2-5-12", "sto"),
        ("gen2-7-12", "hlp"),
        ("gen2-7-12", "sto"),
    ]
    assert len(read_results(tmp_path / "results.csv", ("gen2",))) == 12


def test_durable_write_leaves_the_old_file_when_it_fails(tmp_path, monkeypatch):
    path = tmp_path / "results.csv"
    write_durable(path, results_csv([]))
    monkeypatch.setattr("os.fsync", lambda fd: (_ for _ in ()).throw(OSError("disk full")))
    with pytest.raises(StorageError, match=f"{path}: cannot write: disk full"):
        write_durable(path, "scene\npartial")
    assert path.read_text() == ",".join(COLUMNS) + "\n" and not list(tmp_path.glob(".*.tmp"))


def sleepy_job(job: Job) -> dict:
    """A job far longer than the test: Ctrl-C must not wait for it."""
    time.sleep(40)
    return cheap_job(job)


def test_interrupt_stops_a_process_pool_without_waiting_for_running_jobs(tmp_path):
    timer = threading.Timer(4.0, os.kill, (os.getpid(), signal.SIGINT))  # Ctrl-C while both workers sleep
    started = time.perf_counter()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            run_experiment(settings(workers=2), tmp_path, job=sleepy_job)
    finally:
        timer.cancel()
    assert time.perf_counter() - started < 20
    assert not multiprocessing.active_children()
    assert read_rows(tmp_path / "results.csv") == []


def test_rows_finishing_in_any_order_are_written_sorted(tmp_path):
    run_experiment(settings("gen2", scenes=3, objects=(2, 3)), tmp_path, job=cheap_job)
    text = (tmp_path / "results.csv").read_text()
    rows = read_results(tmp_path / "results.csv")
    random.Random(0).shuffle(rows)
    assert results_csv(rows) == text and results_csv(reversed(rows)) == text


def test_a_drake_check_failing_in_a_job_is_that_jobs_crash_and_a_real_exit_is_not(monkeypatch):
    from hlp_drake.systems.execution import job as job_module
    from hlp_drake.systems.scenario import Scenario

    job = one_job(Scenario().updated("planner: {low_level: {workers: 1}}").yaml, "gen1", 0)

    def failing_check(scenario, *, pool, **kwargs):
        assert scenario.scene.name == "gen1-0" and scenario.planner.initial == "hlp" and pool.workers == 1
        raise SystemExit("Failure at plant.h:1 in SetPositions(): condition 'AllFinite(q)' failed.")

    monkeypatch.setattr(job_module, "plan_and_execute", failing_check)
    row = job_module.run_job(job)
    assert row["success"] is False and row["rollouts"] == 0
    assert row["failure_reason"] == (
        "crashed: SystemExit: Failure at plant.h:1 in SetPositions(): condition 'AllFinite(q)' failed."
    )

    def exiting(*args, **kwargs):
        raise SystemExit(3)

    monkeypatch.setattr(job_module, "plan_and_execute", exiting)
    with pytest.raises(SystemExit):
        job_module.run_job(job)


def process_of(job: Job) -> int:
    """The id of the process that ran ``job``."""
    return os.getpid()


def test_local_pool_workers_are_renewed_every_jobs_per_worker_jobs(monkeypatch):
    from hlp_drake.experiments import executors

    jobs = [one_job("", "gen2", seed, 3) for seed in range(6)]
    monkeypatch.setattr(executors, "JOBS_PER_WORKER", 2)
    pids = [pid for _, pid in executors.run_jobs(process_of, jobs, workers=2)]
    assert len(pids) == 6 and os.getpid() not in pids
    chunks = [set(pids[:4]), set(pids[4:])]  # 2 jobs per worker, 2 workers: fresh ones after 4 jobs
    assert not chunks[0] & chunks[1]
