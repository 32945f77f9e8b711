"""``python -m hlp_drake.experiments`` as a user runs it: bad input and damaged run folders (one line, exit
2, nothing written), what a run says it ran, progress, another robot's tables, the real planners."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from conftest import run_module
from job_support import (
    OUTPUTS,
    assert_well_formed,
    cheap_job,
    drake_info_job,
    never_called,
    read_rows,
    run_experiment,
    settings,
)

from hlp_drake import DRAKE_LOG
from hlp_drake.commands.experiments import main
from hlp_drake.commands.parsing import invoked_as, run_cli
from hlp_drake.errors import HlpError
from hlp_drake.experiments import Job
from hlp_drake.experiments.plots import plot_title
from hlp_drake.experiments.results import COLUMNS, read_results
from hlp_drake.systems.world.robot_description import MOBILE_UR5


def test_a_run_folder_of_an_earlier_version_is_refused_with_how_to_start_over(tmp_path, capsys):
    run_experiment(settings(), tmp_path, job=cheap_job)
    (tmp_path / "config.json").write_text('{"kind": "gen1", "seed": 10, "scenario": "x"}')
    argv = ["gen1", "--scenes", "3", "--seed", "10", "--workers", "1", "--quiet", "--out", str(tmp_path)]
    assert run_cli(lambda a: main(a, job=never_called), argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "written by an earlier version" in err and "--fresh" in err
    (tmp_path / "results.csv").write_text("scene,planner\ngen1-0,hlp\n")
    with pytest.raises(HlpError, match="unexpected columns"):
        read_results(tmp_path / "results.csv")


def test_a_different_run_in_the_directory_is_refused_unless_fresh(tmp_path, capsys):
    run_experiment(settings(), tmp_path, job=cheap_job)
    before = {name: (tmp_path / name).read_bytes() for name in OUTPUTS}
    argv = ["gen1", "--scenes", "2", "--seed", "20", "--workers", "1", "--quiet", "--out", str(tmp_path)]
    assert run_cli(lambda a: main(a, job=cheap_job), argv) == 2
    message = capsys.readouterr().err.strip()
    assert message.count("\n") == 0 and "different grid or scenes (gen1 from seed 10)" in message
    assert "--fresh" in message
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
        ["gen1", "--planner", "astar"],
        ["gen1", "--low-level", "astar"],
        ["missing.yaml"],
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


@pytest.mark.parametrize(
    ("lines", "expected"),
    [
        ("robots: [nosuch]", "robots: unknown robot 'nosuch' (shipped: mobile_ur5"),
        ("tables: nosuch", "tables: unknown robot 'nosuch'"),
        ("model_error: [-3]", "model_error: each seed between 0 and"),
        ("low_level: [astar]", "low_level: unknown 'astar' (known: sto"),
        ("initialisers: [rrt]", "initialisers: unknown 'rrt'"),
        ("scenes: 0", "scenes"),
    ],
)
def test_a_bad_study_file_is_one_line_naming_the_file_and_field(tmp_path, capsys, lines, expected):
    study = tmp_path / "study.yaml"
    study.write_text(f"name: t\ngenerators: [gen1]\n{lines}\n")
    out = tmp_path / "out"
    assert run_cli(lambda a: main(a, job=never_called), [str(study), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"error: {study}: ") and expected in err and err.count("\n") == 1
    assert not out.exists()


@pytest.mark.parametrize("text", ["", "\n", "# nothing yet\n"])
def test_an_empty_study_file_is_refused_not_read_as_the_default_study(tmp_path, capsys, text):
    study = tmp_path / "study.yaml"
    study.write_text(text)
    out = tmp_path / "out"
    assert run_cli(lambda a: main(a, job=never_called), [str(study), "--out", str(out)]) == 2
    assert (
        capsys.readouterr().err
        == f"error: {study}: the file is empty; a study gives its scenes and the conditions to run on them\n"
    )
    assert not out.exists()


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
        (
            "results.csv",
            lambda t: _bad_row(t, "generator", "gen7"),
            "generator 'gen7', not one of the study's",
        ),
        ("results.csv", lambda t: _bad_row(t, "model_error", "many"), "malformed row"),
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


def test_dask_not_installed_says_how_to_install_it(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(__import__("sys").modules, "distributed", None)  # makes "import distributed" fail
    out = tmp_path / "out"
    argv = ["gen1", "--executor", "dask", "--out", str(out)]
    assert run_cli(lambda a: main(a, job=never_called), argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and 'pip install "hlp_drake[cluster]"' in err and not out.exists()


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
    assert "| 3 objects | HLP / STO (straight line) |" in printed
    run = json.loads((tmp_path / "run.json").read_text())
    assert run["command"].startswith("python -m hlp_drake.experiments gen2 --scenes 2")
    with invoked_as("hlp-drake experiments"):
        assert run_cli(lambda a: main(a, job=never_called), argv) == 0
    run = json.loads((tmp_path / "run.json").read_text())
    assert run["command"].startswith("hlp-drake experiments gen2 --scenes 2")
    assert run["seeds"] == {"first": 5, "last": 6, "scenes": 2} and run["status"] == "complete"
    assert run["software"]["drake"] and run["software"]["numpy"] and run["machine"]["cpu_count"]
    assert "low_level:" in run["scenario"] and "scene:" in run["scenario"]
    assert run["study"]["name"] == "gen2" and run["study"]["objects"] == [3]


def test_cli_end_to_end_with_the_real_planners(tmp_path):
    config = tmp_path / "scenario.yaml"  # a small optimiser budget keeps the test's time bounded
    config.write_text(
        "planner:\n  low_level:\n    max_iterations: 2\n    samples: 2\n    time_budget_s: 10.0\n    workers: 1\n"
    )
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


def test_perception_camera_is_part_of_the_runs_scenario_and_summary(tmp_path, capsys):
    argv = ["gen2", "--scenes", "1", "--objects", "3", "--workers", "1", "--quiet", "--out", str(tmp_path)]
    assert run_cli(lambda a: main(a, job=cheap_job), [*argv, "--perception", "camera"]) == 0
    assert "through the cameras (perception: camera)" in capsys.readouterr().out
    run = json.loads((tmp_path / "run.json").read_text())
    assert run["perception_source"] == "camera" and run["study"]["perception"] == ["camera"]
    assert {r["perception"] for r in read_rows(tmp_path / "results.csv")} == {"camera"}
    # The same directory with the true scenes is another run: refused.
    assert run_cli(lambda a: main(a, job=never_called), [*argv, "--perception", "truth"]) == 2
    assert "different grid or scenes" in capsys.readouterr().err


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
        "initials": ["hlp", "line"],
        "low_level": "sto",
        "execution": "closed",
        "model_error_seed": 4,
        "perception_source": "truth",
        "world": "reference",
        "scenario_file": str(config),
    }
    run = json.loads((out / "run.json").read_text())
    summary = json.loads((out / "summary.json").read_text())
    assert {key: run[key] for key in ran} == ran == {key: summary[key] for key in ran}
    line = (
        f"Ran: robot {MOBILE_UR5.name}, initialisers hlp and line, low-level planner sto, execution closed, "
        f"model error seed 4, perception truth, world reference, scenario {config}."
    )
    assert line in (out / "summary.md").read_text() and line in printed
    # Without a scenario file: the built-in default (null in the JSON).
    run_cli(
        lambda a: main(a, job=cheap_job),
        ["gen1", "--scenes", "1", "--workers", "1", "--quiet", "--out", str(tmp_path / "b")],
    )
    assert json.loads((tmp_path / "b" / "summary.json").read_text())["scenario_file"] is None
    assert (
        "model error none, perception truth, world reference, scenario built-in default."
        in capsys.readouterr().out
    )


@pytest.mark.slow
def test_gen2_on_perceived_scenes_with_the_real_planners(tmp_path):
    config = tmp_path / "scenario.yaml"
    config.write_text(
        "planner:\n  low_level:\n    max_iterations: 2\n    samples: 2\n    time_budget_s: 10.0\n    workers: 1\n"
    )
    out = tmp_path / "out"
    args = ("gen2", "--scenes", "1", "--objects", "9", "--workers", "1", "--quiet", "--config", str(config))
    result = run_module("hlp_drake.experiments", *args, "--perception", "camera", "--out", str(out))
    assert result.returncode == 0, result.stderr
    rows = assert_well_formed(out / "results.csv")
    assert [(r["scene"], r["planner"]) for r in rows] == [("gen2-9-0", "hlp"), ("gen2-9-0", "sto")]
    for row in rows:
        assert not row["failure_reason"].startswith(("crashed", "perception failed")), row["failure_reason"]
    assert "perception: camera" in (out / "summary.md").read_text()


def test_another_robots_tables_are_the_runs_scenes_and_part_of_its_identity(tmp_path, capsys):
    from hlp_drake.systems.world.robot_description import load_robot

    workspaces = []

    def job(job: Job) -> dict:
        workspaces.append(job.cell.workspace)
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
    assert "different grid or scenes" in capsys.readouterr().err
    resumed = [*argv, "--tables", "panda"]  # all rows kept: nothing runs again
    assert run_cli(lambda a: main(a, job=never_called), resumed) == 0
    assert run_cli(lambda a: main(a, job=job), [*argv, "--tables", "no_such_robot"]) == 2
    assert capsys.readouterr().err.strip().startswith("error: --tables: unknown robot 'no_such_robot'")
