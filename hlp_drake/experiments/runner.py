"""One experiment job: plan and execute one scene in one cell of a study's grid, reduced to a
``results.csv`` row.

A job is a pure function of its ``Job`` (the scene's generator, seed and object count, the cell,
the scenario YAML), so the same job gives the same outcome in this process, a local worker process
or a dask worker. The real job and the reading of the study's scenario are Drake's
(``hlp_drake.systems.execution.job``): this module only defines what they take and give, and worker
processes are spawned and import what they run.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

from hlp_drake.config.what_ran import Labels, WhatRan
from hlp_drake.errors import SceneError
from hlp_drake.experiments.study import Cell, Study
from hlp_drake.runtime.terminal import counted
from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.model import Scene
from hlp_drake.scene.workspace import Workspace

Row = dict[str, Any]
"""One ``results.csv`` row: the columns of ``hlp_drake.experiments.results.COLUMNS``."""


@dataclass(frozen=True)
class ResolvedCell:
    """A cell of the grid, checked against the scenario: its ``labels``, the ``workspace`` its
    tables are kept within (a fixed robot's reach, or the study's ``tables`` robot's) and the
    rollout ``workers`` of its jobs' low-level planner (1 when jobs run side by side: no nested
    pools; None: the scenario's)."""

    cell: Cell
    labels: Labels
    workspace: Workspace | None = None
    workers: int | None = None


@dataclass(frozen=True)
class Job:
    """One (scene, cell) run: everything its outcome depends on, in picklable plain values."""

    generator: str
    seed: int
    count: int | None  # the generator's object count (None: its fixed count)
    objects: int  # the scene's number of obstacles
    scene: str  # the scene's name, e.g. "gen1-3" or "gen2-7-12"
    cell: ResolvedCell
    config_yaml: str  # the scenario as YAML text (``Scenario.yaml``; its scene is replaced)

    @property
    def planner(self) -> str:
        """The pair's name (``Labels.planner``)."""
        return self.cell.labels.planner

    @property
    def key(self) -> tuple:
        """The job's identity in ``results.csv`` (``row_key`` of its row)."""
        labels = self.cell.labels
        return (
            self.scene,
            self.objects,
            labels.robot,
            labels.initial,
            labels.low_level,
            labels.execution,
            labels.perception,
            labels.model_error,
            labels.world,
        )

    def make_scene(self) -> Scene:
        return generate_scene(self.generator, self.seed, self.count, self.cell.workspace)


JobFunction = Callable[[Job], Row]
"""What an experiment runs per job: a picklable module-level function ``Job -> Row``
(``hlp_drake.systems.run_job`` runs the real planners)."""


@dataclass(frozen=True)
class ResolvedStudy:
    """A study's scenario and cells, checked, as plain values.

    Attributes:
        scenario: the scenario as YAML (part of the run's identity, in ``config.json`` and
            ``run.json``; the jobs' ``Job.config_yaml``).
        cells: every cell of the grid, resolved.
        ran: what its jobs run: the robots, initialisers, low-level planners, execution modes, model
            errors and perception sources, and the tables' robot.
    """

    scenario: str
    cells: tuple[ResolvedCell, ...]
    ran: WhatRan


class StudyResolver(Protocol):
    """Reads a study's scenario and checks its cells (``hlp_drake.systems.resolve_study`` is the real
    one): ``config_yaml`` the scenario settings (None: the defaults); ``single_process_rollouts``:
    the jobs' low-level planner rolls out in its own process. Raises ``HlpError`` for an invalid
    scenario or cell."""

    def __call__(
        self, study: Study, config_yaml: str | None, *, single_process_rollouts: bool
    ) -> ResolvedStudy: ...


def make_jobs(study: Study, resolved: ResolvedStudy) -> list[Job]:
    """Every (scene, cell) job, ordered by (generator, object count, seed, cell).

    Raises:
        SceneError: a scene cannot be generated (the message names its seed).
    """
    jobs, scenes = [], {}
    for generator in study.generators:
        for count in study.counts(generator):
            for seed in range(study.seed, study.seed + study.scenes):
                for cell in resolved.cells:
                    key = (generator, seed, count, cell.workspace)
                    if key not in scenes:
                        scenes[key] = _scene(*key)
                    scene = scenes[key]
                    jobs.append(
                        Job(generator, seed, count, len(scene.obstacles), scene.name, cell, resolved.scenario)
                    )
    return jobs


def _scene(generator: str, seed: int, count: int | None, workspace: Workspace | None) -> Scene:
    """The generated scene (``SceneError`` naming the seed and count if it cannot be made)."""
    try:
        return generate_scene(generator, seed, count, workspace)
    except SceneError as error:
        objects = "" if count is None else f" with {counted(count, 'object')}"
        raise SceneError(f"cannot generate the {generator} scene of seed {seed}{objects}: {error}") from None


def make_row(
    job: Job,
    *,
    success: bool,
    failure_reason: str | None,
    plan_s: float,
    ik_s: float,
    optimise_s: float,
    execute_s: float,
    rollouts: int,
    iterations: int,
    objects_moved: int,
    objects_dropped: int,
    verifications: int = 0,
    rejected: int = 0,
    verify_s: float = 0.0,
    model_success: bool = False,
    replans: int = 0,
    replan_rollouts: int = 0,
    grasp_held: bool | None = None,
    fallback: bool = False,
) -> Row:
    """The row of ``job``'s outcome: init = plan + IK, total = init + low-level planning (execution
    excluded), then the cell's labels, the grasp (None: not attempted) and whether the low-level
    planner fell back to a relaxed problem."""
    init_s = plan_s + ik_s
    labels = job.cell.labels
    return {
        "scene": job.scene,
        "objects": job.objects,
        "planner": labels.planner,
        "success": bool(success),
        "failure_reason": failure_reason,
        "init_s": init_s,
        "optimise_s": optimise_s,
        "total_s": init_s + optimise_s,
        "rollouts": int(rollouts),
        "objects_moved": int(objects_moved),
        "objects_dropped": int(objects_dropped),
        "seed": job.seed,
        "iterations": int(iterations),
        "verifications": int(verifications),
        "rejected": int(rejected),
        "verify_s": verify_s,
        "model_success": bool(model_success),
        "false_accept": bool(model_success) and not success,
        "replans": int(replans),
        "replan_rollouts": int(replan_rollouts),
        "execute_s": execute_s,
        "generator": job.generator,
        "robot": labels.robot,
        "initial": labels.initial,
        "low_level": labels.low_level,
        "execution": labels.execution,
        "perception": labels.perception,
        "model_error": labels.model_error,
        "world": labels.world,
        "grasp_held": None if grasp_held is None else bool(grasp_held),
        "fallback": bool(fallback),
    }


def crash_row(job: Job, reason: str) -> Row:
    """The row of a job that crashed (``reason``: "crashed: ...", one line): a failure, its times NaN
    (unknown: left out of the means) and its counts 0."""
    nan = float("nan")
    return make_row(
        job,
        success=False,
        failure_reason=" ".join(reason.split())[:300],
        plan_s=nan,
        ik_s=nan,
        optimise_s=nan,
        execute_s=nan,
        verify_s=nan,
        rollouts=0,
        iterations=0,
        objects_moved=0,
        objects_dropped=0,
    )


__all__ = [
    "Job",
    "JobFunction",
    "Labels",
    "ResolvedCell",
    "ResolvedStudy",
    "Row",
    "StudyResolver",
    "crash_row",
    "make_jobs",
    "make_row",
]
