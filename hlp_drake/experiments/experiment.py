"""Run a whole study into a directory, resumably: jobs -> ``results.csv`` -> summary and plots.

The directory holds ``config.json`` (what the rows depend on: the study's grid and scenes, the
scenario settings),
``results.csv`` (rewritten atomically after every finished job), ``run.json`` (the run's settings,
what it ran, machine and software), ``summary.md``/``summary.json`` and ``success.png``/``times.png``.
Scene i of a condition has seed ``study.seed + i``. Rows already in ``results.csv`` are kept and not
run again; a job interrupted mid-way is simply run again next time.
"""

from __future__ import annotations

import contextlib
import json
import os
import sys
import time
from contextlib import closing
from dataclasses import asdict, astuple, dataclass, replace
from pathlib import Path
from typing import Any

from tqdm import tqdm

from hlp_drake.config.ranges import config_problems
from hlp_drake.config.what_ran import WhatRan
from hlp_drake.errors import HlpError, StorageError
from hlp_drake.experiments.executors import check_executor, run_jobs
from hlp_drake.experiments.metadata import git_commit, machine_info, software_versions, utc_now
from hlp_drake.experiments.plots import write_plots
from hlp_drake.experiments.results import START_OVER, ResultsFile, read_results, read_run_file, row_key
from hlp_drake.experiments.runner import Job, JobFunction, StudyResolver, make_jobs
from hlp_drake.experiments.study import EXECUTORS, Study
from hlp_drake.experiments.summary import summarise, write_summary
from hlp_drake.files.atomic import check_folder, write_text_atomic
from hlp_drake.runtime.terminal import bars_disabled

RESULTS, CONFIG, RUN = "results.csv", "config.json", "run.json"
DERIVED = ("summary.md", "summary.json", "success.png", "times.png")
OUTPUTS = (RESULTS, CONFIG, RUN, *DERIVED)
"""The files a run writes in its output folder."""
MAX_RECORD_BYTES = 16 << 20
"""A larger ``config.json`` or ``run.json`` is refused (a run's are a few kB to a few MB)."""
IDENTITY_LABELS = {"study": "grid or scenes", "scenario": "scenario"}


@dataclass(frozen=True)
class ExperimentSettings:
    """What to run and how.

    Attributes:
        study: the grid and its scenes (``Study``; ``load_study("gen1")`` is Table II).
        workers: jobs at a time (None: one per core); with more than one, or on dask, every job's
            low-level planner rolls out in its own process (no nested pools).
        executor: "local" (this process, or a spawn process pool) or "dask".
        scheduler: the dask scheduler's address (None: start a ``LocalCluster`` of ``workers``).
        config_yaml: the scenario settings as YAML text (None: ``Scenario()``'s defaults; its scene is
            replaced by each job's).
        scenario_file: the file ``config_yaml`` was read from (None: none, the built-in default), named
            in ``run.json`` and the summary.
        fresh: start over, discarding the directory's earlier results.
    """

    study: Study
    workers: int | None = None
    executor: str = "local"
    scheduler: str | None = None
    config_yaml: str | None = None
    scenario_file: str | None = None
    fresh: bool = False
    progress: bool = True

    @property
    def worker_count(self) -> int:
        return self.workers or os.cpu_count() or 1

    @property
    def parallel(self) -> bool:
        """Whether jobs run in worker processes side by side (then without nested rollout pools)."""
        return self.executor == "dask" or self.worker_count > 1

    def problems(self) -> list[str]:
        """The reasons these settings cannot run (empty when they can)."""
        problems = config_problems(self.study)
        if self.workers is not None and self.workers < 1:
            problems.append(f"--workers must be at least 1, got {self.workers}")
        if self.executor not in EXECUTORS:
            problems.append(f"unknown executor {self.executor!r} (expected one of {', '.join(EXECUTORS)})")
        if self.scheduler is not None and self.executor != "dask":
            problems.append("--scheduler needs --executor dask")
        return problems


def _check_directory(out: Path, identity: dict[str, Any], fresh: bool) -> None:
    """Refuse a directory that holds another run's results (unless ``fresh``)."""
    if fresh:
        return
    config = out / CONFIG
    if config.exists():
        earlier = _read_record(config)
        differs = [label for key, label in IDENTITY_LABELS.items() if earlier.get(key) != identity.get(key)]
        if differs:
            study = earlier.get("study")
            what = (
                f"{earlier.get('name')} from seed {study.get('seed')}"
                if isinstance(study, dict)
                else "written by an earlier version"
            )
            raise HlpError(f"{out} holds a run with a different {', '.join(differs)} ({what}); {START_OVER}")
    elif (out / RESULTS).exists():
        raise HlpError(f"{out / RESULTS} exists without {CONFIG}; {START_OVER}")


def _read_record(path: Path) -> dict[str, Any]:
    """The JSON object of the directory's ``path`` (``config.json``, ``run.json``).

    Raises:
        HlpError: it is unreadable, too large or not a JSON object.
    """
    try:
        record = json.loads(read_run_file(path, MAX_RECORD_BYTES))
    except (ValueError, RecursionError) as error:  # RecursionError: nested too deep
        raise HlpError(f"{path} is unreadable ({error}); {START_OVER}") from None
    if not isinstance(record, dict):
        raise HlpError(f"{path} is unreadable (not a JSON object); {START_OVER}")
    return record


def _earlier_runs(out: Path, fresh: bool) -> list[dict[str, Any]]:
    """The records of the directory's earlier runs (from its ``run.json``), oldest first.

    Raises:
        HlpError: ``run.json`` is unreadable or its ``earlier_runs`` is not a list of records
            (resuming would lose that history).
    """
    if fresh or not (out / RUN).exists():
        return []
    previous = _read_record(out / RUN)
    earlier = previous.pop("earlier_runs", [])
    if not isinstance(earlier, list) or not all(isinstance(run, dict) for run in earlier):
        raise HlpError(f"{out / RUN}: earlier_runs is not a list of run records; {START_OVER}")
    return [*earlier, previous]


def _measured_on(machine: dict[str, Any], settings: ExperimentSettings) -> str:
    where = settings.scheduler and f"the dask cluster at {settings.scheduler}"
    where = where or f"{machine['cpu_model'] or machine['machine']}, {machine['cpu_count']} cores"
    jobs = settings.worker_count
    at_once = f"{jobs} job{'s' if jobs > 1 else ''} at a time ({settings.executor} executor)"
    shared = "; parallel jobs share the cores, so their times are pessimistic" if settings.parallel else ""
    return f"{where}, {at_once}{shared}"


def _run_record(
    settings: ExperimentSettings,
    command: str | None,
    config_yaml: str,
    jobs: list[Job],
    pending: list[Job],
    earlier: list[dict[str, Any]],
    ran: WhatRan,
) -> dict[str, Any]:
    study = settings.study
    return {
        "command": command,
        "status": "running",
        "study": asdict(study),
        **ran.to_dict(),
        "seeds": {"first": study.seed, "last": study.seed + study.scenes - 1, "scenes": study.scenes},
        "objects": sorted({job.objects for job in jobs}),
        "workers": settings.worker_count,
        "executor": settings.executor,
        "scheduler": settings.scheduler,
        "jobs": {"total": len(jobs), "kept": len(jobs) - len(pending), "to_run": len(pending)},
        "machine": machine_info(),
        "software": software_versions(),
        "git_commit": git_commit(),
        "scenario": config_yaml,
        "start_time": utc_now(),
        "end_time": None,
        "wall_s": None,
        "earlier_runs": earlier,
    }


def _prepare(out: Path, identity: dict[str, Any], fresh: bool) -> None:
    """Create the directory and record its identity; ``fresh`` removes the earlier run's outputs."""
    out.mkdir(exist_ok=True)  # its parent checked (check_folder), never made
    if fresh:
        for name in (RESULTS, *DERIVED):
            (out / name).unlink(missing_ok=True)
    write_text_atomic(out / CONFIG, json.dumps(identity, indent=2) + "\n")


def _run_pending(
    job: JobFunction, pending: list[Job], results: ResultsFile, settings: ExperimentSettings, total: int
) -> None:
    """Run ``pending`` on the settings' executor, saving each row as it finishes, with a progress bar
    on a terminal, else (in a file or a pipe) a line per finished job on stderr."""
    bar = tqdm(
        total=total,
        initial=total - len(pending),
        unit="job",
        dynamic_ncols=True,
        desc=f"{settings.study.name} ({settings.worker_count} at a time)",
        disable=bars_disabled(settings.progress),
    )
    lines = settings.progress and bar.disable
    done_jobs = total - len(pending)
    finished = run_jobs(
        job,
        pending,
        executor=settings.executor,
        workers=settings.worker_count,
        scheduler=settings.scheduler,
        warn=lambda message: bar.write(f"warning: {message}", file=sys.stderr),
    )
    with bar, closing(finished):
        for done, row in finished:
            if row_key(row) != done.key:
                raise ValueError(f"the job for {done.key} returned the row of {row_key(row)}")
            results.add(row)
            outcome = f"{done.scene} {_cell_name(done)}: {'success' if row['success'] else 'failure'}"
            bar.set_postfix_str(outcome, refresh=False)
            bar.update()
            done_jobs += 1
            if lines:
                print(
                    f"{settings.study.name}: {done_jobs} of {total} jobs done ({outcome})",
                    file=sys.stderr,
                    flush=True,
                )


def _finish_record(out: Path, record: dict[str, Any], started: float, results: ResultsFile) -> None:
    """Write ``run.json`` with the run's end (time, wall seconds, rows)."""
    record.update(
        end_time=utc_now(),
        wall_s=round(time.perf_counter() - started, 3),
        jobs={**record["jobs"], "rows": len(results.rows)},
    )
    write_text_atomic(out / RUN, json.dumps(record, indent=2) + "\n")


def _cell_name(job: Job) -> str:
    """A job's cell as its progress line names it: its planner pair, then what else the grid varies."""
    labels = job.cell.labels
    extra = [v for v in (labels.robot, labels.execution, labels.perception) if v not in DEFAULTS]
    extra += [] if labels.model_error is None else [f"model error {labels.model_error}"]
    return " ".join([labels.planner, *extra])


DEFAULTS = ("mobile_ur5", "open", "truth")
"""The cell values a progress line leaves unsaid."""


def run_experiment(
    settings: ExperimentSettings,
    out: str | os.PathLike[str],
    *,
    job: JobFunction,
    resolve: StudyResolver,
    command: str | None = None,
) -> dict[str, Any]:
    """Run every job of ``settings`` not yet in ``out/results.csv``; write the summary and plots.

    Every check (settings, scenario, cells, scene generation, the directory's earlier run) happens
    before anything is written. ``job`` runs one job (``hlp_drake.systems.run_job``: the real
    planners); it must be a picklable module-level function for the process pool and dask
    executors. ``resolve`` reads the scenario and checks the cells (``hlp_drake.systems.resolve_study``).

    Returns:
        The summary (as written to ``summary.json``).

    Raises:
        HlpError: bad settings or directory (one line each); KeyboardInterrupt passes through, with
            every finished row saved. StorageError: an output could not be written (a full disk):
            the rows saved before are intact, and running again resumes.
    """
    problems = settings.problems()
    if problems:
        raise HlpError(*problems)
    check_executor(settings.executor, settings.scheduler)
    out, study = check_folder(out, *OUTPUTS), settings.study
    resolved = resolve(study, settings.config_yaml, single_process_rollouts=settings.parallel)
    jobs = make_jobs(study, resolved)
    identity = {"name": study.name, "study": study.identity(), "scenario": resolved.scenario}
    identity = json.loads(json.dumps(identity))  # as config.json holds it: lists, not tuples
    _check_directory(out, identity, settings.fresh)
    cells = [astuple(cell.labels) for cell in resolved.cells]
    rows = [] if settings.fresh else read_results(out / RESULTS, study.generators, cells)
    results = ResultsFile(out / RESULTS, rows)
    earlier = _earlier_runs(out, settings.fresh)

    started = time.perf_counter()
    _prepare(out, identity, settings.fresh)
    results.save()
    pending = [j for j in jobs if j.key not in results]
    ran = replace(resolved.ran, scenario_file=settings.scenario_file)
    record = _run_record(settings, command, resolved.scenario, jobs, pending, earlier, ran)
    write_text_atomic(out / RUN, json.dumps(record, indent=2) + "\n")
    try:
        _run_pending(job, pending, results, settings, len(jobs))
    except BaseException as error:
        interrupted = isinstance(error, KeyboardInterrupt)
        record["status"] = "interrupted" if interrupted else f"failed: {type(error).__name__}"
        with contextlib.suppress(StorageError):  # the first problem is the one to report
            _finish_record(out, record, started, results)
        raise
    record["status"] = "complete"
    _finish_record(out, record, started, results)
    measured_on = _measured_on(record["machine"], settings)
    if "camera" in ran.perceptions:
        measured_on += "; the planners saw the scenes through the cameras (perception: camera)"
    summary = summarise(study, results.rows.values(), measured_on, ran)
    write_summary(out, summary)
    write_plots(out, summary)
    return summary
