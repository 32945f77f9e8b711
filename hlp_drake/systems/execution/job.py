"""The Drake side of an experiment (``hlp_drake.experiments``): its study's scenario and cells, and
its real job.

``python -m hlp_drake.experiments`` hands both to ``run_experiment``: ``resolve_study`` reads the
run's scenario once and checks every cell of the grid against it, ``run_job`` plans and executes one
(scene, cell) job. ``run_job`` is a module-level function, so process pools and dask workers can
unpickle it.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from hlp_drake.config.what_ran import WhatRan
from hlp_drake.errors import HlpError
from hlp_drake.learners.bundled import default_models
from hlp_drake.systems.conditions import Conditions, rollout_workers
from hlp_drake.systems.execution.result import labels_of
from hlp_drake.systems.execution.run import plan_and_execute
from hlp_drake.systems.low_level.registry import check_closed_loop
from hlp_drake.systems.low_level.sto.pool import RolloutPool
from hlp_drake.systems.scenario import load_scenario
from hlp_drake.systems.world.robot_description import load_robot
from hlp_drake.systems.world.simulation import simulation_failure

if TYPE_CHECKING:
    from hlp_drake.experiments.runner import Job, ResolvedStudy, Row
    from hlp_drake.experiments.study import Cell, Study


def conditions(cell: Cell, *, workers: int | None = None) -> Conditions:
    """The ``Conditions`` a study's ``cell`` lays over the scenario (``workers``: the rollout
    processes of a job's low-level planner; None: the scenario's)."""
    return Conditions(
        robot=cell.robot,
        initial=cell.initial,
        low_level=cell.low_level,
        execution=cell.execution,
        uncertainty=cell.model_error,
        perception=cell.perception,
        world=cell.world,
        workers=workers,
    )


def resolve_study(study: Study, config_yaml: str | None, *, single_process_rollouts: bool) -> ResolvedStudy:
    """The scenario of ``config_yaml`` (None: the defaults), read once, and every cell of ``study``
    checked against it: its labels (the robot's name, the initialiser, the low-level planner, ...)
    and the workspace its tables are kept within (the robot's, or ``study.tables``'s).

    Raises:
        HlpError: the scenario, a cell (an unknown robot, a camera source without a camera, a closed
            loop with a low-level planner that cannot re-plan) or the tables' robot is invalid.
    """
    from hlp_drake.experiments.runner import ResolvedCell, ResolvedStudy

    scenario = load_scenario(data=config_yaml, where="--config")
    try:
        tables = load_robot(study.tables) if study.tables else None
    except HlpError as error:
        raise HlpError(f"--tables: {error}") from None
    cells = []
    workers = 1 if single_process_rollouts else None  # jobs side by side: no nested pools
    for cell in study.cells():
        applied = conditions(cell).applied(scenario)
        check_closed_loop(applied.low_level.kind, closed=applied.closed_loop.enabled)
        cells.append(ResolvedCell(cell, labels_of(applied), (tables or applied.robot).workspace, workers))
    ran = WhatRan.of((c.labels for c in cells), tables=None if tables is None else tables.name)
    return ResolvedStudy(scenario.yaml, tuple(cells), ran)


def run_job(job: Job) -> Row:
    """Plan and execute ``job``'s scene in the Drake world, in its cell's conditions.

    A scene the robot cannot run (``HlpError``, e.g. a start out of a fixed arm's reach) is this
    cell's failure with that reason; any other exception (or one of Drake's internal checks
    failing, which pydrake raises as ``SystemExit``) is recorded as its failure ("crashed: ..."),
    its times as NaN (left out of the means), rather than ending the run. The bundled decision
    models are loaded before the timed call, so a worker's first scene is not charged for loading
    them, and every job has a rollout pool of its own: no job uses rollout worlds an earlier one
    (maybe another cell on the same scene) built.
    """
    from hlp_drake.experiments.runner import crash_row, make_row  # experiments is imported when needed

    settings = load_scenario(data=job.config_yaml, where="the job's scenario")
    try:
        cell = conditions(job.cell.cell, workers=job.cell.workers)
        scenario = cell.applied(settings, scene=job.make_scene())
        workers = rollout_workers(scenario)
        if workers is None:
            result = plan_and_execute(scenario, models=default_models())
        else:
            with RolloutPool(workers) as pool:
                result = plan_and_execute(scenario, pool=pool, models=default_models())
    except HlpError as error:  # the scene does not suit the robot, e.g. a start out of its reach
        return crash_row(job, str(error))
    except (Exception, SystemExit) as error:  # noqa: BLE001 - a crash is this cell's failure here
        if isinstance(error, SystemExit):
            simulation_failure(error)  # raises it again unless it is Drake's
        return crash_row(job, f"crashed: {type(error).__name__}: {error}")
    t, low_level = result.timings, result.optimisation
    return make_row(
        job,
        success=result.success,
        failure_reason=result.failure_reason,
        plan_s=t["plan_s"],
        ik_s=t["ik_s"],
        optimise_s=t.get("optimise_s", 0.0),
        execute_s=t.get("execute_s", 0.0),
        rollouts=result.rollouts,
        iterations=result.iterations,
        objects_moved=len(result.objects_moved),
        objects_dropped=len(result.objects_dropped),
        verifications=low_level.get("verifications", 0),
        rejected=low_level.get("rejected", 0),
        verify_s=low_level.get("verify_s", 0.0),
        model_success=bool(result.model_success),
        replans=result.closed_loop.get("replans", 0),
        replan_rollouts=result.closed_loop.get("rollouts", 0),
        grasp_held=result.grasp_held,
        fallback=bool(low_level.get("fallback")),
    )


__all__ = ["conditions", "resolve_study", "run_job"]
