"""One experiment job: plan and execute one scene with one planner, reduced to a ``results.csv`` row.

A job is a pure function of its ``Job`` (kind, seed, object count, planner, scenario YAML), so the
same job gives the same outcome in this process, a local worker process or a dask worker. The real
job and the scenario reading are Drake's (``hlp_drake.systems.execution.job``): this module only
defines what they take and give, and worker processes are spawned and import what they run.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any, Protocol

from hlp_drake.config.what_ran import WhatRan
from hlp_drake.errors import SceneError
from hlp_drake.scene.generators import generate_scene
from hlp_drake.scene.model import Scene
from hlp_drake.scene.workspace import Workspace

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
    workspace: Workspace | None = None  # a fixed robot's reach, which the scene's table is kept within

    @property
    def key(self) -> tuple[str, str]:
        """The job's identity in ``results.csv``: (scene, planner)."""
        return self.scene, self.planner

    def make_scene(self) -> Scene:
        return generate_scene(self.kind, self.seed, self.objects, self.workspace)


JobFunction = Callable[[Job], Row]
"""What an experiment runs per job: a picklable module-level function ``Job -> Row``
(``hlp_drake.systems.run_job`` runs the real planners)."""


@dataclass(frozen=True)
class ScenarioYamls:
    """A run's scenario, read once, as plain values.

    Attributes:
        identity: the scenario as YAML (the run's identity, in ``config.json`` and ``run.json``).
        job: the scenario as the jobs run it, as YAML (``Job.config_yaml``).
        ran: what its jobs run: the robot, both planners, the execution mode, the model error's seed
            and the perception source (no scenario file: the run's settings name it).
        workspace: the robot's reach if it is fixed (the generated tables are kept within it).
    """

    identity: str
    job: str
    ran: WhatRan
    workspace: Workspace | None = None

    @property
    def perception_source(self) -> str:
        """The scenario's ``perception.source`` ("truth" or "camera")."""
        return self.ran.perception_source


class ScenarioResolver(Protocol):
    """Reads a run's scenario (``hlp_drake.systems.scenario_yamls`` is the real one).

    ``text``: the scenario settings as YAML (None: the defaults); ``perception`` overrides its
    ``perception.source`` and ``robot`` its robot (a shipped robot's name or a description file)
    unless None; ``tables``: the generated tables are kept within that robot's reach instead;
    ``single_process_rollouts``: the jobs' optimiser rolls out in its own process
    (``optimiser.workers = 1``). Raises ``HlpError`` for an invalid scenario.
    """

    def __call__(
        self,
        text: str | None,
        *,
        single_process_rollouts: bool,
        perception: str | None,
        robot: str | None = None,
        tables: str | None = None,
    ) -> ScenarioYamls: ...


def make_jobs(
    kind: str,
    seeds: Iterable[int],
    objects: Iterable[int],
    config_yaml: str,
    workspace: Workspace | None = None,
) -> list[Job]:
    """Every (scene, planner) job, ordered by (objects, seed, planner).

    gen2: one scene per (object count, seed); gen1: one scene per seed (``objects`` is ignored);
    the tables within ``workspace`` (a fixed robot's reach).

    Raises:
        SceneError: a scene cannot be generated (the message names its seed).
    """
    counts = [None] if kind == "gen1" else sorted(set(objects))
    jobs = []
    for count in counts:
        for seed in seeds:
            try:
                scene = generate_scene(kind, seed, count, workspace)
            except SceneError as error:
                objects_note = "" if count is None else f" with {count} objects"
                raise SceneError(
                    f"cannot generate the {kind} scene of seed {seed}{objects_note}: {error}"
                ) from None
            jobs += [
                Job(kind, seed, len(scene.obstacles), scene.name, planner, config_yaml, workspace)
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
