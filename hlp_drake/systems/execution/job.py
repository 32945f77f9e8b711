"""The Drake side of an experiment (``hlp_drake.experiments``): its scenario and its real job.

``python -m hlp_drake.experiments`` hands both to ``run_experiment``: ``scenario_yamls`` reads the
run's scenario once, ``run_job`` plans and executes one (scene, planner) job. ``run_job`` is a
module-level function, so process pools and dask workers can unpickle it.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

from hlp_drake.errors import HlpError
from hlp_drake.learners.bundled import default_models
from hlp_drake.systems.execution.result import what_ran
from hlp_drake.systems.execution.run import plan_and_execute
from hlp_drake.systems.low_level.sto.pool import RolloutPool
from hlp_drake.systems.low_level.sto.rollout_world import simulation_failure
from hlp_drake.systems.scenario import load_scenario, with_conditions
from hlp_drake.systems.world.robot_description import load_robot

if TYPE_CHECKING:
    from hlp_drake.experiments.runner import Job, Row, ScenarioYamls


def scenario_yamls(
    text: str | None,
    *,
    single_process_rollouts: bool = False,
    perception: str | None = None,
    robot: str | None = None,
    tables: str | None = None,
) -> ScenarioYamls:
    """The scenario of ``text`` (None: the defaults; ``perception.source`` set to ``perception`` and
    the robot to ``robot`` unless None), read once: its YAML (the run's identity), written out in
    full as the jobs run it (``optimiser.workers = 1`` if ``single_process_rollouts``), what its
    jobs run and the workspace the tables are kept within: the robot's, or that of ``tables`` (a
    shipped robot's name or a description file) to run this robot on another's tables.

    Raises:
        HlpError: the scenario is invalid.
    """
    # hlp_drake.experiments is imported when needed: importing hlp_drake.systems does not load it
    from hlp_drake.experiments.runner import PLANNERS, ScenarioYamls

    scenario = with_conditions(load_scenario(data=text, where="--config"), perception=perception, robot=robot)
    jobs = (
        replace(scenario, optimiser=replace(scenario.optimiser, workers=1))
        if single_process_rollouts
        else scenario
    )
    try:
        other = None if tables is None else load_robot(tables)
    except HlpError as error:
        raise HlpError(f"--tables: {error}") from None
    return ScenarioYamls(
        identity=scenario.yaml,
        job=jobs.yaml,
        ran=replace(what_ran(scenario, planners=PLANNERS), tables=other and other.name),
        workspace=(other or scenario.robot).workspace,
    )


def run_job(job: Job) -> Row:
    """Plan and execute ``job``'s scene in the Drake world.

    A scene the robot cannot run (``HlpError``, e.g. a start out of a fixed arm's reach) is this
    planner's failure with that reason; any other exception (or one of Drake's internal checks
    failing, which pydrake raises as ``SystemExit``) is recorded as its failure ("crashed: ..."), its times as NaN (left
    out of the means), rather than ending the run. The bundled decision models are loaded
    before the timed call, so a worker's first scene is not charged for loading them, and
    every job has a rollout pool of its own: no job uses rollout worlds an earlier one (maybe the
    other planner on the same scene) built.
    """
    from hlp_drake.experiments.runner import crash_row, make_row  # as in scenario_yamls

    settings = load_scenario(data=job.config_yaml, where="the job's scenario")
    try:
        scenario = replace(
            settings, scene=job.make_scene(), planner=replace(settings.planner, kind=job.planner)
        )
        with RolloutPool(scenario.optimiser.workers) as pool:
            result = plan_and_execute(scenario, pool=pool, models=default_models())
    except HlpError as error:  # the scene does not suit the robot, e.g. a start out of its reach
        return crash_row(job, str(error))
    except (Exception, SystemExit) as error:  # noqa: BLE001 - a crash is this planner's failure here
        if isinstance(error, SystemExit):
            simulation_failure(error)  # raises it again unless it is Drake's
        return crash_row(job, f"crashed: {type(error).__name__}: {error}")
    t = result.timings
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
        verifications=result.optimisation.get("verifications", 0),
        rejected=result.optimisation.get("rejected", 0),
        verify_s=result.optimisation.get("verify_s", 0.0),
        passed_then_failed=result.rollout_passed_execution_failed,
        replans=result.closed_loop.get("replans", 0),
        replan_rollouts=result.closed_loop.get("rollouts", 0),
    )
