"""Where jobs run: in this process, a local pool of spawned processes, or a dask cluster.

``run_jobs`` yields ``(job, row)`` in completion order whichever executor runs them; a job's row does
not depend on the executor (jobs are pure functions of their ``Job``). Close the iterator (e.g. with
``contextlib.closing``) to cancel what has not run and shut the workers down.

A worker process that dies (the out-of-memory killer, a ``kill -9``) loses only the job it ran: a
local worker runs one job at a time in a pool of its own, which is replaced, and the job runs again
(``RETRIES`` times, with a one-line warning), else it gets a failure row naming how its worker died.
On the dask cluster this command starts, the scheduler does the same (one job per worker at a time,
``RETRIES`` re-runs: ``allowed-failures``); a job it gives up on (``KilledWorker``) gets a failure row.
"""

from __future__ import annotations

import contextlib
from collections import Counter, deque
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from types import ModuleType

from hlp_drake.errors import HlpError
from hlp_drake.experiments.runner import Job, JobFunction, Row, crash_row
from hlp_drake.runtime.processes import (
    interrupts_held,
    shut_down_broken,
    terminate_workers,
    warn_on_stderr,
    worker_pool,
)

CLUSTER_EXTRA = 'pip install "hlp_drake[cluster]"'
CONNECT_TIMEOUT = "20s"


def require_dask() -> ModuleType:
    """``dask.distributed``, or a one-line ``HlpError`` saying how to install it."""
    try:
        import distributed
    except ImportError:
        raise HlpError(
            f"--executor dask needs dask.distributed, which is not installed: {CLUSTER_EXTRA}"
        ) from None
    return distributed


def connect(distributed: ModuleType, scheduler: str):
    """A ``distributed.Client`` of the scheduler at ``scheduler``, or a one-line ``HlpError``."""
    try:
        return distributed.Client(scheduler, timeout=CONNECT_TIMEOUT)
    except (OSError, ValueError, TypeError) as error:
        raise HlpError(f"cannot connect to the dask scheduler at {scheduler}: {error}") from None


RETRIES = 1
"""Times a job whose worker process died runs again before it gets a failure row."""
JOBS_PER_WORKER = 10
"""Jobs a local worker process runs before a fresh one takes its place (bounds the memory of the
diagrams pydrake does not free: about 77 MB per job on perceived scenes)."""


def check_executor(executor: str, scheduler: str | None) -> None:
    """Fail now, before anything is written, if dask is missing or its scheduler is unreachable."""
    if executor != "dask":
        return
    distributed = require_dask()
    if scheduler is not None:
        connect(distributed, scheduler).close()


def run_jobs(
    job_function: JobFunction,
    jobs: Sequence[Job],
    *,
    executor: str = "local",
    workers: int = 1,
    scheduler: str | None = None,
    warn: Callable[[str], None] = warn_on_stderr,
) -> Iterator[tuple[Job, Row]]:
    """Run ``job_function`` on every job; yield ``(job, row)`` as each finishes.

    Args:
        executor: "local": in this process when ``workers`` is 1, else spawned worker processes;
            "dask": the dask scheduler at ``scheduler``, or a ``LocalCluster`` of ``workers``
            single-threaded worker processes.
        warn: told, in one line, of a job run again because its worker died.
    """
    if not jobs:
        return
    if executor == "dask":
        yield from _on_dask(job_function, jobs, workers, scheduler, warn)
    elif workers == 1:
        yield from ((job, job_function(job)) for job in jobs)
    else:
        yield from _in_process_pool(job_function, jobs, workers, warn)


def _in_process_pool(
    job_function: JobFunction, jobs: Sequence[Job], workers: int, warn: Callable[[str], None]
) -> Iterator[tuple[Job, Row]]:
    """The jobs on fresh workers every ``JOBS_PER_WORKER`` jobs per worker: a process grows with every
    perceived job. Drake 1.51.1 never frees a Python ``LeafSystem`` added to a ``DiagramBuilder``
    (an empty subclass reproduces it; drake#22515), and the camera world's ``DepthNoise`` keeps
    that world and its VTK renderer alive: 24 MB per camera world built, 77 MB per
    ``perceive_world`` with the perception diagram; a world without cameras, 0 MB."""
    chunk = workers * JOBS_PER_WORKER
    for start in range(0, len(jobs), chunk):
        yield from _on_workers(job_function, jobs[start : start + chunk], workers, warn)


def _on_workers(
    job_function: JobFunction, jobs: Sequence[Job], workers: int, warn: Callable[[str], None]
) -> Iterator[tuple[Job, Row]]:
    """The jobs on ``workers`` spawned processes (never fork a process holding Drake), each a pool of
    one running one job at a time, so a worker's death costs that job alone, and names it."""
    waiting, deaths = deque(jobs), Counter[tuple[str, str]]()
    pools: list[ProcessPoolExecutor] = []
    running: dict[Future, tuple[int, Job]] = {}

    def start_next(slot: int) -> None:
        job = waiting.popleft()
        with interrupts_held():  # a fresh worker starts here
            running[pools[slot].submit(job_function, job)] = (slot, job)

    try:
        for slot in range(min(workers, len(jobs))):
            pools.append(worker_pool(1))
            start_next(slot)
        while running:
            done, _ = wait(running, return_when=FIRST_COMPLETED)
            for future in done:
                slot, job = running.pop(future)
                try:
                    row = future.result()
                except BrokenProcessPool:
                    cause = shut_down_broken(pools[slot])
                    pools[slot] = worker_pool(1)
                    deaths[job.key] += 1
                    row = _after_death(job, deaths[job.key], cause, waiting, warn)
                if waiting:
                    start_next(slot)
                if row is not None:
                    yield job, row
    except BaseException:  # Ctrl-C, a failed job, or the caller stopped early: do not wait for the rest
        for pool in pools:
            terminate_workers(pool)
        raise
    finally:
        for pool in pools:
            pool.shutdown(wait=True, cancel_futures=True)


def _after_death(
    job: Job, deaths: int, cause: str, waiting: deque[Job], warn: Callable[[str], None]
) -> Row | None:
    """Queue ``job``, whose worker died (``deaths`` times now), to run again first, or past
    ``RETRIES`` its failure row."""
    what = f"the worker running {job.scene} {job.planner} died ({cause})"
    if deaths <= RETRIES:
        warn(f"{what}; running that job again")
        waiting.appendleft(job)
        return None
    warn(f"{what} again; that job is recorded as a failure")
    return crash_row(job, f"crashed: its worker process died {deaths} times ({cause})")


def _on_dask(
    job_function: JobFunction,
    jobs: Sequence[Job],
    workers: int,
    scheduler: str | None,
    warn: Callable[[str], None],
) -> Iterator[tuple[Job, Row]]:
    distributed = require_dask()
    import logging

    import dask

    with contextlib.ExitStack() as stack:
        if scheduler is None:
            # One job per worker at a time: a worker's death makes only its own job suspect, and
            # the scheduler runs that job again RETRIES times before it gives up (KilledWorker).
            policy = {
                "distributed.scheduler.worker-saturation": 1.0,
                "distributed.scheduler.allowed-failures": RETRIES,
            }
            with dask.config.set(policy):
                cluster = stack.enter_context(
                    distributed.LocalCluster(
                        n_workers=workers,
                        threads_per_worker=1,
                        processes=True,
                        dashboard_address=None,
                        silence_logs=logging.CRITICAL,  # a lost worker is one warning of ours instead
                    )
                )
            client = stack.enter_context(distributed.Client(cluster))
        else:
            client = stack.enter_context(connect(distributed, scheduler))
        pending = {
            future.key: (future, job) for future, job in zip(client.map(job_function, jobs, pure=False), jobs)
        }

        deaths = Counter[str]()

        def worker_lost(event: tuple[float, dict]) -> None:  # on the client's thread
            message = event[1]
            if message.get("action") != "remove-worker" or message.get("expected"):
                return
            for key in message.get("processing-tasks", ()):
                job = (pending.get(key) or (None, None))[1]
                deaths[key] += 1
                if job is None:
                    continue
                what = f"a dask worker died running {job.scene} {job.planner}"
                if scheduler is not None:  # its scheduler's policy decides
                    warn(what)
                elif deaths[key] <= RETRIES:
                    warn(f"{what}; running that job again")

        client.subscribe_topic("all", worker_lost)
        try:
            for future in distributed.as_completed([future for future, _ in pending.values()]):
                job = pending[future.key][1]
                try:
                    row = future.result()
                except distributed.KilledWorker as error:
                    times = error.allowed_failures + 1
                    warn(
                        f"the dask workers running {job.scene} {job.planner} died {times} times; "
                        "that job is recorded as a failure"
                    )
                    row = crash_row(job, f"crashed: its dask worker died {times} times (KilledWorker)")
                del pending[future.key]
                future.release()  # its result leaves the worker: a later death does not recompute it
                yield job, row
        finally:
            client.unsubscribe_topic("all")
            client.cancel([future for future, _ in pending.values()])
