"""``cheap_job``: a deterministic stand-in for the experiments' real job, a module-level function so
process pools and dask workers can unpickle it; ``one_job``: a job made by hand."""

from __future__ import annotations

import random

from hlp_drake.experiments import Job, make_row
from hlp_drake.experiments.runner import Labels, ResolvedCell
from hlp_drake.experiments.study import Cell
from hlp_drake.scene.generators import generate_scene


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
