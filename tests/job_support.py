"""``cheap_job``: a deterministic stand-in for the experiments' real job, a module-level function so
process pools and dask workers can unpickle it; ``one_job``: a job made by hand; ``settings`` and
``run_experiment``: a bundled study run in the test's own process."""

from __future__ import annotations

import csv
import dataclasses
import random
from pathlib import Path

from hlp_drake import experiments
from hlp_drake.experiments import ExperimentSettings, Job, make_row
from hlp_drake.experiments.results import COLUMNS
from hlp_drake.experiments.runner import JobFunction, Labels, ResolvedCell
from hlp_drake.experiments.study import Cell, load_study
from hlp_drake.scene.generators import generate_scene

REQUIRED_COLUMNS = ["scene", "objects", "planner", "success", "failure_reason", "init_s", "optimise_s"]
REQUIRED_COLUMNS += ["total_s", "rollouts", "objects_moved", "objects_dropped"]
"""The paper's columns, first in ``results.csv``."""
OUTPUTS = ("results.csv", "config.json", "run.json", "summary.md", "summary.json", "success.png", "times.png")
"""What a finished run folder holds."""


def cheap_job(job: Job) -> dict:
    """A deterministic stand-in for plan_and_execute: outcome and times drawn from (scene, planner)."""
    rng = random.Random(f"{job.scene}/{job.planner}" + "".join(f"/{v}" for v in job.key[2:] if v is not None))
    scene = job.make_scene()
    success = rng.random() < (0.9 if job.planner == "hlp" else 0.7)
    optimise_s = rng.uniform(0.5, 2.0) * (1 if job.planner == "hlp" else 10)
    return make_row(
        job,
        success=success,
        failure_reason=None if success else "the target is out of reach",
        plan_s=rng.uniform(0.01, 0.1),
        ik_s=rng.uniform(0.1, 0.5),
        optimise_s=optimise_s,
        verify_s=optimise_s * rng.uniform(0.2, 0.8),
        execute_s=rng.uniform(2, 4),
        rollouts=rng.randint(8, 80),
        iterations=rng.randint(1, 10),
        objects_moved=rng.randint(0, len(scene.obstacles)),
        objects_dropped=int(not success),
    )


def drake_info_job(job: Job) -> dict:
    """``cheap_job`` after a Drake INFO line: a MeshCat server starting (``Meshcat listening for
    connections at ...``; needs ``DRAKE_ALLOW_NETWORK=meshcat``), as a job on a worker process might log."""
    from pydrake.geometry import Meshcat, MeshcatParams

    Meshcat(MeshcatParams(host="localhost"))
    return cheap_job(job)


def one_job(config_yaml: str, generator: str, seed: int, count: int | None = None, *, workspace=None) -> Job:
    """The job of the human-like initialiser on the STO on one generated scene of the scenario
    ``config_yaml`` (its own robot, tables within ``workspace``)."""
    scene = generate_scene(generator, seed, count, workspace)
    labels = Labels("robot", "hlp", "sto", "hlp", "open", "truth", None)
    cell = ResolvedCell(Cell(initial="hlp"), labels, workspace)
    return Job(generator, seed, count, len(scene.obstacles), scene.name, cell, config_yaml)


STUDY_FIELDS = ("scenes", "seed", "objects", "robots", "initialisers", "low_level", "execution", "perception")


def settings(name: str = "gen1", **changes) -> ExperimentSettings:
    """The bundled study ``name`` (3 scenes from seed 10 unless ``changes`` say otherwise) in this
    process, the study's fields and the settings' from ``changes``."""
    defaults = {"scenes": 3, "seed": 10, "workers": 1, "progress": False, **changes}
    study = load_study(name)
    study = dataclasses.replace(study, **{k: v for k, v in defaults.items() if k in STUDY_FIELDS})
    return ExperimentSettings(study=study, **{k: v for k, v in defaults.items() if k not in STUDY_FIELDS})


def run_experiment(settings: ExperimentSettings, out: Path, *, job: JobFunction) -> dict:
    """``hlp_drake.experiments.run_experiment`` with the real study resolution and the test's ``job``."""
    from hlp_drake.systems import resolve_study

    return experiments.run_experiment(settings, out, job=job, resolve=resolve_study)


def never_called(job: Job) -> dict:
    raise AssertionError(f"{job.key} was run again")


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
