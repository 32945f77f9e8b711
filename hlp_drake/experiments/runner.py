"""One experiment job: plan and execute one scene with one planner, reduced to a ``results.csv`` row.

A job is a pure function of its ``Job`` (kind, seed, object count, planner, scenario YAML), so the
same job gives the same outcome in this process, a local worker process or a dask worker. Drake is
imported inside ``run_job`` only: worker processes are spawned and import what they run.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace
from typing import Any

from hlp_drake.errors import SceneError
from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.model import Scene

PLANNERS = ("hlp", "sto")  # the planners of Tables II and III: human-like plan; STO's straight line
KINDS = ("gen1", "gen2")  # Generalization I (Table II) and II (Table III)

Row = dict[str, Any]
"""One ``results.csv`` row: the columns of ``hlp_drake.experiments.results.COLUMNS``."""


@dataclass(frozen=True)
class Job:
    """One (scene, planner) run: everything its outcome depends on, in picklable plain values."""

    kind: str
    seed: int
    objects: int  # the scene's number of obstacles
    scene: str  # the scene's name, e.g. "gen1-3" or "gen2-7-12"
    planner: str
    config_yaml: (
        str  # the scenario as YAML text (``Scenario.yaml``; its scene is replaced), not a Drake object
    )

    @property
    def key(self) -> tuple[str, str]:
        """The job's identity in ``results.csv``: (scene, planner)."""
        return self.scene, self.planner

    def make_scene(self) -> Scene:
        return generate_scene(self.kind, self.seed, self.objects)


JobFunction = Callable[[Job], Row]
"""What an experiment runs per job: a picklable module-level function ``Job -> Row``."""


def make_jobs(kind: str, seeds: Iterable[int], objects: Iterable[int], config_yaml: str) -> list[Job]:
    """Every (scene, planner) job, ordered by (objects, seed, planner).

    gen2: one scene per (object count, seed); gen1: one scene per seed (``objects`` is ignored).

    Raises:
        SceneError: a scene cannot be generated (the message names its seed).
    """
    counts = [None] if kind == "gen1" else sorted(set(objects))
    jobs = []
    for count in counts:
        for seed in seeds:
            try:
                scene = generate_scene(kind, seed, count)
            except SceneError as error:
                objects_note = "" if count is None else f" with {count} objects"
                raise SceneError(
                    f"cannot generate the {kind} scene of seed {seed}{objects_note}: {error}"
                ) from None
            jobs += [
                Job(kind, seed, len(scene.obstacles), scene.name, planner, config_yaml)
                for planner in PLANNERS
            ]
    return jobs


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
    passed_then_failed: bool = False,
    replans: int = 0,
    replan_rollouts: int = 0,
) -> Row:
    """The row of ``job``'s outcome: init = plan + IK, total = init + optimise (execution excluded)."""
    init_s = plan_s + ik_s
    return {
        "scene": job.scene,
        "objects": job.objects,
        "planner": job.planner,
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
        "passed_then_failed": bool(passed_then_failed),
        "replans": int(replans),
        "replan_rollouts": int(replan_rollouts),
        "execute_s": execute_s,
    }


def run_job(job: Job) -> Row:
    """Plan and execute ``job``'s scene in the Drake world.

    An exception (or one of Drake's internal checks failing, which pydrake raises as ``SystemExit``)
    is recorded as this planner's failure on this scene ("crashed: ..."), its times as NaN (left
    out of the means), rather than ending the run. The bundled decision models are loaded
    before the timed call, so a worker's first scene is not charged for loading them, and
    every job has a rollout pool of its own: no job uses rollout worlds an earlier one (maybe the
    other planner on the same scene) built.
    """
    from hlp_drake.learners.bundled import default_models
    from hlp_drake.systems.execution.run import plan_and_execute
    from hlp_drake.systems.optimiser.pool import RolloutPool
    from hlp_drake.systems.optimiser.rollout_world import simulation_failure
    from hlp_drake.systems.scenario import load_scenario

    settings = load_scenario(data=job.config_yaml, where="the job's scenario")
    try:
        scenario = replace(
            settings, scene=job.make_scene(), planner=replace(settings.planner, kind=job.planner)
        )
        with RolloutPool(scenario.optimiser.workers) as pool:
            result = plan_and_execute(scenario, pool=pool, models=default_models())
    except (Exception, SystemExit) as error:  # noqa: BLE001 - a crash is this planner's failure here
        if isinstance(error, SystemExit):
            simulation_failure(error)  # raises it again unless it is Drake's
        reason = " ".join(f"crashed: {type(error).__name__}: {error}".split())[:300]
        nan = float("nan")
        return make_row(
            job,
            success=False,
            failure_reason=reason,
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
