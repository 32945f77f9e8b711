"""``RolloutPool``: STO rollouts on one or several worker processes, owned and closed by the caller.

The pool keeps pre-built ``SceneRollouts`` (one per ``RolloutSpec``, keyed by its ``key``, the latest
few, each with its world): with one worker in the pool itself, with several in each worker process,
which receives the spec as YAML text with each task and builds its worlds on first use. A rollout then only swaps a trajectory and resets a context. A single
rollout (the HLP's first, most often its only one) runs in the calling process; the workers start
when a batch first needs them, so a run that needs none neither waits for them nor shares its cores
with their start. The results are the same either way: a rollout is a pure function of the spec
and the sequence.

A worker that dies (the out-of-memory killer, a ``kill -9``) breaks its process pool: the pool is
replaced and the batch's unfinished rollouts run again, with the same outcomes, and one warning
says so. After ``MAX_DEATHS`` deaths in a row (no batch finished between them) the pool gives up
with ``WorkersLost``, which ``optimise`` turns into the optimisation's failure reason.
"""

from __future__ import annotations

import multiprocessing
import time
from collections import OrderedDict
from collections.abc import Callable
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from functools import cached_property
from typing import Self

from hlp_drake.runtime.processes import (
    interrupts_held,
    shut_down_broken,
    terminate_workers,
    warn_on_stderr,
    worker_pool,
)
from hlp_drake.systems.low_level.control_sequence import ControlSequence
from hlp_drake.systems.low_level.outcome import RolloutOutcome, RolloutStart
from hlp_drake.systems.low_level.sto.cost import RolloutSamples
from hlp_drake.systems.low_level.sto.rollout_world import RolloutWorld, timed_rollout
from hlp_drake.systems.low_level.sto.sampler import sample_rollout
from hlp_drake.systems.low_level.sto.sleep import AWAKE, SleepSchedule, Sweep
from hlp_drake.systems.low_level.sto.spec import RolloutSpec

WORLDS_KEPT = 4
"""Specs whose rollout worlds a pool (or a worker process) keeps: a scene and the displaced
copies of it that ``planner.low_level.displaced_checks`` verifies on (each world built on first use)."""
MAX_DEATHS = 3
"""Worker deaths in a row (no batch finished between them) after which a pool gives up."""


class WorkersLost(RuntimeError):
    """The rollout workers died ``MAX_DEATHS`` times in a row; ``str(error)`` is the reason, one line."""


def _finished(future: Future) -> bool:
    """Whether ``future`` holds a result."""
    return future.done() and not future.cancelled() and future.exception() is None


class _Worlds:
    """``SceneRollouts`` by spec key, the latest ``WORLDS_KEPT``, built on first use."""

    def __init__(self) -> None:
        self._kept: OrderedDict[str, SceneRollouts] = OrderedDict()

    def get(self, key: str, make: Callable[[], RolloutSpec]) -> SceneRollouts:
        if key not in self._kept:
            self._kept[key] = SceneRollouts(make())
            while len(self._kept) > WORLDS_KEPT:
                self._kept.popitem(last=False)
        self._kept.move_to_end(key)
        return self._kept[key]

    def clear(self) -> None:
        self._kept.clear()


_worker_worlds = _Worlds()  # in a worker process: its worlds, for the pool that spawned it


def _rollout_task(
    key: str, spec_yaml: str, times, knots, start: RolloutStart | None, verify: bool
) -> RolloutOutcome:
    world = _worker_worlds.get(key, lambda: RolloutSpec.from_yaml(spec_yaml))
    sequence = ControlSequence(times, knots)
    return world.verify(sequence, start) if verify else world.rollout(sequence, start)


def _warm_up(delay: float) -> int:
    import hlp_drake.systems.low_level.sto.pool  # noqa: F401, PLW0406  (imports Drake once per worker)

    time.sleep(delay)
    return multiprocessing.current_process().pid


class RolloutPool:
    """Rolls out control sequences on ``workers`` processes (1: in this process).

    Use as a context manager, or call ``close()``; one pool can serve many specs in turn. The
    worker processes start when a batch of rollouts first needs them; single rollouts run here.

    Args:
        workers: rollout processes (1: roll out here).
        on_rollout: called with every rollout's outcome as it arrives (e.g. to show progress; not
            with the verifications').
        on_warning: called with a one-line message when a worker died and its rollouts ran again
            (default: ``warn_on_stderr``).

    Attributes:
        startup_s: how long starting the worker processes took, s (0 while none was needed; restarts
            after a worker died included).
    """

    def __init__(
        self,
        workers: int = 1,
        *,
        on_rollout: Callable[[RolloutOutcome], None] | None = None,
        on_warning: Callable[[str], None] = warn_on_stderr,
    ) -> None:
        if workers < 1:
            raise ValueError(f"workers must be >= 1, got {workers}")
        self.workers = int(workers)
        self.startup_s = 0.0
        self._on_rollout = on_rollout
        self._on_warning = on_warning
        self._worlds = _Worlds()
        self._executor: ProcessPoolExecutor | None = None
        self._deaths = 0  # in a row
        self._lost: str | None = None  # why the pool gave up

    def _started(self) -> ProcessPoolExecutor:
        """The worker processes, started (and Drake imported in each) on first use."""
        if self._executor is None:
            started = time.perf_counter()
            self._executor = worker_pool(self.workers)  # workers leave Ctrl-C to this process
            try:
                with interrupts_held():
                    warming = [self._executor.submit(_warm_up, 0.2) for _ in range(self.workers)]
                for future in warming:
                    future.result()
            except BrokenProcessPool:
                raise  # a worker died starting: the caller replaces the pool
            except BaseException:
                self.close(terminate=True)
                raise
            self.startup_s += time.perf_counter() - started
        return self._executor

    def world(self, spec: RolloutSpec) -> SceneRollouts:
        """This pool's pre-built ``SceneRollouts`` for ``spec`` (for start checks and in-process rollouts)."""
        return self._worlds.get(spec.key, lambda: spec)

    def rollouts(
        self,
        spec: RolloutSpec,
        sequences: list[ControlSequence],
        *,
        start: RolloutStart | None = None,
        verify: bool = False,
    ) -> list[RolloutOutcome]:
        """The ``RolloutOutcome`` of every sequence, in order, from ``start`` (default: the scene's
        start); with ``verify`` on the execution model (``SceneRollouts.verify``)."""
        return self._simulate([(spec, s) for s in sequences], start, verify)

    def verifications(
        self, specs: list[RolloutSpec], sequence: ControlSequence, *, start: RolloutStart | None = None
    ) -> list[RolloutOutcome]:
        """The execution model's ``RolloutOutcome`` of ``sequence`` on each spec's scene, in order
        (all at once on the workers)."""
        return self._simulate([(spec, sequence) for spec in specs], start, True)

    def _simulate(
        self, jobs: list[tuple[RolloutSpec, ControlSequence]], start: RolloutStart | None, verify: bool
    ) -> list[RolloutOutcome]:
        if self.workers == 1 or len(jobs) == 1:
            return [
                self._arrived((self.world(c).verify if verify else self.world(c).rollout)(s, start), verify)
                for c, s in jobs
            ]
        outcomes: dict[int, RolloutOutcome] = {}
        while True:
            if self._lost is not None:
                raise WorkersLost(self._lost)
            futures: dict[int, Future] = {}
            try:
                executor = self._started()
                with interrupts_held():  # a replaced pool's workers start here
                    for i, (c, s) in enumerate(jobs):
                        if i not in outcomes:
                            futures[i] = executor.submit(
                                _rollout_task, c.key, c.yaml, s.times, s.knots, start, verify
                            )
                for i, future in futures.items():
                    outcomes[i] = self._arrived(future.result(), verify)
            except BrokenProcessPool:
                for i, future in futures.items():  # finished before the pool broke: kept
                    if i not in outcomes and _finished(future):
                        outcomes[i] = self._arrived(future.result(), verify)
                self._replace(len(jobs) - len(outcomes))
                continue
            self._deaths = 0
            return [outcomes[i] for i in range(len(jobs))]

    def _replace(self, unfinished: int) -> None:
        """Replace the broken process pool (and warn), or give up after ``MAX_DEATHS`` in a row."""
        cause = shut_down_broken(self._executor)
        self._executor = None
        self._deaths += 1
        if self._deaths >= MAX_DEATHS:
            self._lost = f"the rollout workers died {self._deaths} times in a row ({cause})"
            raise WorkersLost(self._lost)
        again = f" and ran the batch's {unfinished} unfinished rollout{'s' if unfinished != 1 else ''} again"
        self._on_warning(
            f"a rollout worker died ({cause}); restarted the workers{again if unfinished else ''}"
        )

    def _arrived(self, outcome: RolloutOutcome, verify: bool) -> RolloutOutcome:
        if self._on_rollout is not None and not verify:
            self._on_rollout(outcome)
        return outcome

    def close(self, *, terminate: bool = False) -> None:
        """Stop the worker processes (at once with ``terminate``, else after their rollouts) and
        drop the worlds."""
        self._worlds.clear()
        if self._executor is not None:
            if terminate:
                terminate_workers(self._executor)
            self._executor.shutdown(cancel_futures=True)
            self._executor = None

    def __enter__(self) -> Self:
        return self

    def __exit__(self, kind, error, traceback) -> None:
        self.close(terminate=kind is not None and issubclass(kind, KeyboardInterrupt))


# ``SceneRollouts``: the rollouts of one spec on its execution model.
#
# The reduced model (``planner.low_level.reduced_model``, off by default): most of a rollout's time goes to the
# contact problem, which every resting object joins with its contact points on the table. An object
# nothing has come near stays at rest, so until then it can as well sleep (its joint locked;
# ``sleep_schedule``, ``rollout_sampler``); one that has come to rest again goes back to sleep. Every
# cost term still covers every object. ``verify`` rolls a sequence out with every object awake.
class SceneRollouts:
    """Rollouts on one scene, on its execution model (with ``sto.reduced_model`` its objects asleep
    while nothing comes near them, see the module's docstring); verification with every object awake.

    A rollout's outcome is a pure function of the scene, the configuration, the start and the sequence.
    """

    def __init__(self, spec: RolloutSpec) -> None:
        self.spec = spec

    @cached_property
    def full(self) -> RolloutWorld:
        """The scene's world (built on first use)."""
        return RolloutWorld(self.spec)

    @cached_property
    def _sweep(self) -> Sweep | None:
        return Sweep(self.full) if self.spec.sto.reduced_model else None

    @property
    def start_collisions(self) -> tuple[str, ...]:
        return self.full.start_collisions

    def sleep_schedule(self, sequence: ControlSequence, start: RolloutStart | None = None) -> SleepSchedule:
        """When ``sequence``'s commanded motion first comes within ``planner.low_level.weld_clearance`` of each
        object (from ``start``'s object poses, if given), the objects sleeping until
        ``planner.low_level.weld_lookahead`` before (never with the reduced model off: ``AWAKE``)."""
        sto = self.spec.sto
        if self._sweep is None:
            return AWAKE
        states = None if start is None else start.states
        return SleepSchedule(
            self._sweep.approach_times(sequence, sto.weld_clearance, states), sto.weld_lookahead
        )

    def simulate(self, sequence: ControlSequence, start: RolloutStart | None = None) -> RolloutSamples:
        """Roll ``sequence`` out (from ``start``), reading the state every sample period."""
        schedule = self.sleep_schedule(sequence, start)
        return sample_rollout(
            sequence, self.spec.sto, self.full, schedule, settle_s=self.spec.success.settle_s, start=start
        )

    def rollout(self, sequence: ControlSequence, start: RolloutStart | None = None) -> RolloutOutcome:
        """Simulate ``sequence`` (from ``start``) and cost it."""
        return timed_rollout(sequence, self.simulate, self.full, start)

    def verify(self, sequence: ControlSequence, start: RolloutStart | None = None) -> RolloutOutcome:
        """Simulate ``sequence`` (from ``start``) with every object awake, and cost it."""
        return self.full.rollout(sequence, start)
