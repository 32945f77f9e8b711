"""``python -m hlp_drake.experiments``: results.csv, resume after an interrupt, executors, summary, plots.

All but one test run a cheap deterministic job (``cheap_job``: a pure function of its ``Job``) instead
of the Drake planners; ``test_cli_end_to_end_with_the_real_planners`` runs the real ones on one scene.
"""

from __future__ import annotations

import csv
import json
import multiprocessing
import os
import random
import signal
import threading
import time
from pathlib import Path

import pandas as pd
import pytest
from conftest import run_module
from job_support import cheap_job, drake_info_job

from hlp_drake import DRAKE_LOG, experiments
from hlp_drake.commands.experiments import main
from hlp_drake.commands.parsing import invoked_as, run_cli
from hlp_drake.errors import HlpError, StorageError
from hlp_drake.experiments import ExperimentSettings, Job, make_row
from hlp_drake.experiments.plots import plot_title
from hlp_drake.experiments.results import (
    COLUMNS,
    EARLIER_COLUMNS,
    read_results,
    results_csv,
    write_durable,
)
from hlp_drake.experiments.runner import JobFunction
from hlp_drake.experiments.summary import summarise
from hlp_drake.systems import scenario_yamls
from hlp_drake.systems.world.robot_description import MOBILE_UR5

# fmt: off
REQUIRED_COLUMNS = ["scene", "objects", "planner", "success", "failure_reason", "init_s", "optimise_s",
                    "total_s", "rollouts", "objects_moved", "objects_dropped"]
# fmt: on
OUTPUTS = ("results.csv", "config.json", "run.json", "summary.md", "summary.json", "success.png", "times.png")


class RecordingJob:
    """``cheap_job`` that remembers which jobs it ran (in-process runs only: ``workers=1``)."""

    def __init__(self) -> None:
        self.ran: list[tuple[str, str]] = []

    def __call__(self, job: Job) -> dict:
        self.ran.append(job.key)
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
    if job.key == ("gen1-11", "hlp"):
        raise KeyboardInterrupt
    return cheap_job(job)


def never_called(job: Job) -> dict:
    raise AssertionError(f"{job.key} was run again")


def settings(kind: str = "gen1", **changes) -> ExperimentSettings:
    defaults = {"scenes": 3, "seed": 10, "workers": 1, "progress": False}
    return ExperimentSettings(kind=kind, **{**defaults, **changes})


def run_experiment(settings: ExperimentSettings, out: Path, *, job: JobFunction) -> dict:
    """``hlp_drake.experiments.run_experiment`` with the real scenario reading and the test's ``job``."""
    return experiments.run_experiment(settings, out, job=job, scenario=scenario_yamls)


def read_rows(path: Path) -> list[dict[str, str]]:
    with path.open(newline="") as file:
        return list(csv.DictReader(file))


def assert_well_formed(path: Path) -> list[dict[str, str]]:
    """The CSV has exactly the columns and every row has every field; no temp file beside it."""
    with path.open(newline="") as file:
        records = list(csv.reader(file))
    assert tuple(records[0]) == COLUMNS
    assert all(len(record) == len(COLUMNS) for record in records[1:])
    assert not list(path.parent.glob(".*.tmp"))
    return read_rows(path)


def test_csv_has_the_columns_one_row_per_scene_and_planner_sorted(tmp_path):
    summary = run_experiment(settings("gen2", scenes=2, objects=(4, 3)), tmp_path, job=cheap_job)
    rows = assert_well_formed(tmp_path / "results.csv")
    assert list(rows[0])[: len(REQUIRED_COLUMNS)] == REQUIRED_COLUMNS and list(rows[0])[-1] == "execute_s"
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


def test_a_results_file_from_before_verify_s_resumes_with_it_unknown(tmp_path):
    reference = tmp_path / "reference"
    run_experiment(settings(), reference, job=cheap_job)
    frame = pd.read_csv(reference / "results.csv", dtype=str, keep_default_na=False)
    out = tmp_path / "run"
    out.mkdir()
    (out / "config.json").write_text((reference / "config.json").read_text())
    earlier = frame[list(EARLIER_COLUMNS)].iloc[:4]  # two scenes, as written before the column
    earlier.to_csv(out / "results.csv", index=False, lineterminator="\n")
    rows = read_results(out / "results.csv")
    assert len(rows) == 4 and all(row["verify_s"] != row["verify_s"] for row in rows)  # NaN
    assert [list(row) for row in rows] == [list(COLUMNS)] * 4
    resumed = RecordingJob()
    summary = run_experiment(settings(), out, job=resumed)
    assert resumed.ran == [("gen1-12", "hlp"), ("gen1-12", "sto")]
    written = pd.read_csv(out / "results.csv")
    assert tuple(written.columns) == COLUMNS and written.verify_s.isna().sum() == 4
    (condition,) = summary["conditions"]
    hlp = written[written.planner == "hlp"]
    assert condition["planners"]["hlp"]["verify_s"] == pytest.approx(hlp.verify_s.mean(), abs=1e-4)
    (out / "results.csv").write_text("scene,planner\ngen1-0,hlp\n")
    with pytest.raises(HlpError, match="unexpected columns"):
        read_results(out / "results.csv")


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


def test_a_different_run_in_the_directory_is_refused_unless_fresh(tmp_path, capsys):
    run_experiment(settings(), tmp_path, job=cheap_job)
    before = {name: (tmp_path / name).read_bytes() for name in OUTPUTS}
    argv = ["gen1", "--scenes", "2", "--seed", "20", "--workers", "1", "--quiet", "--out", str(tmp_path)]
    assert run_cli(lambda a: main(a, job=cheap_job), argv) == 2
    message = capsys.readouterr().err.strip()
    assert message.count("\n") == 0 and "different seed" in message and "--fresh" in message
    assert {name: (tmp_path / name).read_bytes() for name in OUTPUTS} == before
    assert run_cli(lambda a: main(a, job=cheap_job), [*argv, "--fresh"]) == 0
    assert [r["scene"] for r in read_rows(tmp_path / "results.csv")] == ["gen1-20"] * 2 + ["gen1-21"] * 2
    with pytest.raises(HlpError, match="scenario"):
        run_experiment(settings(seed=20, config_yaml="motion: {tcp_speed: 0.05}"), tmp_path, job=cheap_job)


@pytest.mark.parametrize(
    "argv",
    [
        ["gen1", "--scenes", "0"],
        ["gen2", "--objects", "5", "0"],
        ["gen3"],
        ["gen1", "--workers", "0"],
        ["gen1", "--scenes", "many"],
        ["gen1", "--scheduler", "tcp://127.0.0.1:8786"],
    ],
)
def test_bad_input_is_one_line_exit_2_and_writes_nothing(tmp_path, capsys, argv):
    out = tmp_path / "out"
    assert run_cli(lambda a: main(a, job=never_called), [*argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and err.count("\n") == 1 and not out.exists()


def _bad_row(text: str, field: str, value: str) -> str:
    """``text`` (a results.csv) with ``field`` of its first row set to ``value``."""
    lines = text.splitlines()
    row = lines[1].split(",")
    row[COLUMNS.index(field)] = value
    return "\n".join([lines[0], ",".join(row), *lines[2:]]) + "\n"


@pytest.mark.parametrize(
    ("name", "damage", "expected"),
    [
        ("results.csv", lambda t: t.encode() + b"\xff\xfe\n", "unreadable"),
        ("results.csv", lambda t: t + "x" * 200_000 + "\n", "unreadable"),
        ("results.csv", lambda t: _bad_row(t, "total_s", "inf"), "total_s inf, expected 0 to"),
        ("results.csv", lambda t: _bad_row(t, "init_s", "-1e308"), "init_s"),
        ("results.csv", lambda t: _bad_row(t, "rollouts", "-3"), "rollouts -3"),
        ("results.csv", lambda t: _bad_row(t, "planner", "magic"), "planner 'magic'"),
        ("results.csv", lambda t: _bad_row(t, "scene", "gen2-9-10"), "not the gen1 scene"),
        ("results.csv", None, "it is a directory"),
        ("summary.md", None, "it is a directory"),  # refused before the jobs, not after them
        ("run.json", lambda t: '{"earlier_runs": 5}', "earlier_runs"),
        ("run.json", lambda t: '{"earlier_runs": "abc"}', "earlier_runs"),
        ("run.json", lambda t: "{not json", "unreadable"),
        ("config.json", lambda t: "[1, 2]", "not a JSON object"),
        ("config.json", lambda t: "[" * 200_000, "unreadable"),
        ("config.json", lambda t: " " * (17 << 20), "larger than"),
    ],
)
def test_a_damaged_run_directory_is_refused_and_left_as_it_was(tmp_path, capsys, name, damage, expected):
    run_experiment(settings(), tmp_path, job=cheap_job)
    path = tmp_path / name
    if damage is None:
        path.unlink()
        path.mkdir()
    else:
        text = damage(path.read_text())
        path.write_bytes(text) if isinstance(text, bytes) else path.write_text(text)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()}
    argv = ["gen1", "--scenes", "3", "--seed", "10", "--workers", "1", "--quiet", "--out", str(tmp_path)]
    assert run_cli(lambda a: main(a, job=never_called), argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and expected in err, err
    assert "--fresh" in err or damage is None  # a folder in an output's place: --fresh cannot help
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()} == before


def crash_gen2_5_11_sto(job: Job) -> dict:
    """``cheap_job``, but the straight line on gen2-5-11 crashes as ``run_job`` records a crash."""
    if job.key == ("gen2-5-11", "sto"):
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
    rows = read_results(tmp_path / "results.csv", "gen2")
    assert len(rows) == 8 and sum(row["total_s"] != row["total_s"] for row in rows) == 1  # NaN
    resumed = RecordingJob()
    run_experiment(settings("gen2", objects=(5, 7), scenes=3), tmp_path, job=resumed)
    assert sorted(resumed.ran) == [
        ("gen2-5-12", "hlp"),
        ("gen2-5-12", "sto"),
        ("gen2-7-12", "hlp"),
        ("gen2-7-12", "sto"),
    ]
    assert len(read_results(tmp_path / "results.csv", "gen2")) == 12


def test_dask_not_installed_says_how_to_install_it(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(__import__("sys").modules, "distributed", None)  # makes "import distributed" fail
    out = tmp_path / "out"
    argv = ["gen1", "--executor", "dask", "--out", str(out)]
    assert run_cli(lambda a: main(a, job=never_called), argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and 'pip install "hlp_drake[cluster]"' in err and not out.exists()


def test_summary_matches_the_csv_and_shows_the_paper_numbers(tmp_path):
    run_experiment(settings("gen2", scenes=4, objects=(5, 9)), tmp_path, job=cheap_job)
    frame = pd.read_csv(tmp_path / "results.csv")
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["table"].startswith("Table III")
    for condition in summary["conditions"]:
        for planner, stats in condition["planners"].items():
            group = frame[(frame.objects == condition["objects"]) & (frame.planner == planner)]
            assert stats["n"] == len(group) == 4
            assert stats["success_pct"] == pytest.approx(100 * group.success.mean())
            assert stats["total_s"] == pytest.approx(group.total_s.mean(), abs=1e-4)
            assert stats["init_s"] + stats["optimise_s"] == pytest.approx(stats["total_s"], abs=2e-4)
            assert 0 < stats["verify_s"] == pytest.approx(group.verify_s.mean(), abs=1e-4)
            assert stats["paper"]["total_s"] is None
        means = {
            p: frame[(frame.objects == condition["objects"]) & (frame.planner == p)].total_s.mean()
            for p in ("hlp", "sto")
        }
        assert condition["hlp_to_sto_total"] == pytest.approx(means["hlp"] / means["sto"], rel=1e-3)
        searching = {
            p: (group.total_s - group.verify_s).mean()
            for p, group in frame[frame.objects == condition["objects"]].groupby("planner")
        }
        assert condition["hlp_to_sto_total_without_verification"] == pytest.approx(
            searching["hlp"] / searching["sto"], rel=1e-3
        )
    papers = {
        c["objects"]: tuple(c["planners"][p]["paper"]["success_pct"] for p in ("hlp", "sto"))
        for c in summary["conditions"]
    }
    assert papers == {5: (93.0, 96.0), 9: (95.0, 98.0)}
    markdown = (tmp_path / "summary.md").read_text()
    assert "| 5 objects | HLP | 4 |" in markdown and "(93)" in markdown and "n/a" in markdown
    for name in ("success.png", "times.png"):
        data = (tmp_path / name).read_bytes()
        assert data.startswith(b"\x89PNG\r\n\x1a\n") and len(data) > 10_000


def test_gen1_summary_has_table_ii_paper_figures():
    rows = [
        {
            "scene": f"gen1-{i}",
            "objects": 6,
            "planner": p,
            "success": i != 0,
            "failure_reason": None,
            "init_s": 0.5,
            "optimise_s": 1.0 if p == "hlp" else 10.0,
            "total_s": 1.5 if p == "hlp" else 10.5,
            "verify_s": 0.6 if p == "hlp" else 2.0,
            "execute_s": 3.0,
        }
        for i in range(4)
        for p in ("hlp", "sto")
    ]
    rows.append(
        {
            **rows[0],
            "scene": "gen1-4",
            "success": False,
            "failure_reason": "crashed: RuntimeError: x",
            "init_s": float("nan"),
            "optimise_s": float("nan"),
            "total_s": float("nan"),
            "verify_s": float("nan"),
        }
    )
    (condition,) = summarise("gen1", rows)["conditions"]
    hlp, sto = condition["planners"]["hlp"], condition["planners"]["sto"]
    assert hlp["paper"] == {"success_pct": 94.0, "init_s": 0.59, "optimise_s": 0.97, "total_s": 1.56}
    assert sto["paper"] == {"success_pct": 84.0, "init_s": 0.04, "optimise_s": 17.84, "total_s": 17.88}
    assert (hlp["n"], hlp["success_pct"], hlp["crashed"], hlp["total_s"]) == (5, 60.0, 1, 1.5)
    assert condition["hlp_to_sto_total"] == pytest.approx(1.5 / 10.5, abs=1e-4)
    assert condition["hlp_to_sto_total_without_verification"] == pytest.approx(0.9 / 8.5, abs=1e-4)
    assert (hlp["verify_s"], sto["verify_s"]) == (0.6, 2.0)
    assert condition["paper_hlp_to_sto_total"] == pytest.approx(1.56 / 17.88, abs=1e-4)
    assert hlp["success_ci95"][0] < 60.0 < hlp["success_ci95"][1]


def test_durable_write_leaves_the_old_file_when_it_fails(tmp_path, monkeypatch):
    path = tmp_path / "results.csv"
    write_durable(path, results_csv([]))
    monkeypatch.setattr("os.fsync", lambda fd: (_ for _ in ()).throw(OSError("disk full")))
    with pytest.raises(StorageError, match=f"{path}: cannot write: disk full"):
        write_durable(path, "scene\npartial")
    assert path.read_text() == ",".join(COLUMNS) + "\n" and not list(tmp_path.glob(".*.tmp"))


def test_cli_fast_public_api(tmp_path, capsys):
    argv = [
        "gen2",
        "--scenes",
        "2",
        "--objects",
        "3",
        "--seed",
        "5",
        "--workers",
        "1",
        "--quiet",
        "--out",
        str(tmp_path),
    ]
    assert run_cli(lambda a: main(a, job=cheap_job), argv) == 0
    printed = capsys.readouterr().out
    assert "Table III" in printed and "| 3 objects | HLP | 2 |" in printed
    wrote = next(line for line in printed.splitlines() if line.startswith("wrote "))
    written = {Path(name).name for name in wrote.removeprefix("wrote ").split(", ")}
    assert written == {p.name for p in tmp_path.iterdir()} >= {"config.json", "run.json", "summary.md"}
    assert "| condition | ratio HLP / STO of the mean total times |" in printed
    run = json.loads((tmp_path / "run.json").read_text())
    assert run["command"].startswith("python -m hlp_drake.experiments gen2 --scenes 2")
    with invoked_as("hlp-drake experiments"):
        assert run_cli(lambda a: main(a, job=never_called), argv) == 0
    run = json.loads((tmp_path / "run.json").read_text())
    assert run["command"].startswith("hlp-drake experiments gen2 --scenes 2")
    assert run["seeds"] == {"first": 5, "last": 6, "scenes": 2} and run["status"] == "complete"
    assert run["software"]["drake"] and run["software"]["numpy"] and run["machine"]["cpu_count"]
    assert "optimiser:" in run["scenario"] and "scene:" in run["scenario"]


def test_cli_end_to_end_with_the_real_planners(tmp_path):
    config = tmp_path / "scenario.yaml"  # a small optimiser budget keeps the test's time bounded
    config.write_text("optimiser:\n  max_iterations: 2\n  samples: 2\n  time_budget_s: 10.0\n  workers: 1\n")
    out = tmp_path / "out"
    result = run_module(
        "hlp_drake.experiments",
        "gen1",
        "--scenes",
        "1",
        "--workers",
        "1",
        "--quiet",
        "--config",
        str(config),
        "--out",
        str(out),
    )
    assert result.returncode == 0, result.stderr
    rows = assert_well_formed(out / "results.csv")
    assert [(r["scene"], r["planner"]) for r in rows] == [("gen1-0", "hlp"), ("gen1-0", "sto")]
    for row in rows:
        assert not row["failure_reason"].startswith("crashed"), row["failure_reason"]
        assert float(row["init_s"]) > 0 and float(row["execute_s"]) > 0 and int(row["objects"]) == 6
        assert int(row["iterations"]) <= 2
    assert "max_iterations: 2" in json.loads((out / "run.json").read_text())["scenario"]
    assert "Table II" in result.stdout and (out / "times.png").exists()


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

    job = Job("gen1", 0, 6, "gen1-0", "hlp", Scenario().updated("planner: {low_level: {workers: 1}}").yaml)

    def failing_check(scenario, *, pool, **kwargs):
        assert scenario.scene.name == "gen1-0" and scenario.planner.kind == "hlp" and pool.workers == 1
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


def test_perception_camera_is_part_of_the_runs_scenario_and_summary(tmp_path, capsys):
    argv = ["gen2", "--scenes", "1", "--objects", "3", "--workers", "1", "--quiet", "--out", str(tmp_path)]
    assert run_cli(lambda a: main(a, job=cheap_job), [*argv, "--perception", "camera"]) == 0
    assert "through the cameras (perception: camera)" in capsys.readouterr().out
    run = json.loads((tmp_path / "run.json").read_text())
    assert "source: camera" in run["scenario"]
    # The same directory with the true scenes is another run: refused.
    assert run_cli(lambda a: main(a, job=never_called), [*argv, "--perception", "truth"]) == 2
    assert "different scenario" in capsys.readouterr().err


def test_without_a_terminal_progress_is_a_line_per_job_without_carriage_returns(tmp_path, capsys):
    argv = ["gen1", "--scenes", "2", "--seed", "5", "--workers", "1", "--out", str(tmp_path)]
    assert run_cli(lambda a: main(a, job=cheap_job), argv) == 0  # stderr is captured: no terminal
    err = capsys.readouterr().err
    assert "\r" not in err
    rows = {(r["scene"], r["planner"]): r["success"] for r in read_rows(tmp_path / "results.csv")}
    assert err.splitlines() == [
        f"gen1: {n} of 4 jobs done ({scene} {planner}: "
        f"{'success' if rows[scene, planner] == 'true' else 'failure'})"
        for n, (scene, planner) in enumerate(
            [("gen1-5", "hlp"), ("gen1-5", "sto"), ("gen1-6", "hlp"), ("gen1-6", "sto")], 1
        )
    ]
    assert run_cli(lambda a: main(a, job=never_called), [*argv, "--quiet"]) == 0
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize(("executor", "verbose"), [("local", False), ("local", True), ("dask", False)])
def test_drake_info_lines_from_worker_processes_only_with_verbose(
    tmp_path, capfd, monkeypatch, executor, verbose
):
    """Each job logs a Drake INFO line in a worker process (spawned, or dask's): like the command's
    own, it reaches stderr only with --verbose (the workers inherit the choice)."""
    if executor == "dask":
        pytest.importorskip("distributed")
    monkeypatch.setenv("DRAKE_ALLOW_NETWORK", "meshcat")  # the job's MeshCat server, a local one
    monkeypatch.delenv(DRAKE_LOG, raising=False)  # the command sets it; restored afterwards
    argv = ["gen1", "--scenes", "1", "--workers", "2", "--executor", executor, "--out", str(tmp_path)]
    assert run_cli(lambda a: main(a, job=drake_info_job), [*argv, *(["--verbose"] if verbose else [])]) == 0
    err = capfd.readouterr().err  # the workers' stderr too: they write to the same file descriptor
    info = [line for line in err.splitlines() if line.startswith("INFO:drake:")]
    if verbose:
        assert len(info) == 2 and all("Meshcat listening for connections" in line for line in info), err
    else:
        assert info == [] and "INFO" not in err, err
        assert [line.split(" (")[0] for line in err.splitlines()] == [
            f"gen1: {n} of 2 jobs done" for n in (1, 2)
        ]


def test_run_json_and_the_summary_say_what_ran(tmp_path, capsys):
    config = tmp_path / "scenario.yaml"
    config.write_text("planner: {low_level: {samples: 2}}\n")
    out = tmp_path / "out"
    argv = ["gen1", "--scenes", "1", "--workers", "1", "--quiet", "--config", str(config), "--out", str(out)]
    argv += ["--execution", "closed", "--uncertainty", "4"]
    assert run_cli(lambda a: main(a, job=cheap_job), argv) == 0
    printed = capsys.readouterr().out
    ran = {
        "robot": MOBILE_UR5.name,
        "planners": ["hlp", "sto"],
        "execution": "closed",
        "model_error_seed": 4,
        "perception_source": "truth",
        "scenario_file": str(config),
    }
    run = json.loads((out / "run.json").read_text())
    summary = json.loads((out / "summary.json").read_text())
    assert {key: run[key] for key in ran} == ran == {key: summary[key] for key in ran}
    line = (
        f"Ran: robot {MOBILE_UR5.name}, planners hlp and sto, execution closed, model error seed 4, "
        f"perception truth, scenario {config}."
    )
    assert line in (out / "summary.md").read_text() and line in printed
    # Without a scenario file: the built-in default (null in the JSON).
    run_cli(
        lambda a: main(a, job=cheap_job),
        ["gen1", "--scenes", "1", "--workers", "1", "--quiet", "--out", str(tmp_path / "b")],
    )
    assert json.loads((tmp_path / "b" / "summary.json").read_text())["scenario_file"] is None
    assert "model error none, perception truth, scenario built-in default." in capsys.readouterr().out


@pytest.mark.slow
def test_gen2_on_perceived_scenes_with_the_real_planners(tmp_path):
    config = tmp_path / "scenario.yaml"
    config.write_text("optimiser:\n  max_iterations: 2\n  samples: 2\n  time_budget_s: 10.0\n  workers: 1\n")
    out = tmp_path / "out"
    args = ("gen2", "--scenes", "1", "--objects", "9", "--workers", "1", "--quiet", "--config", str(config))
    result = run_module("hlp_drake.experiments", *args, "--perception", "camera", "--out", str(out))
    assert result.returncode == 0, result.stderr
    rows = assert_well_formed(out / "results.csv")
    assert [(r["scene"], r["planner"]) for r in rows] == [("gen2-9-0", "hlp"), ("gen2-9-0", "sto")]
    for row in rows:
        assert not row["failure_reason"].startswith(("crashed", "perception failed")), row["failure_reason"]
    assert "perception: camera" in (out / "summary.md").read_text()


def process_of(job: Job) -> int:
    """The id of the process that ran ``job``."""
    return os.getpid()


def test_local_pool_workers_are_renewed_every_jobs_per_worker_jobs(monkeypatch):
    from hlp_drake.experiments import executors

    jobs = [Job("gen2", seed, 3, f"gen2-3-{seed}", "hlp", "") for seed in range(6)]
    monkeypatch.setattr(executors, "JOBS_PER_WORKER", 2)
    pids = [pid for _, pid in executors.run_jobs(process_of, jobs, workers=2)]
    assert len(pids) == 6 and os.getpid() not in pids
    chunks = [set(pids[:4]), set(pids[4:])]  # 2 jobs per worker, 2 workers: fresh ones after 4 jobs
    assert not chunks[0] & chunks[1]


def test_another_robots_tables_are_the_runs_scenes_and_part_of_its_identity(tmp_path, capsys):
    from hlp_drake.systems.world.robot_description import load_robot

    workspaces = []

    def job(job: Job) -> dict:
        workspaces.append(job.workspace)
        return cheap_job(job)

    argv = ["gen2", "--objects", "7", "--scenes", "2", "--workers", "1", "--quiet", "--out", str(tmp_path)]
    assert run_cli(lambda a: main(a, job=job), [*argv, "--tables", "panda"]) == 0
    assert workspaces == [load_robot("panda").workspace] * 4  # the mobile UR5 on the Panda's tables
    assert "robot mobile_ur5" in capsys.readouterr().out
    run = json.loads((tmp_path / "run.json").read_text())
    assert run["robot"] == "mobile_ur5" and run["tables"] == "panda"
    assert "scenario built-in default, tables of panda." in (tmp_path / "summary.md").read_text()
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert (
        plot_title(summary)
        == "Table III: Generalization II, mobile_ur5 on panda's tables (2 scenes per condition)"
    )
    assert run_cli(lambda a: main(a, job=job), argv) == 2  # its own tables: other scenes, refused
    assert "different tables" in capsys.readouterr().err
    resumed = [*argv, "--tables", "panda"]  # all rows kept: nothing runs again
    assert run_cli(lambda a: main(a, job=never_called), resumed) == 0
    assert run_cli(lambda a: main(a, job=job), [*argv, "--tables", "no_such_robot"]) == 2
    assert capsys.readouterr().err.strip().startswith("error: --tables: robot 'no_such_robot'")


def test_a_bars_value_label_stays_clear_of_the_papers_diamond_at_its_top(monkeypatch, tmp_path):
    """Ours 96 %, the paper's 93 %: the diamond sits near the bar's top, the value at half height."""
    from hlp_drake.experiments import plots

    def stats(ours: float, paper: float) -> dict:
        return {
            "n": 100,
            "success_pct": ours,
            "success_ci95": [ours - 6, ours + 2],
            "paper": {"success_pct": paper},
        }

    summary = {
        "table": "Table III: Generalization II",
        "robot": "iiwa14",
        "conditions": [{"condition": "7 objects", "planners": {"hlp": stats(96, 93), "sto": stats(91, 96)}}],
    }
    figures = []
    monkeypatch.setattr(plots, "save_png", lambda figure, path: figures.append(figure))
    plots.plot_success(summary, tmp_path / "success.png")
    (axes,) = figures[0].axes
    plots.plt.close(figures[0])
    labels = {text.get_text(): text.xy[1] for text in axes.texts}
    assert labels == {"96": 48.0, "91": 45.5}
    for value in (93, 96):  # the paper's diamonds, 45 or more points above either label
        assert all(abs(value - y) > 40 for y in labels.values())
