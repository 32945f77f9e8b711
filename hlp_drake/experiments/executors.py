"""Where jobs run: in this process, a local pool of spawned processes, or a dask cluster.

``run_jobs`` yields ``(job, row)`` in completion order whichever executor runs them; a job's row does
not depend on the executor (jobs are pure functions of their ``Job``). Close the iterator (e.g. with
``contextlib.closing``) to cancel what has not run and shut the workers down.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator, Sequence
from concurrent.futures import as_completed
from types import ModuleType

from hlp_drake.errors import HlpError
from hlp_drake.experiments.runner import Job, JobFunction, Row
from hlp_drake.processes import interrupts_held, terminate_workers, worker_pool

EXECUTORS = ("local", "dask")
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
) -> Iterator[tuple[Job, Row]]:
    """Run ``job_function`` on every job; yield ``(job, row)`` as each finishes.

    Args:
        executor: "local": in this process when ``workers`` is 1, else a spawn-context process pool;
            "dask": the dask scheduler at ``scheduler``, or a ``LocalCluster`` of ``workers``
            single-threaded worker processes.
    """
    if not jobs:
        return
    if executor == "dask":
        yield from _on_dask(job_function, jobs, workers, scheduler)
    elif workers == 1:
        yield from ((job, job_function(job)) for job in jobs)
    else:
        yield from _in_process_pool(job_function, jobs, workers)


def _in_process_pool(
    job_function: JobFunction, jobs: Sequence[Job], workers: int
) -> Iterator[tuple[Job, Row]]:
    """The jobs in fresh pools of ``JOBS_PER_WORKER`` jobs per worker: a process grows with every
    perceived job. Drake 1.51.1 never frees a Python ``LeafSystem`` added to a ``DiagramBuilder``
    (an empty subclass reproduces it; drake#22515), and the camera world's ``DepthNoise`` keeps
    that world and its VTK renderer alive: 24 MB per camera world built, 77 MB per
    ``perceive_world`` with the perception diagram; a world without cameras, 0 MB."""
    chunk = workers * JOBS_PER_WORKER
    for start in range(0, len(jobs), chunk):
        yield from _in_one_pool(job_function, jobs[start : start + chunk], workers)


def _in_one_pool(job_function: JobFunction, jobs: Sequence[Job], workers: int) -> Iterator[tuple[Job, Row]]:
    pool = worker_pool(min(workers, len(jobs)))  # spawned: never fork a process holding Drake
    try:
        with interrupts_held():  # the workers start here
            futures = {pool.submit(job_function, job): job for job in jobs}
        for future in as_completed(futures):
            yield futures[future], future.result()
    except BaseException:  # Ctrl-C, a failed job, or the caller stopped early: do not wait for the rest
        terminate_workers(pool)
        raise
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _on_dask(
    job_function: JobFunction, jobs: Sequence[Job], workers: int, scheduler: str | None
) -> Iterator[tuple[Job, Row]]:
    distributed = require_dask()
    with contextlib.ExitStack() as stack:
        if scheduler is None:
            cluster = stack.enter_context(
                distributed.LocalCluster(
                    n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None
                )
            )
            client = stack.enter_context(distributed.Client(cluster))
        else:
            client = stack.enter_context(connect(distributed, scheduler))
        futures = client.map(job_function, jobs, pure=False)
        owners = {future.key: job for future, job in zip(futures, jobs)}
        try:
            for future in distributed.as_completed(futures):
                yield owners[future.key], future.result()
        finally:
            client.cancel(futures)
