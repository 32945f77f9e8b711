"""Worker processes that leave Ctrl-C to their parent.

A Ctrl-C in a terminal reaches the whole process group: the command and every worker it started.
A worker that took it as a KeyboardInterrupt would print its own traceback; instead, workers are
spawned with SIGINT blocked (the mask is inherited, so even a worker still starting up cannot see
it), then ignore it and unblock it before their first task. The parent alone turns it into a
KeyboardInterrupt (``cli.run_cli``: one line, exit 130) and stops the workers
(``terminate_workers``). A SIGTERM to the command (``kill``, a batch scheduler's time limit) takes
the same way out as ``Terminated``, a KeyboardInterrupt (exit 143), so no worker is left behind;
the workers keep SIGTERM's default, which is how they are stopped.

A worker that dies (the out-of-memory killer, a ``kill -9``) breaks its pool; ``shut_down_broken``
closes such a pool and says how the worker died, for the one-line warning (``warn_on_stderr``) of
the caller that runs its work again.
"""

from __future__ import annotations

import contextlib
import signal
import sys
import threading
from collections.abc import Iterator
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from concurrent.futures import ProcessPoolExecutor


class Terminated(KeyboardInterrupt):
    """A SIGTERM, raised in the main thread by ``terminations_raised`` so the interrupt's cleanup runs."""


@contextlib.contextmanager
def terminations_raised() -> Iterator[None]:
    """Inside the block a SIGTERM raises ``Terminated`` in the main thread (elsewhere: nothing changes)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def terminated(signum: int, frame: object) -> None:
        raise Terminated

    previous = signal.signal(signal.SIGTERM, terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def ignore_interrupts() -> None:
    """In a worker: ignore SIGINT (the parent handles it), then unblock it."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


@contextlib.contextmanager
def interrupts_held() -> Iterator[None]:
    """Hold SIGINT back from this thread (and the processes it starts) inside the block; one that
    arrives meanwhile is delivered, as a KeyboardInterrupt, when the block ends."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, previous)


def worker_pool(workers: int, *, method: str | None = "spawn") -> ProcessPoolExecutor:
    """A process pool whose workers ignore SIGINT. Submit its first ``workers`` tasks inside
    ``interrupts_held()``: processes start on submission.

    Args:
        method: the multiprocessing start method ("spawn": fresh interpreters, needed once Drake is
            imported; None: the platform's default).
    """
    import multiprocessing  # here, not at the top: every command imports this module, few start workers
    from concurrent.futures import ProcessPoolExecutor

    context = multiprocessing.get_context(method)
    return ProcessPoolExecutor(workers, mp_context=context, initializer=ignore_interrupts)


def terminate_workers(pool: ProcessPoolExecutor) -> None:
    """Stop the pool's processes now: a task inside a long Drake call would not end soon."""
    terminate = getattr(pool, "terminate_workers", None)  # Python >= 3.14
    if terminate is not None:
        terminate()
        return
    processes = getattr(pool, "_processes", None) or {}  # private before 3.14, hence the fallbacks
    for process in list(processes.values()):
        process.terminate()


def death_cause(exit_codes: list[int | None]) -> str:
    """How a broken pool's dead worker ended ("signal 9", "exit status 3"), from its processes' exit
    codes: the pool stops the survivors with SIGTERM, so any other code comes first."""
    codes = [code for code in exit_codes if code not in (None, 0)]
    own = [code for code in codes if code != -signal.SIGTERM]
    code = (own or codes or [None])[0]
    if code is None:
        return "cause unknown"
    return f"signal {-code}" if code < 0 else f"exit status {code}"


def shut_down_broken(pool: ProcessPoolExecutor) -> str:
    """Shut down ``pool``, broken by a worker's death, and say how that worker died (``death_cause``)."""
    processes = list((getattr(pool, "_processes", None) or {}).values())  # private, hence getattr
    pool.shutdown(wait=True, cancel_futures=True)  # joins the processes: their exit codes are known
    return death_cause([process.exitcode for process in processes])


def warn_on_stderr(message: str) -> None:
    """Print ``warning: message`` on stderr, one line."""
    print(f"warning: {message}", file=sys.stderr, flush=True)
